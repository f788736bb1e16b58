"""Sphinx configuration of the dolfinx_corot documentation (``make docs``)."""
import os
import sys

sys.path.insert(0, os.path.abspath(".."))

project = "dolfinx_corot"
author = "the dolfinx_corot developers"
copyright = "2026, the dolfinx_corot developers"
release = "0.1.0"

extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.mathjax"]
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
exclude_patterns = ["_build", "README.md"]

html_theme = "furo"
html_title = "dolfinx_corot"
html_static_path = ["_static"]
# MathJax 2 from Debian (libjs-mathjax), copied into _static by scripts/docs.py: the site works offline
mathjax_path = "mathjax/MathJax.js"
mathjax2_config = {"jax": ["input/TeX", "output/CommonHTML"], "extensions": ["tex2jax.js"],
                   "TeX": {"extensions": ["AMSmath.js", "AMSsymbols.js"]},
                   "tex2jax": {"inlineMath": [["\\(", "\\)"]], "displayMath": [["\\[", "\\]"]],
                               "processClass": "math", "ignoreClass": "document", "processEscapes": True},
                   "showMathMenu": False, "messageStyle": "none"}

autodoc_member_order = "bysource"
autodoc_typehints = "none"
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False}
autodoc_mock_imports = []
suppress_warnings = ["myst.header"]
