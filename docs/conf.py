"""Sphinx configuration of the volerr manual.

Build (warnings are errors):  sphinx-build -W --keep-going -b html docs docs/_build/html
Needs:                         pip install -e ".[docs]"
"""

import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(HERE / "tutorials"))   # their _common helper
os.environ.setdefault("MPLBACKEND", "Agg")

project = "volerr"
author = "the volerr maintainers"
copyright = "2026, the volerr maintainers"
try:
    from volerr import __version__ as release
except ImportError:  # pragma: no cover
    release = "0"
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "volerr_docs",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "tutorials/README.txt", "audit_reviews/*.json",
                    "tutorials/*.py", "Thumbs.db", ".DS_Store"]
root_doc = "index"

myst_heading_anchors = 3
myst_enable_extensions = ["colon_fence"]
suppress_warnings = ["myst.header", "misc.highlighting_failure"]

autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_validation_checks = set()
numpydoc_xref_param_type = False

sphinx_gallery_conf = {
    "examples_dirs": ["tutorials"],
    "gallery_dirs": ["auto_tutorials"],
    "filename_pattern": r"/plot_",
    "ignore_pattern": r"_common\.py|__init__\.py",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": True,
    "matplotlib_animations": False,
    "reset_modules": ("matplotlib",),
    "capture_repr": ("_repr_html_",),
}

html_theme = "furo"
html_title = f"volerr {release}"
html_static_path = []
