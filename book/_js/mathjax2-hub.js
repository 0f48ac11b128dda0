// ipywidgets' controls typeset every widget label with MathJax 2's API,
// `MathJax.Hub.Queue(["Typeset", MathJax.Hub, element])`; the book serves
// MathJax 3, which has no `Hub`, so each described widget logged
// "Cannot read properties of undefined (reading 'Queue')". This forwards such
// calls to MathJax 3's typesetPromise. MathJax 3 replaces `window.MathJax`
// when it starts, so the property is watched and `Hub` added to whatever
// object it holds (non-enumerable: MathJax 3 never sees it as an option).
(function () {
  "use strict";
  var hub = {
    Queue: function (job) {
      var element = Array.isArray(job) ? job[2] : undefined;
      var mathjax = window.MathJax;
      if (mathjax && typeof mathjax.typesetPromise === "function") {
        mathjax.typesetPromise(element ? [element] : undefined).catch(function () {});
      } // not loaded yet: MathJax 3 typesets the whole page when it starts
    }
  };
  function withHub(mathjax) {
    if (mathjax && typeof mathjax === "object" && !("Hub" in mathjax)) {
      Object.defineProperty(mathjax, "Hub", { value: hub, configurable: true });
    }
    return mathjax;
  }
  var current = withHub(window.MathJax);
  Object.defineProperty(window, "MathJax", {
    configurable: true,
    get: function () { return current; },
    set: function (value) { current = withHub(value); }
  });
})();
