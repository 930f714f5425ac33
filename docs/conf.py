"""Sphinx configuration of the Spectral GI documentation (MyST Markdown pages).

Build: ``python -m sphinx -W --keep-going -b html docs docs/_build/html``.
The API page documents ``spectral_gi.core.__all__`` from this checkout: the repository
root is the package, so it is imported under the name ``spectral_gi`` from here, whether
or not (and wherever) the package is installed.
"""
import importlib.util
import os
import sys
import tomllib

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def _import_checkout():
    spec = importlib.util.spec_from_file_location("spectral_gi", os.path.join(ROOT, "__init__.py"),
                                                  submodule_search_locations=[ROOT])
    module = importlib.util.module_from_spec(spec)
    sys.modules["spectral_gi"] = module
    spec.loader.exec_module(module)


if os.path.realpath(getattr(sys.modules.get("spectral_gi"), "__path__", [""])[0]) != os.path.realpath(ROOT):
    for name in [n for n in sys.modules if n == "spectral_gi" or n.startswith("spectral_gi.")]:
        del sys.modules[name]
    _import_checkout()

with open(os.path.join(ROOT, "pyproject.toml"), "rb") as f:
    _project = tomllib.load(f)["project"]

project = "Spectral GI"
author = "The Spectral GI authors"
copyright = "the Spectral GI authors, GPL-3.0-or-later"
release = version = _project["version"]

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
]
source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]
myst_enable_extensions = ["dollarmath", "deflist", "colon_fence"]
myst_heading_anchors = 3

autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False}
napoleon_google_docstring = True
napoleon_numpy_docstring = True

html_theme = "alabaster"
html_title = f"Spectral GI {release}"
html_static_path = []

# --------------------------------------------------------------------------------------------
# The docstrings are written for readers of the code first. Two plain-text habits of theirs
# are not reStructuredText: |x| for an absolute value (a substitution reference in reST) and
# a paragraph that follows a bullet list without a blank line. Both are mended here, as the
# docstring is read, so the source stays as it is.
import re  # noqa: E402

_ABS = re.compile(r"(?<![\\`|])\|([^|`\s][^|`]*?)\|(?![|_])")
_BULLET = re.compile(r"^(\s*)([*+-]|\d+\.)\s+")


def _mend_docstring(app, what, name, obj, options, lines):
    out, bullet_indent = [], None
    for line in lines:
        stripped = line.strip()
        indent = len(line) - len(line.lstrip())
        m = _BULLET.match(line)
        if m:
            bullet_indent = len(m.group(1))
        elif stripped and bullet_indent is not None and indent <= bullet_indent:
            if out and out[-1].strip():
                out.append("")
            bullet_indent = None
        elif not stripped:
            pass
        if not stripped.startswith(("|", "+-", "+=")):  # leave reST tables alone
            line = _ABS.sub(r"\\|\1\\|", line)
        out.append(line)
    lines[:] = out


def setup(app):
    app.connect("autodoc-process-docstring", _mend_docstring)
