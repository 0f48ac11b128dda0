// Chapter 05's live box: every element with class "pgae-understood" becomes a text box and a
// button. On a click, both PGAE-BERT models read the typed sentence in this page
// (window.pgae.run, pgae.js; signal repeat language, on the first test episode) and each says back
// what it understood, in the dataset's words, and how sure it was of it (the first word's
// probability and the lowest). A model that cannot read the text says why: the
// promise's error message is shown as it is. Nothing here computes a model.
(function () {
  "use strict";

  const UNSURE = 0.5;        // a word chosen with a lower probability is called a guess

  // How sure the decoder was of its readback, briefly: the first word's probability and the lowest.
  function sure(choices) {
    if (!choices || !choices.length) return "";
    const low = choices.reduce((a, c) => (c.p < a.p ? c : a), choices[0]), p = (c) => c.p.toFixed(2);
    return ` [how sure: first word ${choices[0].word} ${p(choices[0])}` +
           (low !== choices[0] ? `, lowest ${low.word} ${p(low)}` : "") + (low.p < UNSURE ? ": a guess]" : "]");
  }

  function box(root) {
    const text = document.createElement("input");
    Object.assign(text, {type: "text", size: 48, className: "pgae-understood-text",
                         placeholder: "e.g. could you shove the scarlet block away, quickly"});
    text.setAttribute("aria-label", "a sentence for PGAE-BERT");
    const button = document.createElement("button");
    Object.assign(button, {type: "button", className: "pgae-understood-run", textContent: "What did it understand?"});
    const out = document.createElement("pre");
    out.className = "pgae-understood-said";
    out.style.whiteSpace = "pre-wrap";                                 // the error messages are long
    root.textContent = "";
    root.append(text, " ", button, out);

    async function ask() {
      const sentence = text.value.trim() || text.placeholder.replace(/^e\.g\. /, "");
      button.disabled = true;
      out.textContent = `Reading "${sentence}" in this page...`;
      const lines = [];
      try {
        const manifest = await window.pgae.load();
        const episode = manifest.episodes[0].id;                       // the first test episode
        const models = Object.keys(manifest.models).filter(m => manifest.models[m].reads === "features");  // PGAE-BERT's
        lines.push(`"${sentence}" (repeat language, test episode ${episode}), computed in this page:`);
        for (const model of models) {                                  // one after the other: one line each
          try {
            const r = await window.pgae.run({model, signal: "repeat language", episode, text: sentence});
            const read = await window.pgae.readAs(model, sentence);       // the variant's word lookup
            lines.push(`${model} understood: ${r.understood || "<EOS>"}` +
                       (read !== sentence ? ` (it read "${read}")` : "") + sure(r.understood_choices));
          } catch (e) {
            lines.push(`${model} cannot: ${e.message}`);
          }
        }
      } catch (e) {
        lines.push(`The models cannot start in this page: ${e.message}`);
      }
      out.textContent = lines.join("\n");
      root.dataset.done = "1";
      button.disabled = false;
    }
    button.addEventListener("click", ask);
    text.addEventListener("keydown", (e) => { if (e.key === "Enter") ask(); });
  }

  const start = () => document.querySelectorAll(".pgae-understood").forEach(box);
  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", start);
  else start();
})();
