// The live playground's controls and drawings (chapter 08): every element with class
// "pgae-live" becomes a small form that calls window.pgae.run (pgae.js) and shows, computed in
// the page, the words the model writes, what it understood of a typed text, its joints against
// the target, and the GMU gate. Nothing here computes the model: it only collects and draws.
(function () {
  "use strict";
  const COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd"];   // one per joint
  const SIGNALS = ["execute", "describe", "repeat action", "repeat language"];

  function element(tag, attrs = {}, ...children) {
    const e = document.createElement(tag);
    Object.entries(attrs).forEach(([k, v]) => (k === "text" ? (e.textContent = v) : e.setAttribute(k, v)));
    children.forEach(c => e.appendChild(c));
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

  function plotJoints(canvas, joints, wanted) {
    const g = canvas.getContext("2d"), W = canvas.width, H = canvas.height, pad = 30;
    const all = joints.concat(wanted).flat(), lo = Math.min(...all), hi = Math.max(...all) + 1e-9;
    const x = (t) => pad + (W - 2 * pad) * t / Math.max(1, joints.length - 1);
    const y = (v) => H - pad - (H - 2 * pad) * (v - lo) / (hi - lo);
    g.clearRect(0, 0, W, H);
    g.strokeStyle = "#999"; g.strokeRect(pad, pad, W - 2 * pad, H - 2 * pad);
    g.fillStyle = "#333"; g.font = "11px sans-serif";
    g.fillText("joints: model (dashed) and target (solid), by step", pad, pad - 8);
    for (let j = 0; j < 5; j++) {
      [[wanted, []], [joints, [5, 4]]].forEach(([series, dash]) => {
        g.setLineDash(dash); g.strokeStyle = COLOURS[j]; g.beginPath();
        series.forEach((pose, t) => (t ? g.lineTo(x(t), y(pose[j])) : g.moveTo(x(t), y(pose[j]))));
        g.stroke();
      });
    }
    g.setLineDash([]);
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

  // NICO from above (x forward, up the page; y to NICO's left, to the left): the table, the cubes
  // where the recording has them, the fingertip's path (model dashed, recording solid) and the arm
  // at the model's last step, by forward kinematics of the model's own joint angles.
  function plotArm(canvas, episode, joints, wanted) {
    const m = window.pgae.manifest(), a = m.arm, g = canvas.getContext("2d"), W = canvas.width, H = canvas.height;
    const back = a.shoulder[0] - 0.05, scale = (H - 30) / (a.table_x[1] + 0.02 - back);   // NICO's shoulder in view
    const X = (p) => W / 2 - p[1] * scale, Y = (p) => H - 10 - (p[0] - back) * scale;
    g.clearRect(0, 0, W, H);
    g.fillStyle = "#eee3d2";
    g.fillRect(X([0, a.table_half_width]), Y([a.table_x[1], 0]), 2 * a.table_half_width * scale,
               (a.table_x[1] - a.table_x[0]) * scale);
    episode.cubes.forEach((xy, k) => {
      const [r, gr, b] = m.cube_rgba[episode.scene[k]], s = a.cube_size * scale;
      g.fillStyle = `rgb(${255 * r}, ${255 * gr}, ${255 * b})`;
      g.fillRect(X(xy) - s / 2, Y(xy) - s / 2, s, s);
    });
    [[wanted, []], [joints, [5, 4]]].forEach(([series, dash]) => {
      g.setLineDash(dash); g.strokeStyle = "#333"; g.beginPath();
      series.forEach((q, t) => { const tip = window.pgae.fk(q)[3]; t ? g.lineTo(X(tip), Y(tip)) : g.moveTo(X(tip), Y(tip)); });
      g.stroke();
    });
    g.setLineDash([]); g.strokeStyle = "#1f77b4"; g.lineWidth = 4; g.beginPath();
    window.pgae.fk(joints[joints.length - 1]).forEach((p, k) => (k ? g.lineTo(X(p), Y(p)) : g.moveTo(X(p), Y(p))));
    g.stroke(); g.lineWidth = 1;
    g.fillStyle = "#333"; g.font = "11px sans-serif";
    g.fillText("NICO from above: fingertip path (model dashed, target solid), arm at the last step", 5, 12);
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
    const button = element("button", {type: "button", text: "Run"});
    const said = element("pre", {class: "pgae-live-said"});
    const joints = element("canvas", {width: "640", height: "260"});
    const gate = element("canvas", {width: "640", height: "120"});
    const arm = element("canvas", {width: "640", height: "300"});
    root.textContent = "";
    [model, signal, episode, text, button].forEach(c => root.appendChild(c));
    [said, joints, gate, arm].forEach(c => root.appendChild(c));
    button.addEventListener("click", async () => {
      button.disabled = true;
      said.classList.remove("pgae-live-error");
      try {
        const t0 = performance.now();
        const r = await window.pgae.run({model: model.value, signal: signal.value, episode: episode.value,
                                         text: text.value});
        said.textContent = (r.understood !== null ? `I understood: ${r.understood || "<EOS>"}\n` : "") +
          `words: ${r.words || "<EOS>"}\ncomputed in this page in ${(performance.now() - t0).toFixed(0)} ms`;
        plotJoints(joints, r.joints, target(window.pgae.recorded(episode.value), signal.value));
        plotGate(gate, r.gate);
        const wanted = target(window.pgae.recorded(episode.value), signal.value);
        plotArm(arm, manifest.episodes.find(e => e.id === episode.value), r.joints, wanted);
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
