// MathJax 3 for pymdownx.arithmatex (generic mode: \( \) inline, \[ \] display), as
// mkdocs-material documents it, and for the notebooks' Markdown cells ($ $ and $$ $$, inside
// mkdocs-jupyter's "jp-RenderedMarkdown" cells); nothing else on a page is read as TeX.
window.MathJax = {
  tex: {
    inlineMath: [["\\(", "\\)"], ["$", "$"]],
    displayMath: [["\\[", "\\]"], ["$$", "$$"]],
    processEscapes: true,
    processEnvironments: true
  },
  options: {
    // The page's own text (md-typeset) and its frame are not read as TeX; inside them only
    // arithmatex's spans and the notebooks' Markdown cells are. (The usual ".*|" would also
    // ignore the unclassed <p> inside a Markdown cell: an ignored class is inherited.)
    ignoreHtmlClass: "md-typeset|md-header|md-sidebar|md-footer|md-search",
    processHtmlClass: "arithmatex|jp-RenderedMarkdown"
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
