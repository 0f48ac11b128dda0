// The live playground: PGAE runs in the reader's page, with no server (not in the paper).
//
// The book build writes the trained models as ONNX graphs and the test episodes into
// _static/web/ (pgae_lite/web/assets.py); onnxruntime-web (WebAssembly, vendored in
// _static/ort/) runs them here. One documented function:
//
//   window.pgae.run({model, signal, episode, text}) -> Promise of {words, understood, joints, gate, note}
//
// model: a name the playground offers ("PGAE", "PGAE-BERT", "PGAE-BERT-phrasings"); signal:
// "describe", "execute", "repeat action" or "repeat language"; episode: a test episode's id,
// e.g. "sim/116-0"; text (optional): a description (action colour speed) that replaces the
// episode's words, or, for the PGAE-BERT models, any sentence. words: what the model writes
// ("" for <EOS> alone); understood: the text said back under "repeat language" (null without
// text); joints: (steps, 5) in the data's units, step 0 the start pose, as
// pgae_lite.robot.playground.play returns them; gate: the GMU's z; note: for free text under
// execute, where the readback and the chosen episode disagree (PlayResult.note), else null. A bad
// argument rejects with the sentence Python gives. Each signal's inputs are built from the episode as
// pgae_lite.model.signals.make_batch builds them.
//
// Free text (a sentence that is not a description) runs the sentence encoder in the page: the
// tokenizer (@huggingface/tokenizers, vendored in _static/tokenizers/), the transformer below its
// top layer and the model's head, its own top layer and pooling (pgae_lite/web/sentence.py),
// after the variant's word lookup read from its table (pgae_lite/web/word_table.py). Those files
// are fetched on the first free text only (their bytes: results/live_playground.json). Under execute, free text the robot will not act on (a negation, two instructions, a
// cube that is not there: pgae_lite/freeform/refusals.py) rejects with Python's sentence
// (pgae-refusals.js), and the result's note says where the readback and the episode disagree.
//
//   window.pgae.readAs(model, text) -> Promise of the text as the model reads it (the variant's lookup).
//   window.pgae.frame(episode, "first" | "last") -> the URL of NICO's recorded camera frame, or null.
//   window.pgae.simulated(model, episode) -> Promise of null or the simulator's own closed-loop run
//   of that model on that episode, made when the book was built (pgae_lite/web/sim_runs.py).
(function () {
  "use strict";
  const BASE = new URL(".", document.currentScript.src);        // .../_static/
  let manifest = null, episodes = null, loading = null, freeText = null, simRuns = null;
  const sessions = {}, tables = {}, heads = {};

  // Python's repr of a string: '...', or "..." when it holds a ' and no "; backslashes and breaks escaped
  function pyrepr(s) {
    s = s.replace(/\\/g, "\\\\").replace(/\n/g, "\\n").replace(/\r/g, "\\r").replace(/\t/g, "\\t");
    return s.includes("'") && !s.includes('"') ? `"${s}"` : `'${s.replace(/'/g, "\\'")}'`;
  }

  function loadScript(src) {
    return new Promise((done, fail) => {
      const s = document.createElement("script");
      s.src = src; s.onload = done; s.onerror = () => fail(new Error(`cannot load ${src}`));
      document.head.appendChild(s);
    });
  }

  async function fetchOk(url) {
    const r = await fetch(url);
    if (!r.ok) throw new Error(`cannot load ${url} (HTTP ${r.status}): the book was built without its live models`);
    return r;
  }

  // Everything the page needs before a first run, fetched once however many callers ask at once.
  function load() {
    loading = loading || (async () => {
      const ortReady = loadScript(new URL("ort/ort.wasm.min.js", BASE).href).then(() => {
        ort.env.wasm.wasmPaths = new URL("ort/", BASE).href;
        ort.env.wasm.numThreads = 1;                              // a plain static server: no threads
      });
      const m = await (await fetchOk(new URL("web/manifest.json", BASE))).json();
      episodes = new Float32Array(await (await fetchOk(new URL(`web/${m.episodes_file}`, BASE))).arrayBuffer());
      await ortReady;
      manifest = m;
      return manifest;
    })();
    return loading;
  }

  async function session(name) {
    if (!sessions[name]) {
      const m = manifest.models[name];
      sessions[name] = ort.InferenceSession.create(new URL(`web/${m.file}`, BASE).href,
                                                   {executionProviders: ["wasm"]});
      if (m.table) {
        tables[name] = fetchOk(new URL(`web/${m.table}`, BASE)).then(r => r.arrayBuffer())
                                                               .then(b => new Float32Array(b));
      }
    }
    return sessions[name];
  }

  // pgae_lite.world.words: normalise_signal, tokenize, parse_description (same messages).
  function normaliseSignal(signal) {
    const key = String(signal).replace(/[\s_:-]+/g, " ").trim().toLowerCase();
    if (!manifest.signals.includes(key)) {
      throw new Error(`unknown signal ${pyrepr(String(signal))}; the signals are: ${manifest.signals.join(", ")}`);
    }
    return key;
  }

  function tokenize(text) {
    const vocab = manifest.vocabulary;
    const words = text.toLowerCase().replace(/<bos\/eos>/g, " ").replace(/[.,;:!?]/g, " ").split(/\s+/)
      .filter(Boolean);
    const tokens = [], unknown = [];
    for (let i = 0; i < words.length; i++) {
      const pair = words.slice(i, i + 2).join("-");
      if (i + 1 < words.length && vocab.includes(pair)) { tokens.push(pair); i++; }
      else (vocab.includes(words[i]) ? tokens : unknown).push(words[i]);
    }
    if (unknown.length) {
      const listed = [...new Set(unknown)];
      const known = vocab.filter(w => w !== vocab[0]).sort().join(", ");
      throw new Error(`unknown word${listed.length > 1 ? "s" : ""} ${listed.map(pyrepr).join(", ")} in ` +
                      `${pyrepr(text)}; the vocabulary is: ${known}`);
    }
    return tokens;
  }

  function parseDescription(text) {
    const tokens = tokenize(text);
    if (tokens.length !== 3) {
      throw new Error(`a description has 3 words (action colour speed), got ${tokens.length} in ${pyrepr(text)}`);
    }
    tokens.forEach((token, k) => {
      const slot = manifest.slots[k], canon = manifest.canonical[token];
      if (!slot.includes(canon)) {
        const allowed = slot.flatMap(w => [w, manifest.synonyms[w]]).join(", ");
        throw new Error(`${pyrepr(token)} cannot be the ${manifest.slot_names[k]} word in ${pyrepr(text)}; ` +
                        `allowed: ${allowed}`);
      }
    });
    return tokens;
  }

  // The canonical meaning (action, colour, speed) of a description, or null if it is none.
  function meaningOf(text) {
    try {
      return parseDescription(text || "").map(token => manifest.canonical[token]);
    } catch (e) {
      return null;
    }
  }

  // A typed text, read once (pgae_lite.robot.typed_text.read_typed): a description's words, or null for
  // free text, which only the PGAE-BERT models read, and only under a signal that reads words.
  function readTyped(model, s, text) {
    try {
      return parseDescription(text);
    } catch (e) {
      if (manifest.models[model].reads !== "features") {
        throw new Error("PGAE's LSTM reads only its vocabulary, in the order action colour speed " +
                        `(PGAE-BERT reads free text): ${e.message}`);
      }
      if (!manifest.reads_words[s]) {
        throw new Error(`${pyrepr(manifest.signals[s])} reads no words, so text can only pick the episode, ` +
                        `and that takes a description: ${e.message}`);
      }
      return null;
    }
  }

  // The sentence encoder, loaded on the first free text: the tokenizer and the shared transformer.
  function loadFreeText() {
    freeText = freeText || (async () => {
      const f = manifest.free_text, url = (p) => new URL(`web/${p}`, BASE).href;
      if (!f) throw new Error("this book was built without the sentence encoder: the page reads descriptions only");
      const [lib, json, vocab, config, transformer, shared] = await Promise.all([
        import(new URL("tokenizers/tokenizers.min.mjs", BASE).href),
        fetchOk(url(f.tokenizer)).then(r => r.json()), fetchOk(url(f.vocab)).then(r => r.text()),
        fetchOk(url(f.tokenizer_config)).then(r => r.json()),
        ort.InferenceSession.create(url(f.transformer), {executionProviders: ["wasm"]}),
        fetchOk(url(f.refusals)).then(r => r.json()),
        loadScript(new URL("pgae-refusals.js", BASE).href)]);
      json.model.vocab = Object.fromEntries(vocab.split("\n").map((token, id) => [token, id]));   // vocab.txt: by id
      return {tokenizer: new lib.Tokenizer(json, config), transformer, reader: window.pgaeRefusals.make(shared, pyrepr)};
    })();
    return freeText;
  }

  // One model's head graph, and its word table (pgae_lite/web/word_table.py; {} without a lookup), loaded once.
  const wordTables = {};
  function head(name) {
    heads[name] = heads[name] || ort.InferenceSession.create(new URL(`web/${manifest.models[name].head}`, BASE).href,
                                                             {executionProviders: ["wasm"]});
    return heads[name];
  }
  function wordTable(name) {
    const file = manifest.models[name].words;
    wordTables[name] = wordTables[name] || (file ? fetchOk(new URL(`web/${file}`, BASE)).then(r => r.json()) : {});
    return wordTables[name];
  }

  // One model's refusal rule (pgae-refusals.js on its refusals.json), loaded once.
  const refusalRules = {};
  function refusalRule(name) {
    refusalRules[name] = refusalRules[name] || Promise.all([
      loadFreeText(), fetchOk(new URL(`web/${manifest.models[name].refusals}`, BASE)).then(r => r.json())])
      .then(([{reader}, data]) => reader(data));
    return refusalRules[name];
  }

  // The words of a text, as pgae_lite.freeform.word_lookup splits them: letters, inner apostrophes.
  const WORD = /[\p{L}\p{Nl}\p{No}]+(?:'[\p{L}\p{Nl}\p{No}]+)*/gu;

  // The text as a model's encoder reads it (encoder.read_as): the variant's unknown words replaced.
  async function readAs(name, text) {
    await load();
    if (manifest.models[name]?.reads !== "features") return text;
    const words = await wordTable(name);
    return text.replace(WORD, w => words[w.toLowerCase()] || w);
  }

  // The words of a text the lookup replaces, [word, replacement] in the text's order (lookup.replacements).
  async function replacements(name, text) {
    const words = await wordTable(name);
    return [...new Set(text.match(WORD) || [])].filter(w => words[w.toLowerCase()])
      .map(w => [w, words[w.toLowerCase()]]);
  }

  // Free text's features (1, D) under signal s, as encoder.encode_texts computes them: the text after
  // the word lookup, the signal phrase first, tokenized, the transformer, then the model's head.
  async function sentenceFeatures(name, s, text) {
    const m = manifest.models[name], [{tokenizer, transformer}, graph] = await Promise.all(
      [loadFreeText(), head(name)]);
    const read = `${manifest.signals[s]} ${await readAs(name, text)}`.trim();
    if (m.fixed_from_table && read in manifest.fixed_texts) {       // a text it was trained on: its table
      await session(name);                                          // (which starts loading the table)
      const table = await tables[name], row = manifest.fixed_texts[read], D = m.features;
      return table.slice(D * row, D * (row + 1));
    }
    let ids = tokenizer.encode(read).ids;
    const most = manifest.free_text.max_tokens;                      // truncated as in Python, [SEP] kept
    if (ids.length > most) ids = [...ids.slice(0, most - 1), ids[ids.length - 1]];
    const shape = [1, ids.length], ones = new BigInt64Array(ids.length).fill(1n);
    const mask = new ort.Tensor("int64", ones, shape);
    const {below_top} = await transformer.run({
      input_ids: new ort.Tensor("int64", BigInt64Array.from(ids.map(BigInt)), shape), attention_mask: mask});
    return (await graph.run({below_top, mask})).features.data;   // its top layer, then its pooling
  }

  // One episode's inputs under one signal, as make_batch builds them (no opposite view).
  function inputs(ep, s, words) {
    const n = ep.steps, at = ep.offset, step = (t) => episodes.subarray(at + 35 * t, at + 35 * (t + 1));
    const readsWords = manifest.reads_words[s], seesAction = manifest.sees_action[s];
    const tokens = [manifest.signal_token + s, ...(readsWords ? [...words, manifest.eos] : [manifest.eos])];
    const shown = seesAction ? n : 1;
    const action = episodes.slice(at, at + 35 * shown);
    const held = s === manifest.describe ? n - 1 : s === manifest.repeat_language ? 0 : -1;
    const dec = new Float32Array(30 * (n - 1));
    for (let t = 0; t < n - 1; t++) dec.set(step(held >= 0 ? held : t).subarray(0, 30), 30 * t);
    const start = step(held >= 0 ? held : 0).slice(30, 35);
    return {tokens, action, shown, dec, start, n};
  }

  function decode(logits) {                                         // (4, V): argmax, up to <EOS>
    const V = manifest.vocabulary.length, words = [];
    for (let k = 0; k < 4; k++) {
      const row = Array.from(logits.subarray(V * k, V * (k + 1)));
      const w = row.indexOf(Math.max(...row));
      if (w === 0) break;
      words.push(manifest.vocabulary[w]);
    }
    return words.join(" ");
  }

  async function forward(name, x, features = null) {
    const m = manifest.models[name], sess = await session(name);
    let language;
    if (features) {                                                  // free text: the sentence encoder's
      language = new ort.Tensor("float32", features, [1, m.features]);
    } else if (m.reads === "tokens") {
      language = new ort.Tensor("int64", BigInt64Array.from(x.tokens.map(BigInt)), [1, x.tokens.length]);
    } else {                                                        // PGAE-BERT: the encoder's features
      const key = [...x.tokens, ...Array(5 - x.tokens.length).fill(manifest.eos)].join(",");
      const row = manifest.fixed_rows[key], table = await tables[name], D = m.features;
      language = new ort.Tensor("float32", table.slice(D * row, D * (row + 1)), [1, D]);
    }
    const out = await sess.run({
      language, action_input: new ort.Tensor("float32", x.action, [1, x.shown, 35]),
      dec_vision: new ort.Tensor("float32", x.dec, [1, x.n - 1, 30]),
      start: new ort.Tensor("float32", x.start, [1, 5])});
    return out;
  }

  async function run({model, signal, episode, text} = {}) {
    await load();
    if (!(model in manifest.models)) {
      throw new Error(`unknown model ${pyrepr(String(model))}; the models are: ${Object.keys(manifest.models).join(", ")}`);
    }
    const s = manifest.signals.indexOf(normaliseSignal(signal));
    const ep = manifest.episodes.find(e => e.id === episode);
    if (!ep) throw new Error(`no test episode ${pyrepr(String(episode))}; e.g. ${manifest.episodes[0].id}`);
    text = (text || "").trim();
    const typed = text ? readTyped(model, s, text) : null, free = Boolean(text) && typed === null;
    if (text && !free && !manifest.reads_words[s]) {
      throw new Error(`${pyrepr(manifest.signals[s])} reads no words: a text only picks the episode here, ` +
                      "so choose the episode instead");
    }
    const words = (typed || ep.description.split(" ")).map(w => manifest.vocabulary.indexOf(w));
    const said = (signal) => (free ? sentenceFeatures(model, signal, text) : null);
    let understood = null, note = null;
    if (text) {                                                     // the text said back, no action shown
      const back = manifest.repeat_language;
      understood = decode((await forward(model, inputs(ep, back, words), await said(back))).logits.data);
    }
    if (free && manifest.signals[s] === "execute") {                 // the robot acts: first, whether it can
      const back = {words: understood, meaning: meaningOf(understood)};
      const rule = await refusalRule(model);
      const why = rule.refusal(text, await readAs(model, text), await replacements(model, text), ep.scene, back);
      if (why) throw new Error(why);
      note = window.pgaeRefusals.disagreement(back, ep.meaning, pyrepr);
    }
    const x = inputs(ep, s, words), out = await forward(model, x, await said(s));
    const [lo, hi] = manifest.joint_units;
    const units = (v) => (v + 1) * (hi - lo) / 2 + lo;                // [-1, 1] -> the data's units
    const joints = [Array.from(x.start, units)];
    const J = out.joints.data;
    for (let t = 0; t < x.n - 1; t++) joints.push(Array.from(J.subarray(5 * t, 5 * (t + 1)), units));
    return {words: decode(out.logits.data), understood, joints, gate: Array.from(out.gate.data), note};
  }

  // The recorded joints of an episode (steps, 5), in the data's units: what execute should write.
  function recorded(episode) {
    const ep = manifest.episodes.find(e => e.id === episode), [lo, hi] = manifest.joint_units, out = [];
    for (let t = 0; t < ep.steps; t++) {
      const at = ep.offset + 35 * t + 30;                             // [v_t (30); j_t (5)], j_t normalised
      out.push(Array.from(episodes.subarray(at, at + 5), v => (v + 1) * (hi - lo) / 2 + lo));
    }
    return out;
  }

  // NICO's arm at joint angles q (radians): the shoulder, elbow, wrist and fingertip (pgae-arm.js).
  const fk = (q) => window.pgaeArm.fk(manifest.arm, q);

  // The simulator's own closed-loop run of a model on an episode, made when the book was built, or null.
  async function simulated(model, episode) {
    await load();
    if (!manifest.sim_runs) return null;
    simRuns = simRuns || fetchOk(new URL(`web/${manifest.sim_runs}`, BASE)).then(r => r.json());
    const all = await simRuns, r = all.runs.find(r => r.model === model && r.episode === episode);
    return r ? {label: all.label, ...r} : null;
  }

  // The URL of NICO's recorded camera frame of an episode ("first" or "last" step), or null.
  const frame = (episode, which) => (manifest.frames ? new URL(`web/${manifest.frames.replace(
    "{episode}", String(episode).replace(/^sim\//, "")).replace("{which}", which)}`, BASE).href : null);

  window.pgae = {run, load, recorded, fk, simulated, readAs, frame, manifest: () => manifest};
  document.addEventListener("DOMContentLoaded", () => {
    document.querySelectorAll(".pgae-live").forEach(el => window.pgaeWidget && window.pgaeWidget(el));
  });
})();
