"""Sphinx configuration of chainsim's documentation site (docs/ is the source; `bash scripts/quickstart.sh docs`
builds it into build/site with warnings as errors).

- The guides are the Markdown files of docs/, read by myst-parser as they are shown on the repository.
- The Python reference (api/python.md) is autodoc + numpydoc of the module built in the build tree
  (CHAINSIM_BUILD_DIR/python, default build/python) and of the plotting tool (python/).
- The C++ reference (api/cpp.md) is breathe over Doxygen's XML of the public headers (docs/Doxyfile), which
  the docs target writes to CHAINSIM_BUILD_DIR/doxygen/xml before Sphinx runs.
- The gallery (gallery.md) shows the notebooks of examples/notebooks/ with their outputs: the docs target
  executes them with nbclient into CHAINSIM_BUILD_DIR/notebooks/ (scripts/run_notebooks.py), and this file
  copies the executed notebooks into docs/gallery/ (generated, not in git) for nbsphinx, which never executes.
"""
import os
import pathlib
import shutil
import sys

docs = pathlib.Path(__file__).resolve().parent
root = docs.parent
build = (root / os.environ.get("CHAINSIM_BUILD_DIR", "build")).resolve()  # relative: to the root (Sphinx runs this file in docs/)
sys.path[:0] = [str(build / "python"), str(root / "python")]

project = "chainsim"
author = "the chainsim authors"
copyright = "the chainsim authors, BSD-3-Clause"

extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.mathjax", "numpydoc", "breathe", "nbsphinx"]
source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["figures/*.py", "figures/*.sh", "data", "**.ipynb_checkpoints"]

# The Markdown: $...$ and $$...$$ math, GitHub's heading anchors (links such as reduced.md#outputs), tables.
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence"]
myst_heading_anchors = 4
suppress_warnings = ["myst.header"]  # the guides start at '#' and some skip a level, as on the repository

# The Python reference.
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "show-inheritance": False}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False

# The C++ reference.
breathe_projects = {"chainsim": str(build / "doxygen" / "xml")}
breathe_default_project = "chainsim"
breathe_default_members = ("members",)

# The gallery: executed notebooks, never executed again here.
nbsphinx_execute = "never"
nbsphinx_allow_errors = False
executed = build / "notebooks"
gallery = docs / "gallery"
sources = sorted((root / "examples" / "notebooks").glob("*.ipynb"))
missing = [nb.name for nb in sources if not (executed / nb.name).is_file()]
if missing:
    raise RuntimeError(f"the gallery needs the executed notebooks {missing} in {executed}: run "
                       "/usr/bin/python3 scripts/run_notebooks.py first (bash scripts/quickstart.sh docs does)")
shutil.rmtree(gallery, ignore_errors=True)
gallery.mkdir()
for nb in sources:
    # The notebooks link to the guides as seen from examples/notebooks/ (../../docs/model.md, right on the
    # repository and in Jupyter); from docs/gallery/ the same page is ../model.md.
    text = (executed / nb.name).read_text(encoding="utf-8")
    (gallery / nb.name).write_text(text.replace("](../../docs/", "](../"), encoding="utf-8")

html_theme = "sphinx_rtd_theme"
html_title = "chainsim"
html_show_sourcelink = False
