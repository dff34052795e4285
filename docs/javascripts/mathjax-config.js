// MathJax 3 for pymdownx.arithmatex (generic mode: \( \) inline, \[ \] display), as
// mkdocs-material documents it, and for the notebooks' Markdown cells ($ $ and $$ $$, inside
// mkdocs-jupyter's "jupyter-wrapper"); nothing else on a page is read as TeX.
window.MathJax = {
  tex: {
    inlineMath: [["\\(", "\\)"], ["$", "$"]],
    displayMath: [["\\[", "\\]"], ["$$", "$$"]],
    processEscapes: true,
    processEnvironments: true
  },
  options: {
    ignoreHtmlClass: ".*|",
    processHtmlClass: "arithmatex|jupyter-wrapper"
  }
};

if (typeof document$ !== "undefined") {
  document$.subscribe(() => {
    if (window.MathJax.typesetPromise) {
      MathJax.startup.output.clearCache();
      MathJax.typesetClear();
      MathJax.texReset();
      MathJax.typesetPromise();
    }
  });
}
