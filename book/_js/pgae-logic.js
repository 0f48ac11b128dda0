// What `play` decides, in the reader's page (not in the paper): the live playground's logic.
//
// pgae_lite.robot.playground.play reads the reader's choices and text, picks the episode, builds
// the signal's inputs and judges what the model wrote. The page does the same here, on the data
// Python writes at export (manifest.json, pgae_lite/web/assets.py): the vocabulary and signals,
// the form's choices (pgae_lite/web/episodes.py) and every message as Python's template
// (pgae_lite/web/messages.py), filled by say(). Nothing here types a sentence or a constant of
// Python's. tests/test_page_logic.py runs these functions against Python's own answers
// (parity.json, pgae_lite/web/parity.py) in a headless browser; pgae.js runs the models.
//
//   window.pgaeLogic.make(manifest) -> {say, normaliseTyped, readTyped, choose, inputs, decode, choices, ...}
(function () {
  "use strict";
  // Python's whitespace (str.split(), str.strip()): JavaScript's \s less U+FEFF, plus U+001C-U+001F, U+0085.
  const WHITE = "\\t\\n\\v\\f\\r\\x1c-\\x20\\x85\\xa0\\u1680\\u2000-\\u200a\\u2028\\u2029\\u202f\\u205f\\u3000";
  const RUNS = new RegExp(`[${WHITE}]+`, "u"), ENDS = new RegExp(`^[${WHITE}]+|[${WHITE}]+$`, "gu");
  const strip = (s) => s.replace(ENDS, "");                                       // str.strip()
  const split = (s) => (strip(s) ? strip(s).split(RUNS) : []);                    // str.split()
  const HIDDEN = /[\p{Cc}\p{Cf}\p{Cs}\p{Co}\p{Cn}\p{Zl}\p{Zp}\p{Zs}]/u;          // not str.isprintable()
  const hex = (c, n) => c.toString(16).padStart(n, "0");

  // Python's repr of a string: '...', or "..." when it holds a ' and no "; what is not printable escaped.
  function pyrepr(s) {
    const quote = s.includes("'") && !s.includes('"') ? '"' : "'", escapes = {"\\": "\\\\", "\t": "\\t",
      "\n": "\\n", "\r": "\\r", [quote]: "\\" + quote};
    let out = "";
    for (const ch of s) {                                                         // by code point
      const c = ch.codePointAt(0);
      out += escapes[ch] || (ch !== " " && HIDDEN.test(ch) ?
        (c < 0x100 ? "\\x" + hex(c, 2) : c < 0x10000 ? "\\u" + hex(c, 4) : "\\U" + hex(c, 8)) : ch);
    }
    return quote + out + quote;
  }

  // The name of a JSON value's type in Python, and its repr.
  function pytype(v) {
    if (v === null || v === undefined) return "NoneType";
    if (typeof v === "boolean") return "bool";
    if (typeof v === "number") return Number.isInteger(v) ? "int" : "float";
    if (typeof v === "string") return "str";
    return Array.isArray(v) ? "list" : "dict";
  }
  function pyvalue(v) {
    const type = pytype(v);
    if (type === "NoneType") return "None";
    if (type === "bool") return v ? "True" : "False";
    if (type === "float") return Number.isNaN(v) ? "nan" : !Number.isFinite(v) ? (v > 0 ? "inf" : "-inf") : String(v);
    if (type === "str") return pyrepr(v);
    if (type === "list") return `[${v.map(pyvalue).join(", ")}]`;
    if (type === "int") return String(v);
    return `{${Object.entries(v).map(([k, x]) => `${pyrepr(k)}: ${pyvalue(x)}`).join(", ")}}`;
  }

  function make(m) {
    const P = m.play, vocab = m.vocabulary;

    // A message: Python's template `key` with each {field} filled (pgae_lite/web/messages.py).
    function say(key, fields = {}) {
      if (!(key in m.messages)) throw new Error(`the page has no message ${pyrepr(key)}`);
      return m.messages[key].replace(/\{(\w+)\}/g, (_, name) => {
        if (!(name in fields)) throw new Error(`message ${key} needs its field ${name}`);
        return String(fields[name]);
      });
    }
    const fail = (key, fields) => { throw new Error(say(key, fields)); };

    // pgae_lite.util.checks.whole_number
    function wholeNumber(name, value, low, high = null) {
      const allowed = high === null ? say("whole_number_at_least", {low}) : say("whole_number_between", {low, high});
      const shown = pyvalue(value);
      if (pytype(value) !== "int") fail("whole_number_type", {name, allowed, value: shown, type: pytype(value)});
      if (value < low || (high !== null && value > high)) fail("whole_number_range", {name, allowed, value: shown});
      return value;
    }

    // pgae_lite.world.typed.normalise_typed: marks(NFKC(marks(text))), the marks' table written by Python
    // (manifest.typed.marks: each character -> what it is read as).
    const MARKS = m.typed.marks;
    const marks = (s) => { let out = ""; for (const ch of s) out += Object.hasOwn(MARKS, ch) ? MARKS[ch] : ch; return out; };
    const normaliseTyped = (text) => marks(marks(String(text)).normalize("NFKC"));

    // pgae_lite.world.words: normalise_signal, tokenize, parse_description
    function normaliseSignal(signal) {
      const key = strip(String(signal).replace(new RegExp(`[${WHITE}_:-]+`, "gu"), " ")).toLowerCase();
      if (!m.signals.includes(key)) fail("unknown_signal", {signal: pyvalue(signal), signals: m.signals.join(", ")});
      return key;
    }
    function tokenize(text) {
      const read = normaliseTyped(text);                              // as typed: curly marks, odd spaces, fullwidth
      const words = split(read.toLowerCase().split(vocab[0].toLowerCase()).join(" ").replace(/[.,;:!?]/g, " "));
      const tokens = [], unknown = [];
      for (let i = 0; i < words.length; i++) {
        const pair = words.slice(i, i + 2).join("-");
        if (i + 1 < words.length && vocab.includes(pair)) { tokens.push(pair); i++; }
        else (vocab.includes(words[i]) ? tokens : unknown).push(words[i]);
      }
      if (unknown.length) {
        const listed = [...new Set(unknown)];
        fail("unknown_words", {s: listed.length > 1 ? "s" : "", words: listed.map(pyrepr).join(", "),
                               text: pyrepr(text), vocabulary: vocab.filter(w => w !== vocab[0]).sort().join(", ")});
      }
      return tokens;
    }
    function parseDescription(text) {                                 // the canonical (action, colour, speed)
      const tokens = tokenize(text);
      if (tokens.length !== 3) fail("description_length", {count: tokens.length, text: pyrepr(text)});
      return tokens.map((token, k) => {
        const slot = m.slots[k], word = m.canonical[token];
        if (!slot.includes(word)) {
          fail("wrong_slot", {word: pyrepr(token), slot: m.slot_names[k], text: pyrepr(text),
                              allowed: slot.flatMap(w => [w, m.synonyms[w]]).join(", ")});
        }
        return word;
      });
    }

    // pgae_lite.robot.typed_text.read_typed: a description's words and meaning, or free text ({free: true}).
    function readTyped(model, signal, text) {
      try {
        const meaning = parseDescription(text);
        return {words: tokenize(text), meaning, free: false};
      } catch (e) {
        if (model.reads !== "features") fail("lstm_reads_vocabulary", {error: e.message});
        if (!m.reads_words[m.signals.indexOf(signal)]) {
          fail("signal_reads_no_words", {signal: pyrepr(signal), error: e.message});
        }
        return {words: null, meaning: null, free: true};
      }
    }

    // pgae_lite.bert.pretrained.input_text: the text after its signal's phrase.
    const inputText = (signal, text) => strip(`${signal} ${text}`);

    // Patterns (pgae_lite.world.patterns): 72 speed + 6 arrangement + k; the playground's action a is k = a % 6
    // at speed a // 6 (pgae_lite.robot.playground.scene_pattern).
    function scenePattern(arrangement, action) {
      wholeNumber("arrangement", arrangement, 0, P.scenes.length - 1);
      wholeNumber("action", action, 0, P.actions.length - 1);
      const k = P.action_sides.length;
      return P.scenes.length * k * Math.floor(action / k) + k * arrangement + action % k;
    }
    function patternOf(number) {                                     // Pattern.from_number
      const k = P.action_sides.length, per = P.scenes.length * k;
      const [left, right] = P.scenes[Math.floor(number % per / k)], [action, side] = P.action_sides[number % k];
      return {number, action, side, left, right, colour: side === "L" ? left : right,
              speed: P.speeds[Math.floor(number / per)], arrangement: Math.floor(number % per / k)};
    }
    function patternFor(meaning, arrangement) {                       // pgae_lite.robot.closedloop.pattern_for
      const [action, colour, speed] = meaning, [left, right] = P.scenes[arrangement];
      if (colour !== left && colour !== right) fail("no_cube_in_arrangement", {colour, arrangement, left, right});
      const k = P.action_sides.findIndex(([a, s]) => a === action && s === (colour === left ? "L" : "R"));
      const sides = P.action_sides.length;
      return P.scenes.length * sides * P.speeds.indexOf(speed) + sides * arrangement + k;
    }
    // playground.find_episode: the variation-th recording of a pattern among the page's episodes.
    function findEpisode(pattern, variation) {
      wholeNumber("pattern", pattern, 0, P.scenes.length * P.action_sides.length * P.speeds.length - 1);
      wholeNumber("variation", variation, 0);
      const mine = m.episodes.filter(e => e.pattern === pattern);
      if (variation < mine.length) return mine[variation];
      const p = patternOf(pattern), what = say("pattern_named", {pattern, action: p.action, colour: p.colour,
                                                                   speed: p.speed, left: p.left, right: p.right});
      if (!mine.length) {                              // the page holds a recording of every recorded pattern
        const have = [...new Set(m.episodes.map(e => P.arrangements.find(a => a.number === e.arrangement).label))];
        fail("no_recording", {where: say("this_dataset"), what, arrangements: have.sort().join("; ")});
      }                                                 // all of a test pattern's recordings, one of a training one's
      const where = mine[0].split === "test" ? say("this_dataset") : say("this_page");
      return fail("no_variation", {where, count: mine.length, what, variation});
    }

    // One episode's inputs under signal index s, as make_batch and episode_inputs build them (no opposite
    // view): tokens, the action steps shown, the decoder's vision and the start joints. `values`: the
    // episode's file, [v_t (30); j_t (5)] per step.
    const V = m.vision_dim, J = m.joint_dim, W = V + J;                // a step: [v_t (30); j_t (5)]
    function inputs(ep, values, s, words) {
      const n = ep.steps, at = ep.offset, step = (t) => values.subarray(at + W * t, at + W * (t + 1));
      const reads = m.reads_words[s], ids = (words || ep.description.split(" ")).map(w => vocab.indexOf(w));
      const tokens = [m.signal_token + s, ...(reads ? [...ids, m.eos] : [m.eos])];
      const shown = m.sees_action[s] ? n : 1;
      const held = s === m.describe ? n - 1 : s === m.repeat_language ? 0 : -1;   // one pose held, or none
      const dec = new Float32Array(V * (n - 1));
      for (let t = 0; t < n - 1; t++) dec.set(step(held >= 0 ? held : t).subarray(0, V), V * t);
      return {tokens, action: values.slice(at, at + W * shown), shown, dec,
              start: step(held >= 0 ? held : 0).slice(V, W), n};
    }

    // The recorded joints of an episode (steps, 5) in the data's units, from its file's values.
    function recorded(ep, values) {
      const out = [];
      for (let t = 0; t < ep.steps; t++) {
        out.push(Array.from(values.subarray(ep.offset + W * t + V, ep.offset + W * (t + 1)), toData));
      }
      return out;
    }

    // The words written, from the decoder's scores (4, V): greedy, up to <EOS> (words.decode).
    function decode(logits) {
      const words = [];
      for (const c of choices(logits)) {
        if (c.word === vocab[0]) break;
        words.push(c.word);
      }
      return words.join(" ");
    }
    // How sure of each word (play_result.word_choices): softmax, the best and the runner-up, up to <EOS>.
    function choices(logits) {
      const V = vocab.length, out = [];
      for (let k = 0; k < logits.length / V; k++) {
        const row = Array.from(logits.slice(V * k, V * (k + 1))), top = Math.max(...row);
        const e = row.map(x => Math.exp(x - top)), sum = e.reduce((a, b) => a + b, 0), p = e.map(x => x / sum);
        const best = p.indexOf(Math.max(...p)), rest = p.map((x, i) => (i === best ? -1 : x));
        const second = rest.indexOf(Math.max(...rest));
        out.push({word: vocab[best], p: p[best], runner_up: vocab[second], runner_up_p: p[second]});
        if (best === 0) break;
      }
      return out;
    }

    // words.is_correct against the episode's descriptions: a description of its meaning, or <EOS> alone.
    function isCorrect(words, s, meaning) {
      if (!m.lang_out[s]) return words === "";
      const ws = words ? words.split(" ") : [];
      return ws.length === 3 && ws.every((w, k) => m.canonical[w] === meaning[k]);
    }
    // instructions.acted_on: the readback where it is a description (hyphens read as spaces), else the text.
    function actedOn(understood, text) {
      try {
        parseDescription(understood);
        return understood.replace(/-/g, " ");
      } catch (e) {
        return text;
      }
    }
    // play's nRMSE: % of the joint range, over steps 1.. (joints and target in data units, (T, 5)).
    function nrmse(joints, target) {
      let sum = 0, count = 0;
      for (let t = 1; t < joints.length; t++) joints[t].forEach((v, j) => { sum += (v - target[t][j]) ** 2; count++; });
      return 100 * Math.sqrt(sum / count) / P.joint_range;
    }
    // The target of a signal's joints (play_result.TARGETS): the recording, or one pose held.
    function target(recorded, signal) {
      const s = m.signals.indexOf(signal);
      if (s === m.describe) return recorded.map(() => recorded[recorded.length - 1]);
      if (s === m.repeat_language) return recorded.map(() => recorded[0]);
      return recorded;
    }
    const [lo, hi] = m.joint_units, toData = (v) => (v + 1) * (hi - lo) / 2 + lo;   // [-1, 1] -> the data's units

    return {say, wholeNumber, normaliseTyped, normaliseSignal, tokenize, parseDescription, readTyped, inputText, scenePattern,
            patternOf, patternFor, findEpisode, inputs, recorded, decode, choices, isCorrect, actedOn, nrmse, target,
            toData,
            pyrepr, pyvalue, strip};
  }

  window.pgaeLogic = {make, pyrepr, pyvalue, pytype, strip, split};
})();
