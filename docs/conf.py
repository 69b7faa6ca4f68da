"""Sphinx configuration of the parapend documentation site.

Build (from the repository root) with the docs command of CONTRIBUTING.md, ``python -m
sphinx -W --keep-going -b html docs docs/_build/html`` after ``python -m pip install
'.[docs]'``.

The tutorials (``tutorials/*.md``, MyST notebooks) execute at every build; a failing cell
fails the build. The API reference is generated from the docstrings (autosummary +
numpydoc), the CLI reference from ``parapend.cli.build_parser()`` (sphinx-argparse).
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SRC = ROOT / "src"
# Document (and execute the tutorials against) this checkout's code, also in the notebook
# kernels, which inherit the environment.
sys.path.insert(0, str(SRC))
os.environ["PYTHONPATH"] = os.pathsep.join(
    [str(SRC), *filter(None, [os.environ.get("PYTHONPATH")])])
# Notebooks draw inline (ipykernel's backend): a backend set in the environment would
# send their figures nowhere.
os.environ.pop("MPLBACKEND", None)

import parapend  # noqa: E402

# -- Project ------------------------------------------------------------------------------
project = "parapend"
author = "The parapend developers"
copyright = "2026, the parapend developers"
release = version = parapend.__version__

# -- General ------------------------------------------------------------------------------
extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinxarg.ext",
]
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
root_doc = "index"
templates_path = ["_templates"]
exclude_patterns = [
    "_build", "_templates", "_static", "**.ipynb_checkpoints", "jupyter_execute",
    "check_site.py", "check_links.py", "conf.py", "README.md",
]
nitpicky = True
# Types named in prose-like docstring type fields ("array of float", "callable", "int or
# None") are not cross-referenced (numpydoc_xref_param_type is off); the remaining
# unresolvable targets are objects of other libraries (no intersphinx: the build is
# offline) and private helpers that a docstring names for the reader.
nitpick_ignore_regex = [
    (r"py:.*", r"(numpy|np|scipy|xarray|xr|matplotlib|zarr|dask|distributed|pathlib)\..*"),
    (r"py:.*", r"(int|float|str|bool|dict|list|tuple|callable|None|object|bytes)"),
]
# Internal modules and helpers that docstrings name for the reader but the reference leaves
# out. Listed one by one: any other unresolved reference fails the build.
nitpick_ignore = [
    ("py:func", "dataclasses.replace"),
    ("py:mod", "parapend.fileio"), ("py:mod", "parapend.optimal.hermite"),
    ("py:mod", "parapend.optimal.collocation"), ("py:mod", "optimal.batch"),
    ("py:mod", "parapend.dynamics._kernel"),
    ("py:func", "parapend.api.optimize"), ("py:func", "parapend.irregular.sea"),
    ("py:func", "search_fourier"), ("py:func", "design_sea"), ("py:func", "infer_excitation"),
    ("py:func", "_resample_points"), ("py:func", "_verify"), ("py:func", "colour_scale"),
    ("py:meth", "evaluate"), ("py:class", "HessianOperator"),
    ("py:class", "parapend.optimal.hermite.HermiteMotion"),
    ("py:class", "parapend.optimal.collocation.CollocationMotion"),
    ("py:data", "parapend.limits.MAX_TRACK_WORK"), ("py:data", "parapend.limits.MAX_BYTES_FILE"),
]
# sphinx-argparse's domain cannot answer MyST's "any" lookups; links to the CLI page are
# ordinary document links.
suppress_warnings = ["myst.header", "myst.domains"]


def _help_substitutions() -> str:
    """reST substitutions that print ``|x|`` as itself in the CLI reference.

    The parsers' help text writes absolute values as ``|delta|``; sphinx-argparse reads help
    as reST, where that is a substitution reference.
    """
    import argparse

    from parapend.cli import build_parser

    texts, todo = [], [build_parser()]
    while todo:
        parser = todo.pop()
        texts += [parser.description or "", parser.epilog or ""]
        for action in parser._actions:
            texts.append(action.help or "")
            if isinstance(action, argparse._SubParsersAction):
                todo += list(action.choices.values())
                texts += [a.help or "" for a in action._choices_actions]
    names = sorted({m for t in texts for m in re.findall(r"\|([^|\s][^|]*?)\|", t)})
    return "\n".join(f".. |{n}| replace:: \\|{n}\\|" for n in names)


rst_prolog = _help_substitutions()

_ABS = re.compile(r"(?<![\\`])\|([^|\s`][^|`]*?)\|(?![`_])")
_LITERAL = re.compile(r"(``.+?``)")


def _escape_absolute_values(app, what, name, obj, options, lines):
    """Docstrings write absolute values as ``|x|``: keep them text, not substitutions."""
    del app, what, name, obj, options
    for i, line in enumerate(lines):
        parts = _LITERAL.split(line)
        lines[i] = "".join(p if k % 2 else _ABS.sub(r"\\|\1\\|", p)
                           for k, p in enumerate(parts))


def setup(app):
    app.connect("autodoc-process-docstring", _escape_absolute_values, priority=400)

# -- MyST / myst-nb -----------------------------------------------------------------------
myst_enable_extensions = ["colon_fence", "dollarmath", "amsmath", "deflist"]
myst_heading_anchors = 3
# Execute every notebook at every build ("force"): the build is the test that the
# tutorials run. PARAPEND_DOCS_EXECUTE=cache reuses results between local builds, kept
# outside the source tree.
nb_execution_mode = os.environ.get("PARAPEND_DOCS_EXECUTE", "force")
nb_execution_cache_path = str(ROOT / ".jupyter_cache")
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_execution_timeout = 300  # seconds per cell
nb_execution_excludepatterns: list[str] = []
nb_merge_streams = True

# -- API reference ------------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = True
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()

# -- HTML ---------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"parapend {release}"
html_static_path = ["_static"]
html_css_files = ["parapend.css"]
html_sidebars = {"**": ["sidebar-global.html"]}
html_theme_options = {
    "navigation_with_keys": False,
    "navbar_center": [],
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_show_sourcelink = False
html_last_updated_fmt = None

