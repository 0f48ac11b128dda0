// The live playground's controls (chapter 08; its drawings are pgae-draw.js's): every element with class
// "pgae-live" becomes play's form (model, signal, cubes, action, variation, a text, the route)
// that calls window.pgae.run (pgae.js) and shows what play shows, computed in the page: what the
// model understood of a typed text, the words it wrote with the verdict and how sure it was of
// each, its joints against the signal's target, the GMU gate, and NICO's arm in 3-D, drawn from
// those joints by forward kinematics. Nothing here computes the model or moves a cube: it only
// collects and draws. Cubes move only along the simulator's own closed-loop run of exactly this
// model, episode and instruction, made when the book was built (result.simulated,
// window.pgae.simulated); otherwise they stay where the recording had them. Every choice, label and
// constant of Python's comes from the manifest (manifest.play).
(function () {
  "use strict";
  const {COLOURS, VIEW, plotJoints, plotGate, drawScene} = window.pgaeDraw;           // pgae-draw.js
  const PLAY_RATE = 20;      // steps per second on screen
  const UNSURE = 0.5;        // a word chosen with a lower probability is flagged as a guess

  function element(tag, attrs = {}, ...children) {
    const e = document.createElement(tag);
    Object.entries(attrs).forEach(([k, v]) => (k === "text" ? (e.textContent = v) : e.setAttribute(k, v)));
    children.forEach(c => e.appendChild(typeof c === "string" ? document.createTextNode(c) : c));
    return e;
  }
  function fill(select, options) {                        // options: [value, text]
    select.textContent = "";
    options.forEach(([value, text]) => select.appendChild(element("option", {value: String(value), text})));
  }
  // A control with its visible name above it; the control carries the same name for screen readers.
  function field(name, control) {
    control.setAttribute("aria-label", name);
    return element("label", {class: "pgae-live-field"}, element("span", {class: "pgae-live-name", text: name}), control);
  }

  window.pgaeWidget = async function (root) {
    root.textContent = "Loading the models (onnxruntime-web)...";
    let manifest, L;
    try {
      manifest = await window.pgae.load();
      L = window.pgae.logic();
    } catch (e) {
      root.textContent = `The live playground cannot start: ${e.message}`;
      return;
    }
    const P = manifest.play, names = Object.keys(manifest.models), first = manifest.episodes[0];
    const jointNames = P.joint_names || [0, 1, 2, 3, 4].map(j => `joint ${j + 1}`);
    const say = (words) => (words ? L.pyrepr(words) : "<EOS> alone");

    // ---- The form: play's choices.
    const model = element("select"), signal = element("select"), cubes = element("select"),
          action = element("select"), variation = element("select"), route = element("select");
    fill(model, names.map(m => [m, m]));
    fill(signal, P.signals.map(s => [s, s]));
    fill(cubes, P.arrangements.map(a => [a.number, a.label]));
    fill(action, P.actions.map(a => [a.number, a.label]));
    fill(route, P.routes.map(r => [r, P.route_labels[r]]));             // Python's Playground's labels
    cubes.value = String(first.arrangement); action.value = String(first.action);
    signal.value = P.default_signal;                                       // play's default signal
    const text = element("input", {type: "text", class: "pgae-live-text",
                                   placeholder: "or type a description, e.g. push red slowly; PGAE-BERT: any sentence"});
    const button = element("button", {type: "button", class: "pgae-live-run", text: "Run"});
    const routeField = field("act on", route), busy = element("span", {class: "pgae-live-busy", role: "status"});
    // The robot, as play's loop: the page runs no physics, so only the simulator's build-time run, or none.
    const robot = element("select", {class: "pgae-live-robot"});
    fill(robot, [["built", "closed loop, as run at build time"], ["none", "no robot"]]);
    const form = element("div", {class: "pgae-live-form"}, field("model", model), field("robot", robot),
                         field("signal", signal),
                         field("cubes", cubes), field("action", action), field("variation", variation),
                         element("label", {class: "pgae-live-field pgae-live-wide"},
                                 element("span", {class: "pgae-live-name", text: "text"}), text),
                         routeField, element("span", {class: "pgae-live-go"}, button, busy));
    text.setAttribute("aria-label", "text");
    button.setAttribute("aria-label", "Run");

    // The chosen pattern's recordings on this page: variation 0..n-1, each marked test or training.
    const pattern = () => L.scenePattern(Number(cubes.value), Number(action.value));
    const recordings = () => manifest.episodes.filter(e => e.pattern === pattern());
    function fillVariations(keep) {
      const mine = recordings();
      fill(variation, mine.length ? mine.map((e, k) => [k, `${k} (${e.split === "test" ? "test" : "training"})`])
                                  : [[0, "none on this page"]]);
      variation.value = String(Math.min(keep, Math.max(0, mine.length - 1)));
    }
    fillVariations(recordings().indexOf(first));
    const chosen = () => recordings()[Number(variation.value)] || null;
    // The route: only for the models that have one (free text under execute), each model's own by default.
    function showRoute() {
      const own = manifest.models[model.value].route;
      routeField.hidden = own === null || own === undefined;
      if (!routeField.hidden) route.value = own;
      route.disabled = signal.value !== P.route_signal;
      route.title = route.disabled ? `used only under ${P.route_signal}` : "";
    }
    model.addEventListener("change", showRoute);
    signal.addEventListener("change", () => { route.disabled = signal.value !== P.route_signal;
                                              route.title = route.disabled ? `used only under ${P.route_signal}` : ""; });
    showRoute();

    // ---- What a run shows, hidden until one succeeds.
    const error = element("p", {class: "pgae-live-error", role: "alert", hidden: ""});
    const cameraBox = element("div", {class: "pgae-live-camera"});
    const said = element("pre", {class: "pgae-live-said"});
    const sure = element("div", {class: "pgae-live-sure"});
    const play = element("input", {type: "button", class: "pgae-live-play", value: "Play", "aria-label": "play or pause"});
    const slider = element("input", {type: "range", class: "pgae-live-time", min: "0", max: "0", value: "0",
                                     "aria-label": "step"});
    const clock = element("span", {class: "pgae-live-clock"});
    const simBox = element("input", {type: "checkbox", checked: "", "aria-label": "show the simulator's arm"});
    const simToggle = element("label", {class: "pgae-live-simarm", hidden: ""}, simBox, " show the simulator's arm");
    const arm = element("canvas", {width: "640", height: "380", class: "pgae-live-arm",
                                   "aria-label": "NICO's arm in 3-D, drag to turn"});
    const armKey = element("p", {class: "pgae-live-caption"});
    const cubesNote = element("p", {class: "pgae-live-cubes"});
    const joints = element("canvas", {width: "640", height: "300", class: "pgae-live-joints",
                                      "aria-label": "the joints by step: model dashed, target solid"});
    const jointsTitle = element("p", {class: "pgae-live-caption"});
    const legend = element("div", {class: "pgae-live-legend"});
    jointNames.forEach((name, j) => legend.appendChild(element("span", {},
      element("span", {class: "pgae-live-swatch", style: `background: ${COLOURS[j]}`}), name)));
    legend.appendChild(element("span", {}, element("span", {class: "pgae-live-line pgae-live-dashed"}), "model"));
    legend.appendChild(element("span", {}, element("span", {class: "pgae-live-line"}), "target"));
    const gate = element("canvas", {width: "640", height: "110", class: "pgae-live-gate",
                                    "aria-label": "the GMU gate z per dimension of h"});
    const gateTitle = element("p", {class: "pgae-live-caption"});
    const result = element("div", {class: "pgae-live-result", hidden: ""}, said, sure, armKey, arm,
                           element("div", {class: "pgae-live-controls"}, play, slider, clock, simToggle),
                           cubesNote, jointsTitle, legend, joints, gateTitle, gate);
    root.textContent = "";
    [form, error, cameraBox, result].forEach(c => root.appendChild(c));

    // NICO's camera in an episode's recording (the build's PNGs), first and last step.
    function showCamera(ep) {
      cameraBox.textContent = "";
      if (!ep || !window.pgae.frame(ep.id, "first")) return;
      const frames = element("div", {class: "pgae-live-frames"});
      ["first", "last"].forEach(which => frames.appendChild(element("img", {
        src: window.pgae.frame(ep.id, which), width: "160", height: "120",
        alt: `NICO's camera at the ${which} step of ${ep.id}`})));
      cameraBox.append(frames, element("div", {class: "pgae-live-caption",
        text: `NICO's camera in the recording of ${ep.id} (${ep.split === "test" ? "test" : "training"}): ` +
              `${ep.description}, first and last step (what the model sees, not drawn by this page)`}));
    }
    const formChanged = () => { if (!running) showCamera(chosen()); };
    [cubes, action].forEach(c => c.addEventListener("change", () => { fillVariations(0); formChanged(); }));
    variation.addEventListener("change", formChanged);
    showCamera(chosen());

    // What is drawn: s (the run, its target, the episode, the simulator's run or null) at step t.
    const view = {...VIEW};
    let s = null, t = 0, playing = 0, last = null, running = false;
    const steps = () => Math.max(s.joints.length, s.sim ? s.sim.cubes.length : 0);
    function redraw() {
      if (!s) return;
      drawScene(arm, view, s, t);
      plotJoints(joints, s.joints, s.wanted, Math.min(t, s.joints.length - 1));
      slider.value = String(Math.round(t));
      clock.textContent = `step ${Math.round(t)} of ${steps() - 1} · ${(t / P.robot_rate).toFixed(2)} s of robot time ` +
                          `· played ${+(P.robot_rate / PLAY_RATE).toFixed(1)}× slower`;
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
      if (!s) return;
      if (playing) return setPlaying(false);
      if (t >= steps() - 1) t = 0;                                        // at the end: from the start again
      setPlaying(true);
    });
    slider.addEventListener("input", () => { setPlaying(false); t = Number(slider.value); redraw(); });
    simBox.addEventListener("change", () => { if (s) s.showSim = simBox.checked; redraw(); });
    // Turn the view by dragging: a drag across the whole canvas, as it is shown, turns it 1.5 pi.
    let drag = null;
    arm.addEventListener("pointerdown", (e) => { drag = [e.clientX, e.clientY]; arm.setPointerCapture(e.pointerId); });
    ["pointerup", "pointercancel"].forEach(k => arm.addEventListener(k, () => { drag = null; }));
    arm.addEventListener("pointermove", (e) => {
      if (!drag) return;
      const shown = arm.getBoundingClientRect(), turn = 1.5 * Math.PI;
      view.az -= (e.clientX - drag[0]) / shown.width * turn;
      view.el = Math.max(0.05, Math.min(1.5, view.el + (e.clientY - drag[1]) / shown.width * turn));
      drag = [e.clientX, e.clientY]; redraw();
    });

    // How sure the decoder was of each word it wrote: word, p, runner-up, its p; a low p flagged.
    function sureTable(caption, choices) {
      const table = element("table", {class: "pgae-live-choices"}, element("caption", {text: caption}));
      table.appendChild(element("tr", {}, ...["#", "word", "p", "runner-up", "p"].map(h => element("th", {text: h}))));
      choices.forEach((c, k) => {
        const guess = c.p < UNSURE, cell = element("td", {text: c.p.toFixed(2)});
        if (guess) cell.appendChild(element("span", {class: "pgae-live-guess-tag", text: " a guess"}));
        table.appendChild(element("tr", guess ? {class: "pgae-live-guess"} : {},
          element("td", {text: String(k + 1)}), element("td", {text: c.word}), cell,
          element("td", {text: c.runner_up}), element("td", {text: c.runner_up_p.toFixed(2)})));
      });
      return element("div", {class: "pgae-live-table"}, table);
    }
    const lowest = (choices) => choices.reduce((a, c) => (c.p < a.p ? c : a), choices[0]);
    function sureText(choices) {                                            // e.g. "lowest p 0.43 (red): a guess"
      if (!choices || !choices.length) return "";
      const low = lowest(choices);
      return ` (how sure: lowest p ${low.p.toFixed(2)}, ${low.word}${low.p < UNSURE ? ": a guess" : ""})`;
    }
    const line = (...parts) => {                          // one line of the summary (a block: wraps indented)
      const out = element("span", {class: "pgae-live-said-line"});
      parts.forEach(p => out.appendChild(typeof p === "string" ? document.createTextNode(p) : p));
      return out;
    };

    function showResult(r, ep, ms) {
      said.textContent = "";
      said.appendChild(line(`episode ${r.episode} (${r.split === "test" ? "test" : "training"}): ${ep.description} ` +
                            `(${ep.scene[0]} left, ${ep.scene[1]} right); the model reads ${L.pyrepr(r.told)}`));
      if (r.understood !== null) {
        said.appendChild(line(`I understood: ${r.understood || "<EOS>"}`,
                              element("span", {class: lowest(r.understood_choices || [{p: 1}]).p < UNSURE ?
                                                 "pgae-live-unsure" : "pgae-live-quiet",
                                               text: sureText(r.understood_choices)})));
      }
      if (r.note) said.appendChild(line(`note: ${r.note}`));
      if (r.route === "said back" && r.acted_on !== null) said.appendChild(line(`acted on (${r.route}): ${L.pyrepr(r.acted_on)}`));
      said.appendChild(r.correct
        ? line(`words: ${say(r.words)} `, element("span", {class: "pgae-live-right", text: "right"}),
               ` (${r.signal} asks for ${r.expected})`)
        : line("words: ", element("span", {class: "pgae-live-wrong",
               text: `wrong: wrote ${say(r.words)} where ${r.signal} asks for ${r.expected}`})));
      const mean = r.gate.reduce((a, b) => a + b, 0) / r.gate.length;
      said.appendChild(line(`joints: nRMSE ${r.nrmse.toFixed(2)}% of the joint range against ${P.targets[r.signal]}`));
      said.appendChild(line(`mean gate z ${mean.toFixed(2)} (0 = language, 1 = action)`));
      said.appendChild(line(`computed in this page in ${ms.toFixed(0)} ms`));

      sure.textContent = "";
      sure.appendChild(sureTable("how sure of each word it wrote", r.choices));
      if (r.understood_choices) sure.appendChild(sureTable("how sure of each word it said back", r.understood_choices));
      sure.appendChild(element("p", {class: "pgae-live-caption", text: `The decoder can only answer in the dataset's ` +
        `${manifest.vocabulary.length - 1} words: its last layer scores those and nothing else, so any sentence ` +
        "gets an answer; a low probability says it was a guess."}));

      jointsTitle.textContent = `${r.signal}: the joints (rad) by step, the model's (dashed) against the target ` +
                                `(solid), which is ${P.targets[r.signal]}`;
      gateTitle.textContent = `GMU gate z per dimension of h, mean ${mean.toFixed(2)} (dotted line; 0 language, 1 action)`;
      plotGate(gate, r.gate);
    }

    function clear() {                                                      // nothing stale stays drawn
      setPlaying(false);
      s = null;
      result.hidden = true;
      said.textContent = ""; sure.textContent = ""; cubesNote.textContent = "";
      [arm, joints, gate].forEach(c => c.getContext("2d").clearRect(0, 0, c.width, c.height));
    }

    async function runIt() {
      if (running) return;
      running = true; button.disabled = true; busy.textContent = "computing...";
      setPlaying(false);
      delete root.dataset.result;
      const args = {model: model.value, signal: signal.value, arrangement: Number(cubes.value),
                    action: Number(action.value), variation: Number(variation.value), text: text.value};
      if (!routeField.hidden) args.route = route.value;
      try {
        const t0 = performance.now();
        const r = await window.pgae.run(args), ms = performance.now() - t0;
        const ep = manifest.episodes.find(e => e.id === r.episode);
        // The cubes move only along the simulator's own build-time run of exactly this model, episode and instruction.
        const sim = r.simulated && robot.value === "built" ? await window.pgae.simulated(r.model, r.episode) : null;
        error.hidden = true; error.textContent = "";
        showResult(r, ep, ms);
        showCamera(ep);
        s = {joints: r.joints, wanted: r.target, episode: ep, sim, showSim: simBox.checked};
        armKey.textContent = "NICO's arm from the model's joints (blue), drawn by forward kinematics; its fingertip's " +
          "path: the model's (blue dashed), the target's (grey)" + (sim ? "; grey dashed arm: the simulator's measured " +
          "arm in its build-time run" : "") + ". Drag to turn.";
        cubesNote.textContent = "";
        if (sim) {
          cubesNote.append(`${sim.label} ${r.model}, told ${L.pyrepr(sim.description)} (${sim.kind}): `,
                           element("strong", {class: sim.passed ? "pgae-live-right" : "pgae-live-wrong",
                                              text: sim.passed ? "passed" : "failed"}),
                           ". The cubes move as they moved in that run.");
        } else if (robot.value === "none") {
          cubesNote.textContent = "No robot: the page shows what the model computed, its joints and NICO's arm drawn " +
            "from them by forward kinematics; the cubes stay where the recording had them.";
        } else {
          cubesNote.textContent = "The simulator ran only when the book was built, and only for each test episode's " +
            "own instruction; for this instruction the page shows what the model computed: its joints, and NICO's " +
            "arm drawn from them by forward kinematics. The cubes stay where the recording had them.";
        }
        simToggle.hidden = !sim;
        result.hidden = false;
        slider.max = String(steps() - 1);
        t = 0; redraw(); setPlaying(true);
        root.dataset.result = JSON.stringify(r);
      } catch (e) {
        clear();
        showCamera(chosen());
        error.textContent = `Cannot run this: ${e.message}`;
        error.hidden = false;
      } finally {
        running = false; button.disabled = false; busy.textContent = "";
      }
    }
    button.addEventListener("click", runIt);
    text.addEventListener("keydown", (e) => { if (e.key === "Enter") runIt(); });
  };
})();
