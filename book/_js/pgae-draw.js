// The live playground's drawings (chapter 08): the joints plot, the GMU gate and NICO's arm in 3-D,
// drawn from a run's joints by forward kinematics (window.pgae.fk, pgae-arm.js) on the table and cubes
// of the manifest. Nothing here computes the model or moves a cube; pgae-widget.js calls
//
//   window.pgaeDraw.plotJoints(canvas, joints, wanted, t), plotGate(canvas, gate),
//   drawScene(canvas, view, s, t) with s = {joints, wanted, episode, sim, showSim}, at(series, t), VIEW.
(function () {
  "use strict";
  const COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd"];   // one per joint
  const CENTRE = [0.15, 0.02, 0.05];                     // the point the 3-D view turns about (m)
  const VIEW = {az: 2.2, el: 0.75, dist: 0.95};          // camera: azimuth, elevation (rad), distance (m):
                                                         // above and behind NICO's left (moving) shoulder

  // A series (a list of poses, points, ...) at a fractional step t: linear between the two steps
  // around it, its last entry after its end.
  const lerp = (a, b, f) => (Array.isArray(a) ? a.map((v, i) => lerp(v, b[i], f)) : a + (b - a) * f);
  function at(series, t) {
    const last = series.length - 1, s = Math.max(0, Math.min(t, last)), i = Math.floor(s);
    return lerp(series[i], series[Math.min(i + 1, last)], s - i);
  }

  // The joints, model (dashed) against target (solid), with a cursor at step t.
  function plotJoints(canvas, joints, wanted, t) {
    const g = canvas.getContext("2d"), W = canvas.width, H = canvas.height, left = 64, pad = 16, bottom = 40;
    const all = joints.concat(wanted).flat(), lo = Math.min(...all), hi = Math.max(...all) + 1e-9;
    const x = (s) => left + (W - left - pad) * s / Math.max(1, joints.length - 1);
    const y = (v) => H - bottom - (H - bottom - pad) * (v - lo) / (hi - lo);
    g.clearRect(0, 0, W, H);
    g.strokeStyle = "#999"; g.lineWidth = 1; g.strokeRect(left, pad, W - left - pad, H - bottom - pad);
    g.fillStyle = "#333"; g.font = "22px sans-serif"; g.textAlign = "right";
    [lo, (lo + hi) / 2, hi].forEach(v => g.fillText(v.toFixed(1), left - 8, y(v) + 8));
    g.textAlign = "center";
    [0, joints.length - 1].forEach(s => g.fillText(String(s), x(s), H - bottom + 28));
    g.fillText("step", (left + W - pad) / 2, H - bottom + 28);
    g.textAlign = "left"; g.lineWidth = 2;
    for (let j = 0; j < 5; j++) {
      [[wanted, []], [joints, [8, 6]]].forEach(([series, dash]) => {
        g.setLineDash(dash); g.strokeStyle = COLOURS[j]; g.beginPath();
        series.forEach((pose, s) => (s ? g.lineTo(x(s), y(pose[j])) : g.moveTo(x(s), y(pose[j]))));
        g.stroke();
      });
    }
    g.setLineDash([]); g.strokeStyle = "#555"; g.lineWidth = 1.5;
    g.beginPath(); g.moveTo(x(t), pad); g.lineTo(x(t), H - bottom); g.stroke();
  }

  function plotGate(canvas, gate) {
    const g = canvas.getContext("2d"), W = canvas.width, H = canvas.height, pad = 12, w = (W - 2 * pad) / gate.length;
    const mean = gate.reduce((a, b) => a + b, 0) / gate.length, y = (z) => H - pad - (H - 2 * pad) * z;
    g.clearRect(0, 0, W, H);
    g.strokeStyle = "#bbb"; g.lineWidth = 1; g.strokeRect(pad, pad, W - 2 * pad, H - 2 * pad);
    gate.forEach((z, k) => {
      g.fillStyle = `rgb(${Math.round(255 * z)}, 80, ${Math.round(255 * (1 - z))})`;
      g.fillRect(pad + k * w, y(z), Math.max(1, w - 1), (H - 2 * pad) * z);
    });
    g.setLineDash([4, 4]); g.strokeStyle = "#000";
    g.beginPath(); g.moveTo(pad, y(mean)); g.lineTo(W - pad, y(mean)); g.stroke(); g.setLineDash([]);
  }

  // ---- The 3-D view: NICO's frame (x forward, y to NICO's left, z up; the table top is z = 0),
  // seen by a perspective camera on a sphere around CENTRE. project(p) -> [x, y, depth] on the canvas.
  const sub = (a, b) => a.map((v, i) => v - b[i]), dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const unit = (a) => a.map(v => v / Math.hypot(...a));
  function camera(view, W, H) {
    const eye = [Math.cos(view.el) * Math.cos(view.az), Math.cos(view.el) * Math.sin(view.az), Math.sin(view.el)]
      .map((v, i) => CENTRE[i] + view.dist * v);
    const f = unit(sub(CENTRE, eye)), r = unit(cross(f, [0, 0, 1])), u = cross(r, f), focal = 1.1 * W;
    const project = (p) => {
      const d = sub(p, eye), z = dot(d, f);
      return [W / 2 + focal * dot(d, r) / z, H / 2 - focal * dot(d, u) / z, z];
    };
    return {eye, project};
  }

  function polyline(g, project, points, style) {
    const {dash = [], fill = false, ...paint} = style;                     // paint: context properties
    g.save(); Object.assign(g, paint); g.setLineDash(dash); g.beginPath();
    points.forEach((p, k) => { const [x, y] = project(p); k ? g.lineTo(x, y) : g.moveTo(x, y); });
    fill ? g.fill() : g.stroke(); g.restore();
  }

  // An axis-aligned box (a cube: the simulator's run keeps centres only) centred at c, of sizes
  // size [x, y, z]: the faces that look at the eye, each shaded by its direction.
  function box(g, cam, c, size, rgba) {
    const faces = [[0, 1], [0, -1], [1, 1], [1, -1], [2, 1], [2, -1]];   // axis, sign
    const shade = [0.75, 0.6, 0.85, 0.65, 1.0, 0.5], h = size.map(v => v / 2);
    faces.forEach(([axis, sign], k) => {
      const centre = c.map((v, i) => (i === axis ? v + sign * h[i] : v));
      const normal = [0, 1, 2].map(i => (i === axis ? sign : 0));
      if (dot(normal, sub(cam.eye, centre)) <= 0) return;                // faces away from the camera
      const [a, b] = [0, 1, 2].filter(i => i !== axis), corners = [[-1, -1], [1, -1], [1, 1], [-1, 1]].map(([s, t]) =>
        centre.map((v, i) => (i === a ? v + s * h[i] : i === b ? v + t * h[i] : v)));
      const col = rgba.slice(0, 3).map(v => Math.round(255 * v * shade[k])).join(", ");
      polyline(g, cam.project, corners, {fill: true, fillStyle: `rgba(${col}, ${rgba[3]})`});
      polyline(g, cam.project, corners.concat([corners[0]]), {strokeStyle: "rgba(0,0,0,0.35)", lineWidth: 1});
    });
  }

  // One frame: the table, shadows, fingertip paths, then cubes, NICO's torso and arms far to near.
  function drawScene(canvas, view, s, t) {
    const m = window.pgae.manifest(), a = m.arm, g = canvas.getContext("2d"), W = canvas.width, H = canvas.height;
    const cam = camera(view, W, H), P = cam.project, [x0, x1] = a.table_x, w = a.table_half_width;
    g.clearRect(0, 0, W, H);
    polyline(g, P, [[x0, -w, 0], [x1, -w, 0], [x1, w, 0], [x0, w, 0]], {fill: true, fillStyle: "#eee3d2"});
    for (let y = -0.3; y <= 0.31; y += 0.1) polyline(g, P, [[x0, y, 0], [x1, y, 0]], {strokeStyle: "#ddd0bc", lineWidth: 1});
    const tip = (q) => window.pgae.fk(q)[3], arm = at(s.joints, t);
    const simArm = s.sim && s.showSim ? at(s.sim.measured, t) : null;   // the simulator's measured arm
    [arm, simArm].filter(Boolean).forEach(q =>                            // shadows, straight down
      polyline(g, P, window.pgae.fk(q).map(p => [p[0], p[1], 0]),
               {strokeStyle: "rgba(0,0,0,0.15)", lineWidth: 6, lineCap: "round"}));
    polyline(g, P, s.wanted.map(tip), {strokeStyle: "#888", lineWidth: 1.5});
    polyline(g, P, s.joints.map(tip), {strokeStyle: "#1f77b4", lineWidth: 1.5, dash: [6, 5]});
    const cubes = s.sim ? at(s.sim.cubes, t) : s.episode.cubes.map(([x, y]) => [x, y, a.cube_size / 2]);
    const items = cubes.map((c, k) => ({depth: P(c)[2], draw: () =>
      box(g, cam, c, [a.cube_size, a.cube_size, a.cube_size], m.cube_rgba[s.episode.scene[k]])}));
    const [torsoCentre, torsoSize] = m.play.torso;                         // NICO's torso above the table, see-through
    items.push({depth: P(torsoCentre)[2], draw: () => box(g, cam, torsoCentre, torsoSize, [0.85, 0.86, 0.9, 0.55])});
    const limb = (q, style) => window.pgae.fk(q).slice(1).forEach((p, k, ps) => {
      const from = k ? ps[k - 1] : window.pgae.fk(q)[0];
      items.push({depth: P(lerp(from, p, 0.5))[2], draw: () => polyline(g, P, [from, p], style)});
    });
    if (simArm) limb(simArm, {strokeStyle: "rgba(90,90,90,0.9)", lineWidth: 5, lineCap: "round", dash: [8, 6]});
    limb(arm, {strokeStyle: "#1f77b4", lineWidth: 9, lineCap: "round"});
    items.sort((p, q) => q.depth - p.depth).forEach(item => item.draw());
    const [tx, ty] = P(tip(arm));
    g.fillStyle = "#0b3c66"; g.beginPath(); g.arc(tx, ty, 5, 0, 2 * Math.PI); g.fill();
  }

  window.pgaeDraw = {COLOURS, VIEW, at, plotJoints, plotGate, drawScene};
})();
