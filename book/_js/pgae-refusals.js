// What the robot will not do with a free instruction, and says instead, in the reader's page
// (not in the paper). The rule of pgae_lite/freeform/refusals.py, line for line, on the data the
// build writes for it (pgae_lite/web/refusal_data.py): the phrase lexicon's tables, and WordNet's
// colour words and verbs. pgae.js loads this file with the sentence encoder, on the first free
// text, and calls window.pgaeRefusals.make(shared, pyrepr) once:
//
//   reader(model's refusals.json) -> {refusal(text, read, swapped, scene, understood), disagreement}
//
// refusal returns the sentence Python's CannotDo carries, or null: the robot may act.
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

  function make(shared, pyrepr) {
    const negators = new Set(shared.negators), colourWords = new Set(shared.colour_words);
    const verbs = words(shared.verbs), colours = shared.colours;
    const clauseEnd = new RegExp(shared.clause_end, "i"), stepEnd = new RegExp(shared.step_end, "i");
    const sceneText = (scene) => `the cubes here are ${scene[0]} (left) and ${scene[1]} (right)`;

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
        for (const [slot, named] of [["action", slotMeanings(read, byVerbs).action], ["cube", said.colour],
                                     ["speed", speeds]]) {
          const each = unique(named);
          if (each.length > 1) return `${each.length} ${slot}s (${each.join(", ")})`;
        }
        const steps = read.split(stepEnd).filter(step => slotMeanings(step, full).action.length);
        return steps.length > 1 ? `${steps.length} steps` : null;
      }

      function outsideTheWorld(text, read, said, swapped, scene) {        // refusals._outside_the_world
        const outside = unique(wordsOf(text)).filter(w => !swapped.some(([raw]) => raw === w) && !isKnown(w) &&
                                                      !colours.includes(w) && /^[a-z]{3,}$/.test(w) && colourWords.has(w));
        if (outside.length) {
          return `I know no ${outside[0]} cube: the cubes of this world are ${colours.slice(0, -1).join(", ")} or ` +
                 `${colours[colours.length - 1]}` + (scene ? `, and ${sceneText(scene)}` : "");
        }
        if (!said.action.length) {
          const named = unique(wordsOf(read)).filter(w => !isKnown(w) && verbs.has(w));
          const what = named.length ? `'${named[0]}' a cube` : `do ${pyrepr(text.trim())}`;
          return `I can't ${what}: I can ${shared.actions_said}`;
        }
        return null;
      }

      function absentCube(said, swapped, scene, understood) {            // refusals._absent_cube
        for (const colour of unique(said.colour)) {
          if (!scene.includes(colour)) {
            const hit = swapped.find(([, v]) => slotMeanings(v, full).colour.includes(colour));
            const asRead = hit ? ` (I read '${hit[0]}' as ${colour})` : "";
            return `there is no ${colour} cube here${asRead}: ${sceneText(scene)}`;
          }
        }
        if (understood === null || said.colour.length) return null;
        const colour = understood.meaning ? understood.meaning[1] : null;  // the colour of the readback
        return colour === null || scene.includes(colour) ? null :
          `I understood ${pyrepr(understood.words)}, but there is no ${colour} cube here: ${sceneText(scene)}`;
      }

      // refusals.refusal: text as typed, read after the word lookup, swapped its [word, replacement]s,
      // scene the (left, right) colours, understood {words, meaning (null if not a description)} or null.
      function refusal(text, read, swapped, scene, understood) {
        const [negations, negatedSpeeds] = negated(read);
        if (negations.length) {
          return `I can't do ${pyrepr(text.trim())}: it says what not to do (${pyrepr(negations[0])}); tell me ` +
                 `what to do, e.g. 'push the ${scene ? scene[0] : "red"} cube slowly'`;
        }
        const said = slotMeanings(read, full);
        const several = moreThanOne(read, said, negatedSpeeds);
        if (several) {
          return `one instruction at a time: ${pyrepr(text.trim())} asks for ${several}; tell me one action on one cube`;
        }
        return outsideTheWorld(text, read, said, swapped, scene) ||
               (scene ? absentCube(said, swapped, scene, understood) : null);
      }
      return {refusal};
    };
  }

  // refusals.disagreement: the readback {words, meaning} against the chosen episode's meaning.
  function disagreement(understood, chosen, pyrepr) {
    const said = `the chosen episode is ${chosen.join(" ")}: the verdict is against the chosen episode`;
    if (!understood.meaning) {
      return `I could not say the text back as a description (${pyrepr(understood.words || "<EOS>")}); ${said}`;
    }
    return understood.meaning.join(" ") === chosen.join(" ") ? null :
      `the text asks for ${understood.meaning.join(" ")}, as I understood it, but ${said}`;
  }

  window.pgaeRefusals = {make, disagreement, slotMeanings};
})();
