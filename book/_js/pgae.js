// The live playground: `play` in the reader's page, with no server (not in the paper).
//
// The book build writes the trained models as ONNX graphs, the episodes and what the page
// computes with into _static/web/ (pgae_lite/web/assets.py); onnxruntime-web (WebAssembly,
// vendored in _static/ort/) runs the graphs here. One documented function, the page's
// pgae_lite.robot.playground.play:
//
//   window.pgae.run({model, signal, arrangement, action, variation, text, route}) -> Promise of a result
//
// The choices are play's: model (a name the manifest offers), signal ("describe", "execute",
// "repeat action", "repeat language"), arrangement (0-11) and action (0-11) name a pattern, variation
// its recording (from 0); or episode, an episode's id ("sim/116-0") in place of the three. text: a
// description (action colour speed, any synonym), which then picks the episode in the chosen
// arrangement, or, for the PGAE-BERT models, any sentence. route: how free text under execute is
// acted on, "direct" or "said back" (default: the model's own, manifest.models[m].route, from its
// recipe: pgae_lite.robot.instructions.default_route). The result holds what play's PlayResult holds
// (signal, pattern, variation, episode, told, words, correct, understood, note, route, acted_on,
// choices and understood_choices: how sure of each word, joints and target (steps, 5) in the data's
// units, nrmse, gate), with expected (what the signal asks the words to be), split ("test" or
// "train") and simulated: whether the simulator ran exactly this (model, episode, instruction) when the
// book was built (window.pgae.simulated fetches that run). The page's episodes: every test episode and
// the first recording of each training pattern. A bad choice rejects with the sentence Python gives.
//
// The decisions (reading text, picking the episode, the inputs, the verdict) are pgae-logic.js's;
// free text the robot will not act on is pgae-refusals.js's. Free text runs the sentence encoder in
// the page: the tokenizer (@huggingface/tokenizers, vendored), the transformer below its top layer and
// the model's head (pgae_lite/web/sentence.py), after the variant's word lookup read from its table
// (pgae_lite/web/word_table.py); those files are fetched on the first free text only.
//
//   window.pgae.readAs(model, text) -> Promise of the text as the model reads it (the variant's lookup).
//   window.pgae.refusal(model, text, scene, understood) -> Promise of why the robot will not act on it, or null.
//   window.pgae.frame(episode, "first" | "last") -> the URL of NICO's recorded camera frame, or null.
//   window.pgae.simulated(model, episode) -> Promise of null or the simulator's closed-loop run at build time.
//   window.pgae.fk(q) -> NICO's shoulder, elbow, wrist and fingertip at joint angles q (pgae-arm.js).
(function () {
  "use strict";
  const BASE = new URL(".", document.currentScript.src);        // .../_static/
  let manifest = null, L = null, loading = null, freeText = null, simRuns = null;
  const sessions = {}, tables = {}, heads = {}, values = {}, wordTables = {}, refusalRules = {};

  function loadScript(src) {
    return new Promise((done, fail) => {
      const s = document.createElement("script");
      s.src = src; s.onload = done; s.onerror = () => fail(new Error(`cannot load ${src}`));
      document.head.appendChild(s);
    });
  }

  async function fetchOk(url) {
    const r = await fetch(url);
    if (!r.ok) {
      const message = L ? L.say("cannot_load", {url, status: r.status}) : `cannot load ${url} (HTTP ${r.status})`;
      throw new Error(message);
    }
    return r;
  }
  const web = (path) => new URL(`web/${path}`, BASE).href;

  // Everything the page needs before a first run, fetched once however many callers ask at once.
  function load() {
    loading = loading || (async () => {
      const ready = Promise.all([loadScript(new URL("ort/ort.wasm.min.js", BASE).href).then(() => {
        ort.env.wasm.wasmPaths = new URL("ort/", BASE).href;
        ort.env.wasm.numThreads = 1;                              // a plain static server: no threads
      }), window.pgaeLogic ? null : loadScript(new URL("pgae-logic.js", BASE).href)]);
      const m = await (await fetchOk(web("manifest.json"))).json();
      await ready;
      L = window.pgaeLogic.make(m);
      manifest = m;
      await episodeValues("test");
      return manifest;
    })();
    return loading;
  }

  // The values of one episode file ("test": with the models; "train": when a training episode is first chosen).
  function episodeValues(split) {
    values[split] = values[split] || fetchOk(web(manifest.episodes_files[split]))
      .then(r => r.arrayBuffer()).then(b => new Float32Array(b));
    return values[split];
  }

  async function session(name) {
    if (!sessions[name]) {
      const m = manifest.models[name];
      sessions[name] = ort.InferenceSession.create(web(m.file), {executionProviders: ["wasm"]});
      if (m.table) tables[name] = fetchOk(web(m.table)).then(r => r.arrayBuffer()).then(b => new Float32Array(b));
    }
    return sessions[name];
  }

  // The sentence encoder, loaded on the first free text: the tokenizer and the shared transformer.
  function loadFreeText() {
    freeText = freeText || (async () => {
      const f = manifest.free_text;
      if (!f) throw new Error(L.say("no_sentence_encoder"));
      const [lib, json, vocab, config, transformer, shared] = await Promise.all([
        import(new URL("tokenizers/tokenizers.min.mjs", BASE).href),
        fetchOk(web(f.tokenizer)).then(r => r.json()), fetchOk(web(f.vocab)).then(r => r.text()),
        fetchOk(web(f.tokenizer_config)).then(r => r.json()),
        ort.InferenceSession.create(web(f.transformer), {executionProviders: ["wasm"]}),
        fetchOk(web(f.refusals)).then(r => r.json()),
        loadScript(new URL("pgae-refusals.js", BASE).href)]);
      json.model.vocab = Object.fromEntries(vocab.split("\n").map((token, id) => [token, id]));   // vocab.txt: by id
      return {tokenizer: new lib.Tokenizer(json, config), transformer, reader: window.pgaeRefusals.make(shared, L)};
    })();
    return freeText;
  }

  function head(name) {                                               // one model's head graph, loaded once
    heads[name] = heads[name] || ort.InferenceSession.create(web(manifest.models[name].head),
                                                             {executionProviders: ["wasm"]});
    return heads[name];
  }
  function wordTable(name) {                                          // its word table ({} without a lookup)
    const file = manifest.models[name].words;
    wordTables[name] = wordTables[name] || (file ? fetchOk(web(file)).then(r => r.json()) : Promise.resolve({}));
    return wordTables[name];
  }
  function refusalRule(name) {                                        // its refusal rule, loaded once
    refusalRules[name] = refusalRules[name] || Promise.all([
      loadFreeText(), fetchOk(web(manifest.models[name].refusals)).then(r => r.json())])
      .then(([{reader}, data]) => reader(data));
    return refusalRules[name];
  }

  // The words of a text, as pgae_lite.freeform.word_lookup splits them: letters, inner apostrophes.
  const WORD = /[\p{L}\p{Nl}\p{No}]+(?:'[\p{L}\p{Nl}\p{No}]+)*/gu;

  // The text as a model's encoder reads it (encoder.read_as): the variant's unknown words replaced, in the
  // text's plain form (its lookup reads the text as typed.normalise_typed gives it; L.normaliseTyped).
  async function readAs(name, text) {
    await load();
    if (manifest.models[name]?.reads !== "features" || !manifest.models[name].words) return text;
    const words = await wordTable(name);
    return L.normaliseTyped(text).replace(WORD, w => words[w.toLowerCase()] || w);
  }
  // The words of a text the lookup replaces, [word, replacement] in the text's order (lookup.replacements).
  async function replacements(name, text) {
    const words = await wordTable(name);
    text = L.normaliseTyped(text);
    return [...new Set(text.match(WORD) || [])].filter(w => words[w.toLowerCase()])
      .map(w => [w, words[w.toLowerCase()]]);
  }

  // encoder.encode_texts([told]) (1, D): the text read through the lookup; a text the tuned variant was
  // trained on comes from its table, any other runs the tokenizer, the transformer and the model's head.
  async function encodeText(name, told) {
    const m = manifest.models[name];
    const [{tokenizer, transformer}, graph] = await Promise.all([loadFreeText(), head(name)]);
    const read = await readAs(name, told);
    if (m.fixed_from_table && read in manifest.fixed_texts) {
      await session(name);                                          // (which starts loading the table)
      const table = await tables[name], row = manifest.fixed_texts[read], D = m.features;
      return table.slice(D * row, D * (row + 1));
    }
    let ids = tokenizer.encode(read).ids;
    const most = manifest.free_text.max_tokens;                      // truncated as in Python, [SEP] kept
    if (ids.length > most) ids = [...ids.slice(0, most - 1), ids[ids.length - 1]];
    const shape = [1, ids.length], mask = new ort.Tensor("int64", new BigInt64Array(ids.length).fill(1n), shape);
    const {below_top} = await transformer.run({
      input_ids: new ort.Tensor("int64", BigInt64Array.from(ids.map(BigInt)), shape), attention_mask: mask});
    return (await graph.run({below_top, mask})).features.data;      // its top layer, then its pooling
  }

  // The graph on one episode's inputs x; `features`: free text's, else the tokens (or PGAE-BERT's table row).
  async function forward(name, x, features = null) {
    const m = manifest.models[name], sess = await session(name);
    let language;
    if (features) {
      language = new ort.Tensor("float32", features, [1, m.features]);
    } else if (m.reads === "tokens") {
      language = new ort.Tensor("int64", BigInt64Array.from(x.tokens.map(BigInt)), [1, x.tokens.length]);
    } else {                                                        // PGAE-BERT: the encoder's features
      const key = [...x.tokens, ...Array(5 - x.tokens.length).fill(manifest.eos)].join(",");
      const row = manifest.fixed_rows[key], table = await tables[name], D = m.features;
      language = new ort.Tensor("float32", table.slice(D * row, D * (row + 1)), [1, D]);
    }
    const V = manifest.vision_dim, J = manifest.joint_dim;
    return sess.run({language, action_input: new ort.Tensor("float32", x.action, [1, x.shown, V + J]),
                     dec_vision: new ort.Tensor("float32", x.dec, [1, x.n - 1, V]),
                     start: new ort.Tensor("float32", x.start, [1, J])});
  }

  // A readback as the refusal rule reads it: its words, and its meaning if it is a description.
  function readback(understood) {
    try {
      return {words: understood, meaning: L.parseDescription(understood)};
    } catch (e) {
      return {words: understood, meaning: null};
    }
  }

  // Why the robot will not act on free text (refusals.refusal), or null: scene [left, right] or null,
  // understood the model's readback or null.
  async function refusal(model, text, scene = null, understood = null) {
    await load();
    text = L.normaliseTyped(text);                                    // as typed (refusal reads its plain form)
    const rule = await refusalRule(model);
    return rule.refusal(text, await readAs(model, text), await replacements(model, text), scene,
                        understood === null ? null : readback(understood));
  }

  // play's choice of episode: an id, or (arrangement, action) and variation, or what a description asks for.
  function place(args) {
    if (args.episode === undefined) return [args.arrangement, args.action, args.variation ?? 0];
    const ep = manifest.episodes.find(e => e.id === args.episode);
    if (!ep) throw new Error(L.say("no_episode", {episode: L.pyvalue(args.episode), example: manifest.episodes[0].id}));
    return [ep.arrangement, ep.action, manifest.episodes.filter(e => e.pattern === ep.pattern).indexOf(ep)];
  }

  async function run(args = {}) {
    await load();
    const {model} = args, m = Object.hasOwn(manifest.models, model) ? manifest.models[model] : null;
    if (!m) {
      const models = Object.keys(manifest.models).join(", ");
      throw new Error(L.say("unknown_model", {model: L.pyvalue(model), models}));
    }
    // In play's order: the scene, the signal, the route, the text, the pattern, the episode.
    const [arrangement, action, variation] = place(args);
    L.scenePattern(arrangement, action);
    const signal = L.normaliseSignal(args.signal ?? "execute"), s = manifest.signals.indexOf(signal);
    const text = L.strip(L.normaliseTyped(args.text == null ? "" : String(args.text))), route = args.route ?? (m.route || "direct");
    const routes = manifest.play.routes;                                // instructions.check_route
    if (!routes.includes(route)) throw new Error(L.say("unknown_route", {route: L.pyvalue(route),
                                                                         routes: routes.map(L.pyrepr).join(", ")}));
    const typed = text ? L.readTyped(m, signal, text) : null, words = typed ? typed.words : null;
    const pattern = words ? L.patternFor(typed.meaning, arrangement) : L.scenePattern(arrangement, action);
    const ep = L.findEpisode(pattern, variation), episode = await episodeValues(ep.split);
    const reads = manifest.reads_words[s], free = Boolean(reads && typed && typed.free);
    let said = text || ep.description;                                 // the words the task may read
    let told = L.inputText(signal, reads ? (typed ? await readAs(model, text) : said) : "");

    let understood = null, understoodChoices = null, note = null, acted = null, language = null;
    if (reads && text) {                                              // readback: said back, no action shown
      const back = await forward(model, L.inputs(ep, episode, manifest.repeat_language, words),
                                 free ? await encodeText(model, L.inputText("repeat language", text)) : null);
      understood = L.decode(back.logits.data);
      understoodChoices = L.choices(back.logits.data);
    }
    if (free && signal === "execute") {                               // the robot acts: first, whether it can
      const p = L.patternOf(pattern), why = await refusal(model, text, [p.left, p.right], understood);
      if (why) throw new Error(why);
      note = window.pgaeRefusals.disagreement(readback(understood), [p.action, p.colour, p.speed], L);
    }
    const routed = free && signal === "execute" ? route : null;
    if (routed === "said back") {                                     // act on its own words
      said = acted = L.actedOn(understood, said);
      told = L.inputText(signal, said);
      language = await encodeText(model, told);
    } else if (free) {
      language = await encodeText(model, L.inputText(signal, text));
    }
    const x = L.inputs(ep, episode, s, words), out = await forward(model, x, language);
    const J = out.joints.data, joints = [Array.from(x.start, L.toData)];
    const D = manifest.joint_dim;
    for (let t = 0; t < x.n - 1; t++) joints.push(Array.from(J.subarray(D * t, D * (t + 1)), L.toData));
    const target = L.target(L.recorded(ep, episode), signal), written = L.decode(out.logits.data);
    return {model, signal, pattern, variation: Number(ep.id.split("-").pop()), episode: ep.id, split: ep.split, told,
            words: written, correct: L.isCorrect(written, s, patternMeaning(pattern)),
            expected: manifest.play.expected[signal], understood, note, route: routed, acted_on: acted,
            choices: L.choices(out.logits.data), understood_choices: understoodChoices, joints, target,
            nrmse: L.nrmse(joints, target), gate: Array.from(out.gate.data),
            simulated: signal === "execute" && (manifest.sim_run_episodes || []).includes(ep.id) &&
                       told === L.inputText("execute", ep.description)};
  }
  const patternMeaning = (pattern) => { const p = L.patternOf(pattern); return [p.action, p.colour, p.speed]; };

  // The simulator's own closed-loop run of a model on an episode, made when the book was built, or null.
  async function simulated(model, episode) {
    await load();
    if (!manifest.sim_runs) return null;
    simRuns = simRuns || fetchOk(web(manifest.sim_runs)).then(r => r.json());
    const all = await simRuns, r = all.runs.find(r => r.model === model && r.episode === episode);
    return r ? {label: all.label, ...r} : null;
  }

  // The URL of NICO's recorded camera frame of an episode ("first" or "last" step), or null.
  const frame = (episode, which) => (manifest.frames ? web(manifest.frames.replace(
    "{episode}", String(episode).replace(/^sim\//, "")).replace("{which}", which)) : null);
  const fk = (q) => window.pgaeArm.fk(manifest.arm, q);

  window.pgae = {run, load, simulated, readAs, replacements, refusal, frame, fk,
                 manifest: () => manifest, logic: () => L};
  document.addEventListener("DOMContentLoaded", () => {
    document.querySelectorAll(".pgae-live").forEach(el => window.pgaeWidget && window.pgaeWidget(el));
  });
})();
