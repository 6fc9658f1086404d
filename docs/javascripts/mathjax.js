// MathJax 3 for pymdownx.arithmatex (generic mode: \( \) and \[ \] in span/div.arithmatex), as the
// Material theme documents it, and for the notebooks' Markdown cells, which keep $ and $$
// (mkdocs-jupyter's own MathJax 2 configuration does not apply to MathJax 3).
window.MathJax = {
  tex: {
    inlineMath: [["\\(", "\\)"], ["$", "$"]],
    displayMath: [["\\[", "\\]"], ["$$", "$$"]],
    processEscapes: true,
    processEnvironments: true
  },
  // not Material's ignoreHtmlClass ".*|": it also skips the class-less <p> inside a notebook cell
  options: {ignoreHtmlClass: "tex2jax_ignore", processHtmlClass: "arithmatex|jp-RenderedMarkdown"}
};
document$.subscribe(() => {
  MathJax.startup.output.clearCache();
  MathJax.typesetClear();
  MathJax.texReset();
  MathJax.typesetPromise();
});
