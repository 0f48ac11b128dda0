// What the robot will not do with a free instruction, and says instead, in the reader's page
// (not in the paper). The rule of pgae_lite/freeform/refusals.py and its English classes
// (refusal_words.py), line for line, on the data the build writes for it (pgae_lite/web/refusal_data.py):
// the phrase lexicon's tables, WordNet's colour words and verbs, the world's colours and what the robot can do. pgae.js loads this file
// with the sentence encoder, on the first free text, and calls window.pgaeRefusals.make(shared, logic)
// once:
//
//   make(refusals.json, logic) -> reader(model's refusals.json) -> {refusal(text, read, swapped, scene, understood)}
//   disagreement(understood, chosen, logic)
//
// This file types no sentence: each one is a template of refusals.MESSAGES, which the build writes into
// the manifest's messages (pgae_lite/web/messages.py) and Python formats its own from. logic.say(key,
// fields) fills one (every {field} replaced by fields[field]; it throws if the key or a field is missing),
// logic.pyrepr(s) is Python's repr of a string. Each field is handed as a string, already written, as
// refusals.py hands it to str.format. refusal returns the sentence Python's CannotDo carries, or null:
// the robot may act.
(function () {
  "use strict";

  const wordsOf = (text) => text.toLowerCase().match(/[a-z']+/g) || [];     // phrase_lexicon.words_of
  const tokens = (text) => text.toLowerCase().match(/[a-z']+|[0-9]+/g) || []; // refusal_words.tokens
  const unique = (xs) => [...new Set(xs)];                                   // dict.fromkeys: first order kept
  const same = (xs, ys) => xs.length === ys.length && xs.every((x, i) => x === ys[i]);

  // The front coding of refusal_data.front_coded undone: each line, the shared prefix's length, then the rest.
  function words(coded) {
    const out = new Set();
    let before = "";
    for (const line of coded.split("\n")) {
      before = before.slice(0, line.charCodeAt(0) - 48) + line.slice(1);
      out.add(before);
    }
    return out;
  }

  // phrasings.slot_meanings: the meaning of each phrase of the table in the text, longest phrases first.
  function table(rows) {
    const map = new Map(rows.map(([phrase, slot, meaning]) => [phrase, slot === null ? null : [slot, meaning]]));
    return {map, longest: Math.max(...rows.map(([phrase]) => (phrase ? phrase.split(" ").length : 0)))};
  }
  function slotMeanings(text, t) {
    const ws = wordsOf(text), found = {action: [], colour: [], speed: []};
    let i = 0;
    while (i < ws.length) {
      let k = Math.min(t.longest, ws.length - i);
      for (; k > 0; k--) {
        const key = ws.slice(i, i + k).join(" ");
        if (t.map.has(key)) {
          const hit = t.map.get(key);
          if (hit) found[hit[0]].push(hit[1]);
          i += k;
          break;
        }
      }
      if (k === 0) i += 1;
    }
    return found;
  }

  // The closed classes of pgae_lite/freeform/refusal_words.py, line for line, on its lists (shared).
  function english(shared) {
    const S = (k) => new Set(shared[k]), negators = S("negators"), inverted = S("inverted"), asked = S("asked");
    const fillers = S("fillers"), omissions = S("omissions"), openers = S("openers"), always = S("always_quantified");
    const pronouns = S("plural_pronouns"), singular = S("cube_nouns"), plurals = S("cube_plurals");
    const repetitions = S("repetitions"), counts = S("counts"), units = S("action_plurals"), joiners = S("joiners");
    const notASide = S("not_a_side_after"), sides = shared.sides;

    function isNegator(ws, i) {                                          // refusal_words.is_negator
      const word = ws[i], after = i + 1 < ws.length ? ws[i + 1] : "";
      if (!negators.has(word) && !word.endsWith("n't")) return false;
      if ((inverted.has(word) && asked.has(after)) || (i > 0 && ws[i - 1] === "why")) return false;
      let k = i + 1;
      while (k < ws.length && fillers.has(ws[k])) k++;
      return !(k < ws.length && omissions.has(ws[k]));
    }
    function dismissed(clause) {                                         // refusal_words.dismissed
      const ws = tokens(clause);
      let k = 0;
      while (k < ws.length && openers.has(ws[k])) k++;
      return shared.dismissals.some(d => same(ws.slice(k, k + d.split(" ").length), d.split(" ")));
    }
    function quantified(text) {                                          // refusal_words.quantified
      const ws = tokens(text);
      for (let i = 0; i < ws.length; i++) {
        const w = ws[i];
        if (always.has(w) || plurals.has(w) || pronouns.has(w)) return w;
        if (shared.quantifiers.includes(w) &&
            (ws.slice(i + 1, i + 4).some(a => singular.has(a) || plurals.has(a) || a === "of" || a === "them") ||
             (i > 0 && pronouns.has(ws[i - 1])) || i === ws.length - 1)) return w;
      }
      return null;
    }
    function repetition(text) {                                          // refusal_words.repetition
      const ws = tokens(text), joined = ` ${ws.join(" ")} `;
      for (const phrase of shared.repeated_phrases) if (joined.includes(` ${phrase} `)) return phrase;
      for (let i = 0; i < ws.length; i++) {
        if (repetitions.has(ws[i])) return ws[i];
        if (counts.has(ws[i]) || (/^[0-9]+$/.test(ws[i]) && Number(ws[i]) > 1)) {
          for (let k = i + 1; k < Math.min(i + 4, ws.length); k++) if (units.has(ws[k])) return ws.slice(i, k + 1).join(" ");
        }
      }
      return null;
    }
    function directions(text, table) {                                   // refusal_words.directions
      const ws = tokens(text), found = [];
      const longest = Math.max(...Object.keys(table).map(p => p.split(" ").length));
      let i = 0;
      while (i < ws.length) {
        const after = i + 1 < ws.length ? ws[i + 1] : "";
        if (sides.includes(ws[i]) && !singular.has(after) && !plurals.has(after) &&
            !(ws[i] === "right" && notASide.has(after))) {
          found.push([i, i + 1, ws[i], ws[i]]);
          i += 1;
          continue;
        }
        let k = Math.min(longest, ws.length - i);
        for (; k > 0; k--) {
          const piece = ws.slice(i, i + k).join(" ");
          if (Object.hasOwn(table, piece)) { found.push([i, i + k, table[piece], piece]); i += k; break; }
        }
        if (k === 0) i += 1;
      }
      return found;
    }
    function oppositeWays(text, table) {                                 // refusal_words.opposite_ways
      const found = directions(text, table), ws = tokens(text);
      for (let j = 0; j + 1 < found.length; j++) {
        const [, end, meaning, said] = found[j], [start, , other, saidNext] = found[j + 1];
        if (meaning !== other && ws.slice(end, start).every(w => joiners.has(w))) return [said, saidNext];
      }
      return null;
    }
    return {isNegator, dismissed, quantified, repetition, directions, oppositeWays};
  }

  function make(shared, logic) {
    const colourWords = new Set(shared.colour_words), E = english(shared);
    const verbs = words(shared.verbs), colours = shared.colours;
    const say = (key, fields) => logic.say(key, fields), pyrepr = (s) => logic.pyrepr(s);
    const clauseEnd = new RegExp(shared.clause_end, "i"), stepEnd = new RegExp(shared.step_end, "i");
    const clauseEnds = new RegExp(shared.clause_end, "gi"), idioms = new RegExp(shared.idioms, "gi");
    const withoutIdioms = (text) => text.replace(idioms, m => " ".repeat(m.length));   // refusal_words.without_idioms
    const sceneText = (scene) => say("scene", {left: scene[0], right: scene[1]});

    return function reader(model) {
      const full = table(model.phrases), byVerbs = table(model.phrases_by_verbs), known = new Set(model.known);
      const isKnown = (w) => known.has(w) || w.includes("'"), untrusted = new Set(model.untrusted);

      function setAside(read) {                                          // refusals._set_aside
        const kept = [], acted = [];
        let at = 0;
        const ends = [...read.matchAll(clauseEnds)].map(m => [m.index, m.index + m[0].length]);
        for (const [start, end] of [...ends, [read.length, read.length]]) {
          const clause = read.slice(at, start), out = E.dismissed(clause);
          if (out && slotMeanings(clause, full).action.length) acted.push(wordsOf(clause).join(" "));
          kept.push(out ? " ".repeat(clause.length) : clause, read.slice(start, end));
          at = end;
        }
        return [kept.join(""), acted];
      }

      function negated(read) {                                           // refusals._negated
        const refused = [], speeds = [];
        for (const clause of read.split(clauseEnd)) {
          const ws = wordsOf(clause), at = ws.findIndex((w, i) => E.isNegator(ws, i));
          if (at < 0) continue;
          const scope = slotMeanings(ws.slice(at + 1).join(" "), full);
          if (scope.action.length || scope.colour.length) refused.push(ws.slice(at).join(" "));
          speeds.push(...scope.speed.map(s => [s, ws.slice(at).join(" ")]));
        }
        return [refused, speeds];
      }

      function moreThanOne(read, said, negatedSpeeds) {                   // refusals._more_than_one
        const speeds = said.speed.filter(s => !negatedSpeeds.includes(s));
        for (const [key, named] of [["several_actions", slotMeanings(read, byVerbs).action],
                                    ["several_cubes", said.colour], ["several_speeds", speeds]]) {
          const each = unique(named);
          if (each.length > 1) return say(key, {count: String(each.length), named: each.join(", ")});
        }
        const word = E.quantified(read), again = E.repetition(read);
        if (word) return say("several_cubes_said", {word: pyrepr(word)});
        if (again) return say("repeated", {words: pyrepr(again)});
        const ways = E.oppositeWays(read, model.directions);
        if (ways) return say("opposite_ways", {named: ways.map(pyrepr).join(", ")});
        const steps = read.split(stepEnd).filter(step => slotMeanings(step, full).action.length);
        return steps.length > 1 ? say("several_steps", {count: String(steps.length)}) : null;
      }

      function outsideTheWorld(text, read, said, swapped, scene) {        // refusals._outside_the_world
        const outside = unique(wordsOf(text)).filter(w => !swapped.some(([raw]) => raw === w) && !isKnown(w) &&
                                                      !colours.includes(w) && /^[a-z]{3,}$/.test(w) && colourWords.has(w));
        if (outside.length) {
          const andScene = scene ? say("and_scene", {scene: sceneText(scene)}) : "";
          return say("no_such_colour", {word: outside[0], colours: colours.slice(0, -1).join(", "),
                                        last: colours[colours.length - 1], and_scene: andScene});
        }
        if (!said.action.length) {
          const named = unique(wordsOf(text)).filter(w => !isKnown(w) && verbs.has(w));
          if (named.length) return say("cannot_verb", {verb: named[0], actions: shared.actions_said});
          return say("cannot_do", {text: pyrepr(text.trim()), actions: shared.actions_said});
        }
        const ways = new Set(E.directions(read, model.directions).map(d => d[2]));
        for (const [word, replacement] of swapped) {                     // the person's own word, judged as well
          const acts = untrusted.has(word.toLowerCase()) ? slotMeanings(replacement, full).action : [];
          if (acts.length && !acts.some(a => ways.has(a))) {
            return say("cannot_verb", {verb: word.toLowerCase(), actions: shared.actions_said});
          }
        }
        return null;
      }

      function absentCube(said, swapped, scene, understood) {            // refusals._absent_cube
        for (const colour of unique(said.colour)) {
          if (!scene.includes(colour)) {
            const hit = swapped.find(([, v]) => slotMeanings(v, full).colour.includes(colour));
            const asRead = hit ? say("as_read", {word: hit[0], colour}) : "";
            return say("absent_cube", {colour, as_read: asRead, scene: sceneText(scene)});
          }
        }
        if (understood === null) return null;                            // named or not: the readback's colour
        const colour = understood.meaning ? understood.meaning[1] : null;
        return colour === null || scene.includes(colour) ? null :
          say("understood_absent", {understood: pyrepr(understood.words), colour, scene: sceneText(scene)});
      }

      // refusals.refusal: text as typed (in its plain form, logic.normaliseTyped), read after the word lookup,
      // swapped its [word, replacement]s, scene the (left, right) colours, understood {words, meaning (null if
      // not a description)} or null.
      function refusal(text, lookedUp, swapped, scene, understood) {
        const example = scene ? scene[0] : colours[0], count = [...text].length;   // Python's len: code points
        if (count > shared.most_characters) {
          return say("too_long", {count: String(count), most: String(shared.most_characters), colour: example});
        }
        const [read, dismissals] = setAside(withoutIdioms(lookedUp));
        const [negatedNow, negated_] = negated(read), negations = [...dismissals, ...negatedNow];
        if (negations.length) {
          return say("negation", {text: pyrepr(text.trim()), negation: pyrepr(negations[0]), colour: example});
        }
        const said = slotMeanings(read, full), negatedSpeeds = negated_.map(([s]) => s);
        if (negated_.length && !said.speed.some(s => !negatedSpeeds.includes(s))) {
          const other = shared.speeds.filter(s => !negatedSpeeds.includes(s));
          return say("negated_speed", {text: pyrepr(text.trim()), negation: pyrepr(negated_[0][1]), colour: example,
                                       speed: other.length ? other[0] : shared.speeds[0]});
        }
        const several = moreThanOne(read, said, negatedSpeeds);
        if (several) {
          return say("one_at_a_time", {text: pyrepr(text.trim()), several});
        }
        return outsideTheWorld(text, read, said, swapped, scene) ||
               (scene ? absentCube(said, swapped, scene, understood) : null);
      }
      return {refusal};
    };
  }

  // refusals.disagreement: the readback {words, meaning} against the chosen episode's meaning.
  function disagreement(understood, chosen, logic) {
    const said = logic.say("chosen_episode", {chosen: chosen.join(" ")});
    if (!understood.meaning) {
      return logic.say("no_readback", {words: logic.pyrepr(understood.words || "<EOS>"), chosen: said});
    }
    return understood.meaning.join(" ") === chosen.join(" ") ? null :
      logic.say("asks_otherwise", {asked: understood.meaning.join(" "), chosen: said});
  }

  window.pgaeRefusals = {make, disagreement, slotMeanings};
})();
