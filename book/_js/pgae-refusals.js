// What the robot will not do with a free instruction, and says instead, in the reader's page
// (not in the paper). The rule of pgae_lite/freeform/refusals.py, line for line, on the data the
// build writes for it (pgae_lite/web/refusal_data.py): the phrase lexicon's tables, WordNet's
// colour words and verbs, the world's colours and what the robot can do. pgae.js loads this file
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
  const unique = (xs) => [...new Set(xs)];                                   // dict.fromkeys: first order kept

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

  function make(shared, logic) {
    const negators = new Set(shared.negators), colourWords = new Set(shared.colour_words);
    const verbs = words(shared.verbs), colours = shared.colours;
    const say = (key, fields) => logic.say(key, fields), pyrepr = (s) => logic.pyrepr(s);
    const clauseEnd = new RegExp(shared.clause_end, "i"), stepEnd = new RegExp(shared.step_end, "i");
    const sceneText = (scene) => say("scene", {left: scene[0], right: scene[1]});

    return function reader(model) {
      const full = table(model.phrases), byVerbs = table(model.phrases_by_verbs), known = new Set(model.known);
      const isKnown = (w) => known.has(w) || w.includes("'");

      function negated(read) {                                           // refusals._negated
        const refused = [], speeds = [];
        for (const clause of read.split(clauseEnd)) {
          const ws = wordsOf(clause), at = ws.findIndex(w => negators.has(w) || w.endsWith("n't"));
          if (at < 0) continue;
          const scope = slotMeanings(ws.slice(at + 1).join(" "), full);
          if (scope.action.length || scope.colour.length) refused.push(ws.slice(at).join(" "));
          speeds.push(...scope.speed);
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
          const named = unique(wordsOf(read)).filter(w => !isKnown(w) && verbs.has(w));
          if (named.length) return say("cannot_verb", {verb: named[0], actions: shared.actions_said});
          return say("cannot_do", {text: pyrepr(text.trim()), actions: shared.actions_said});
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
        if (understood === null || said.colour.length) return null;
        const colour = understood.meaning ? understood.meaning[1] : null;  // the colour of the readback
        return colour === null || scene.includes(colour) ? null :
          say("understood_absent", {understood: pyrepr(understood.words), colour, scene: sceneText(scene)});
      }

      // refusals.refusal: text as typed, read after the word lookup, swapped its [word, replacement]s,
      // scene the (left, right) colours, understood {words, meaning (null if not a description)} or null.
      function refusal(text, read, swapped, scene, understood) {
        const [negations, negatedSpeeds] = negated(read);
        if (negations.length) {
          return say("negation", {text: pyrepr(text.trim()), negation: pyrepr(negations[0]),
                                  colour: scene ? scene[0] : colours[0]});
        }
        const said = slotMeanings(read, full);
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
