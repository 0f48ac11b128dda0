// The live playground's controls and drawings (chapter 08): every element with class
// "pgae-live" becomes a small form that calls window.pgae.run (pgae.js) and shows, computed in
// the page, the words the model writes, what it understood of a typed text, its joints against
// the target, the GMU gate, and NICO's arm in 3-D, animated through the joints the model wrote.
// Nothing here computes the model or moves a cube: it only collects and draws. Cubes move only
// along a closed-loop run that the pybullet simulator made at build time (pgae.simulated).
(function () {
  "use strict";
  const COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd"];   // one per joint
  const SIGNALS = ["execute", "describe", "repeat action", "repeat language"];
  const ROBOT_RATE = 80;     // recorded steps per second of robot time (pgae_lite.sim.record.SimConfig)
  const PLAY_RATE = 20;      // steps per second on screen: a quarter of the robot's speed
  const CENTRE = [0.15, 0.02, 0.05];                     // the point the 3-D view turns about (m)
  const VIEW = {az: 2.2, el: 0.75, dist: 0.95};          // camera: azimuth, elevation (rad), distance (m):
                                                         // above and behind NICO's left (moving) shoulder
  // NICO's torso, half see-through: pgae_lite.sim.robot.nico_urdf's box (centre, size) above the table top.
  const BODY = [[[-0.04, 0, 0.09], [0.11, 0.17, 0.18]]];

  function element(tag, attrs = {}, ...children) {
    const e = document.createElement(tag);
    Object.entries(attrs).forEach(([k, v]) => (k === "text" ? (e.textContent = v) : e.setAttribute(k, v)));
    children.forEach(c => e.appendChild(typeof c === "string" ? document.createTextNode(c) : c));
    return e;
  }

  function select(label, options) {
    const s = element("select", {"aria-label": label});
    options.forEach(([value, text]) => s.appendChild(element("option", {value, text})));
    return s;
  }

  // The target of a signal's joints (pgae_lite.robot.playground.TARGETS): the recording, or one pose held.
  function target(recorded, signal) {
    if (signal === "describe") return recorded.map(() => recorded[recorded.length - 1]);
    if (signal === "repeat language") return recorded.map(() => recorded[0]);
    return recorded;
  }

  // A series (a list of poses, points, ...) at a fractional step t: linear between the two steps
  // around it, its last entry after its end.
  const lerp = (a, b, f) => (Array.isArray(a) ? a.map((v, i) => lerp(v, b[i], f)) : a + (b - a) * f);
  function at(series, t) {
    const last = series.length - 1, s = Math.max(0, Math.min(t, last)), i = Math.floor(s);
    return lerp(series[i], series[Math.min(i + 1, last)], s - i);
  }

  // The joints, model (dashed) against target (solid), with a cursor at step t.
  function plotJoints(canvas, joints, wanted, t) {
    const g = canvas.getContext("2d"), W = canvas.width, H = canvas.height, pad = 30;
    const all = joints.concat(wanted).flat(), lo = Math.min(...all), hi = Math.max(...all) + 1e-9;
    const x = (s) => pad + (W - 2 * pad) * s / Math.max(1, joints.length - 1);
    const y = (v) => H - pad - (H - 2 * pad) * (v - lo) / (hi - lo);
    g.clearRect(0, 0, W, H);
    g.strokeStyle = "#999"; g.strokeRect(pad, pad, W - 2 * pad, H - 2 * pad);
    g.fillStyle = "#333"; g.font = "11px sans-serif";
    g.fillText("joints (rad): model (dashed) and target (solid), by step", pad, pad - 8);
    for (let j = 0; j < 5; j++) {
      [[wanted, []], [joints, [5, 4]]].forEach(([series, dash]) => {
        g.setLineDash(dash); g.strokeStyle = COLOURS[j]; g.beginPath();
        series.forEach((pose, s) => (s ? g.lineTo(x(s), y(pose[j])) : g.moveTo(x(s), y(pose[j]))));
        g.stroke();
      });
    }
    g.setLineDash([]); g.strokeStyle = "#555";
    g.beginPath(); g.moveTo(x(t), pad); g.lineTo(x(t), H - pad); g.stroke();
  }

  function plotGate(canvas, gate) {
    const g = canvas.getContext("2d"), W = canvas.width, H = canvas.height, pad = 20, w = (W - 2 * pad) / gate.length;
    g.clearRect(0, 0, W, H);
    g.fillStyle = "#333"; g.font = "11px sans-serif";
    const mean = gate.reduce((a, b) => a + b, 0) / gate.length;
    g.fillText(`GMU gate z per dimension of h, mean ${mean.toFixed(2)} (0 language, 1 action)`, pad, 12);
    gate.forEach((z, k) => {
      g.fillStyle = `rgb(${Math.round(255 * z)}, 80, ${Math.round(255 * (1 - z))})`;
      g.fillRect(pad + k * w, H - pad - (H - 2 * pad - 10) * z, Math.max(1, w - 1), (H - 2 * pad - 10) * z);
    });
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

  // One frame: the table, shadows, fingertip paths, then cubes and arms far to near.
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
    polyline(g, P, s.wanted.map(tip), {strokeStyle: "#888", lineWidth: 1});
    polyline(g, P, s.joints.map(tip), {strokeStyle: "#1f77b4", lineWidth: 1, dash: [5, 4]});
    const cubes = s.sim ? at(s.sim.cubes, t) : s.episode.cubes.map(([x, y]) => [x, y, a.cube_size / 2]);
    const items = cubes.map((c, k) => ({depth: P(c)[2], draw: () =>
      box(g, cam, c, [a.cube_size, a.cube_size, a.cube_size], m.cube_rgba[s.episode.scene[k]])}));
    BODY.forEach(([c, size]) => items.push({depth: P(c)[2], draw: () => box(g, cam, c, size, [0.85, 0.86, 0.9, 0.55])}));
    const limb = (q, style) => window.pgae.fk(q).slice(1).forEach((p, k, ps) => {
      const from = k ? ps[k - 1] : window.pgae.fk(q)[0];
      items.push({depth: P(lerp(from, p, 0.5))[2], draw: () => polyline(g, P, [from, p], style)});
    });
    if (simArm) limb(simArm, {strokeStyle: "rgba(90,90,90,0.9)", lineWidth: 4, lineCap: "round", dash: [6, 5]});
    limb(arm, {strokeStyle: "#1f77b4", lineWidth: 7, lineCap: "round"});
    items.sort((p, q) => q.depth - p.depth).forEach(item => item.draw());
    const [tx, ty] = P(tip(arm));
    g.fillStyle = "#0b3c66"; g.beginPath(); g.arc(tx, ty, 4, 0, 2 * Math.PI); g.fill();
    const label = (text, y, colour) => {                                  // text on a white band
      g.font = "11px sans-serif"; g.fillStyle = "rgba(255,255,255,0.8)";
      g.fillRect(3, y - 11, g.measureText(text).width + 6, 15); g.fillStyle = colour; g.fillText(text, 6, y);
    };
    label("NICO's arm from the model's joints (blue), drawn by forward kinematics; drag to turn", 14, "#333");
    label("fingertip path: model (blue dashed), target (grey)", 28, "#333");
    if (simArm) label("grey dashed arm: the simulator's measured arm in its build-time run", 42, "#333");
    label(s.sim ? `cubes: the simulator's ${s.sim.kind} run at build time, not this page: ${s.sim.passed ? "passed" : "failed"}`
                : "cubes: where the recording has them (they do not move in this page)",
          H - 8, s.sim ? (s.sim.passed ? "#1a7f37" : "#b42318") : "#555");
  }

  window.pgaeWidget = async function (root) {
    root.textContent = "Loading the models (onnxruntime-web)...";
    let manifest;
    try {
      manifest = await window.pgae.load();
    } catch (e) {
      root.textContent = `The live playground cannot start: ${e.message}`;
      return;
    }
    const model = select("model", Object.keys(manifest.models).map(m => [m, m]));
    const signal = select("signal", SIGNALS.map(s => [s, s]));
    const episode = select("episode", manifest.episodes.map(e => [e.id, `${e.id}: ${e.description} ` +
                                                                  `(${e.scene[0]} left, ${e.scene[1]} right)`]));
    const text = element("input", {type: "text", size: "34", "aria-label": "text",
                                   placeholder: "or type a description, e.g. push red slowly"});
    const button = element("button", {type: "button", class: "pgae-live-run", text: "Run"});
    const said = element("pre", {class: "pgae-live-said"});
    const camera = element("div", {class: "pgae-live-camera"});
    // The animation's controls are <input>s, not <button>s: the Run button stays the widget's only <button>.
    const play = element("input", {type: "button", class: "pgae-live-play", value: "Play", disabled: ""});
    const slider = element("input", {type: "range", class: "pgae-live-time", min: "0", max: "0", value: "0",
                                     disabled: "", "aria-label": "step"});
    const clock = element("span", {class: "pgae-live-clock"});
    const simBox = element("input", {type: "checkbox", checked: ""});
    const simToggle = element("label", {class: "pgae-live-simarm", hidden: ""}, simBox, " show the simulator's arm");
    const arm = element("canvas", {width: "640", height: "380", class: "pgae-live-arm",
                                   "aria-label": "NICO's arm in 3-D, drag to turn"});
    const note = element("p", {class: "pgae-live-cubes"});
    const joints = element("canvas", {width: "640", height: "260"});
    const gate = element("canvas", {width: "640", height: "120"});
    root.textContent = "";
    [model, signal, episode, text, button, camera, said, arm,
     element("div", {}, play, " ", slider, " ", clock, " ", simToggle), note, joints, gate].forEach(c => root.appendChild(c));
    arm.style.cursor = "grab"; arm.style.touchAction = "none"; arm.style.maxWidth = "100%";
    slider.style.width = "240px"; note.style.fontSize = "0.9em";

    // NICO's camera in the chosen episode's recording (the build's PNGs), first and last step.
    function showCamera() {
      camera.textContent = "";
      if (!window.pgae.frame(episode.value, "first")) return;
      ["first", "last"].forEach(which => camera.appendChild(element("img", {
        src: window.pgae.frame(episode.value, which), width: "160", height: "120",
        alt: `NICO's camera at the ${which} step of ${episode.value}`, style: "margin-right: 4px"})));
      camera.appendChild(element("div", {style: "font-size: 0.85em",
        text: "NICO's camera in this episode's recording, first and last step (what the CAE read, not this page)"}));
    }
    episode.addEventListener("change", showCamera);
    showCamera();

    // What is drawn: s (the run, its target, the episode, the simulator's run or null) at step t.
    const view = {...VIEW};
    let s = null, t = 0, playing = 0, last = null;
    const steps = () => Math.max(s.joints.length, s.sim ? s.sim.cubes.length : 0);
    function redraw() {
      if (!s) return;
      drawScene(arm, view, s, t);
      plotJoints(joints, s.joints, s.wanted, Math.min(t, s.joints.length - 1));
      slider.value = String(Math.round(t));
      clock.textContent = `step ${Math.round(t)} of ${steps() - 1} · ${(t / ROBOT_RATE).toFixed(2)} s of robot time ` +
                          `· played ${ROBOT_RATE / PLAY_RATE}× slower`;
    }
    // requestAnimationFrame loop; each Play starts a new one and stops the ones before it.
    function setPlaying(on) {
      playing = on ? playing + 1 : 0;
      last = null; play.value = on ? "Pause" : "Play";
      const mine = playing;
      const frame = (now) => {
        if (playing !== mine) return;
        if (last !== null) t = Math.min(t + (now - last) / 1000 * PLAY_RATE, steps() - 1);
        last = now; redraw();
        if (t >= steps() - 1) setPlaying(false); else requestAnimationFrame(frame);
      };
      if (on) requestAnimationFrame(frame);
    }
    play.addEventListener("click", () => {
      if (playing) return setPlaying(false);
      if (t >= steps() - 1) t = 0;                                        // at the end: from the start again
      setPlaying(true);
    });
    slider.addEventListener("input", () => { setPlaying(false); t = Number(slider.value); redraw(); });
    simBox.addEventListener("change", () => { if (s) s.showSim = simBox.checked; redraw(); });
    let drag = null;                                                      // turn the view by dragging
    arm.addEventListener("pointerdown", (e) => { drag = [e.clientX, e.clientY]; arm.setPointerCapture(e.pointerId); });
    ["pointerup", "pointercancel"].forEach(k => arm.addEventListener(k, () => { drag = null; }));
    arm.addEventListener("pointermove", (e) => {
      if (!drag) return;
      view.az -= (e.clientX - drag[0]) * 0.01;
      view.el = Math.max(0.05, Math.min(1.5, view.el + (e.clientY - drag[1]) * 0.01));
      drag = [e.clientX, e.clientY]; redraw();
    });

    button.addEventListener("click", async () => {
      button.disabled = true;
      setPlaying(false);
      said.classList.remove("pgae-live-error");
      try {
        const t0 = performance.now();
        const r = await window.pgae.run({model: model.value, signal: signal.value, episode: episode.value,
                                         text: text.value});
        said.textContent = (r.understood !== null ? `I understood: ${r.understood || "<EOS>"}\n` : "") +
          (r.note ? `note: ${r.note}\n` : "") +
          `words: ${r.words || "<EOS>"}\ncomputed in this page in ${(performance.now() - t0).toFixed(0)} ms`;
        // The cubes move only along the simulator's own run of this model on this episode (execute).
        let sim = null, why = "";
        if (signal.value === "execute" && typeof window.pgae.simulated === "function") {
          try { sim = await window.pgae.simulated(model.value, episode.value); }
          catch (e) { why = ` (no simulator run: ${e.message})`; }
        }
        const ep = manifest.episodes.find(e => e.id === episode.value);
        s = {joints: r.joints, wanted: target(window.pgae.recorded(episode.value), signal.value), episode: ep,
             sim, showSim: simBox.checked};
        note.textContent = sim
          ? `The cubes move as they moved in the simulator, not in this page. ${sim.label} ${model.value} was ` +
            `told "${sim.description}" (${sim.kind}): ${sim.passed ? "passed" : "failed"} (the simulator's check: ` +
            "did the named cube move the named way?). The grey dashed arm is that run's measured arm; the blue " +
            "arm is this page's run, which reads the recorded camera frames instead, so the two can differ."
          : "The cubes do not move in this page: they stay where the recording has them. Only the simulator " +
            `moves them (chapter 07); this page computes the model, not the physics.${why}`;
        simToggle.hidden = !sim;
        slider.max = String(steps() - 1); slider.disabled = false; play.disabled = false;
        plotGate(gate, r.gate);
        t = 0; redraw(); setPlaying(true);
        root.dataset.result = JSON.stringify(r);
      } catch (e) {
        said.textContent = `Cannot run this: ${e.message}`;
        said.classList.add("pgae-live-error");
      } finally {
        button.disabled = false;
      }
    });
  };
})();
