"""Sphinx configuration of rollqp's documentation.

Build (from the repository root; any warning fails it)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

or ``sh docs/build.sh``. The pages are Markdown (MyST) that also read well on a code host; the
API reference (``api.md``) is generated from the numpydoc docstrings.

Links from the Markdown pages to the code are written as relative paths to the source file,
``[`NormalStep.residuals`](../rollqp/problem.py)``, so that they work in a checkout and on a
code host. MyST turns a link to an existing non-document file into a download link (a link to a
missing file is a warning, so stale links fail the build). :func:`link_code_to_api` then
points each such link at the API reference instead: at the object the link text names
(``rollqp.problem.NormalStep.residuals``), or the nearest documented parent (a private method
links to its class, a private function to its module), or the module; only a module the API
reference does not document keeps the download link.
"""
from __future__ import annotations

import importlib
import os
import pkgutil
import re
import sys

from docutils import nodes
from sphinx import addnodes

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, ROOT)

import rollqp  # noqa: E402

project = "rollqp"
author = "rollqp authors"
copyright = "2026, rollqp authors"
version = release = rollqp.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    # MathJax served from the build itself (docs/_build/html/_static/mathjax), not from a CDN:
    # formulas render offline. The extension is ten lines around a copy of MathJax 3.
    "sphinx-mathjax-offline",
    "sphinx.ext.viewcode",
    "numpydoc",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "figures", "build.sh"]

# MyST: $…$ and $$…$$ math, \begin{align} environments, and GitHub-style heading anchors
# (formulation.md#8-the-symmetricskew-splitting) down to level 4, as the pages link them.
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 4

autodoc_member_order = "bysource"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False

# Literal blocks in docstrings are formulas and tables, not Python.
highlight_language = "text"

# The index's toctree ends with a glob, "*", that picks up any further top-level page
# (docs/*.md) without editing the index; :func:`drop_empty_glob` removes it while there is none
# (Sphinx warns about a glob that matches nothing).

html_theme = "alabaster"
html_title = f"rollqp {release}"
# wide tables scroll within the text column (docs/_static/rollqp.css)
html_static_path = ["_static"]
html_css_files = ["rollqp.css"]

_CODE_LINK = re.compile(r"(?:^|/)rollqp/((?:[A-Za-z_][A-Za-z0-9_]*/)*[A-Za-z_][A-Za-z0-9_]*)\.py$")
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_.]*")


def _candidates(module: str, text: str):
    """Dotted names to try for a link to ``module`` whose text is ``text``, most specific first."""
    match = _NAME.match(text.strip())
    if match:
        name = match.group(0).strip(".")
        if not name.startswith("rollqp."):
            name = f"{module}.{name}"
        parts = name.split(".")
        while len(parts) > len(module.split(".")):
            yield ".".join(parts)
            parts.pop()
    yield module


def link_code_to_api(app, doctree, docname):
    """Point links to ``../rollqp/*.py`` at the API reference entry they name (module docstring)."""
    objects = app.env.get_domain("py").objects
    for node in list(doctree.findall(addnodes.download_reference)):
        match = _CODE_LINK.search(node.get("reftarget", ""))
        if not match:
            continue
        module = "rollqp." + match.group(1).replace("/", ".")
        module = module.removesuffix(".__init__")
        literal = next(iter(node.findall(nodes.literal)), None)
        text = literal.astext() if literal is not None else node.astext()
        for name in _candidates(module, text):
            entry = objects.get(name)
            if entry is not None:
                uri = app.builder.get_relative_uri(docname, entry.docname) + "#" + entry.node_id
                ref = nodes.reference("", "", internal=True, refuri=uri, reftitle=name)
                ref += node.children
                node.replace_self(ref)
                break


def drop_empty_glob(app, docname, source):
    """Remove the index toctree's final ``*`` while every top-level page is listed before it."""
    if docname != root_doc:
        return
    text = source[0]
    listed = set(re.findall(r"^([A-Za-z0-9_-]+)$", text, flags=re.M))
    pages = {name for name in app.env.found_docs if "/" not in name} - {root_doc}
    if pages <= listed:
        source[0] = re.sub(r"^\*$\n", "", text, flags=re.M)


def add_further_modules(app, docname, source):
    """Append to the API page every public rollqp module it does not list yet.

    A module added to the package is documented (and its docstrings checked by the build)
    without editing ``api.md``; place it in the page's sections when convenient. A module
    whose optional dependency is not installed is named instead of documented, so the build
    does not depend on optional extras.
    """
    if docname != "api":
        return
    listed = set(re.findall(r"automodule::\s+(\S+)", source[0]))
    documented, skipped = [], []
    for info in pkgutil.walk_packages(rollqp.__path__, "rollqp."):
        name = info.name
        if name in listed or any(part.startswith("_") for part in name.split(".")):
            continue
        try:
            importlib.import_module(name)
        except ImportError as exc:
            skipped.append(f"`{name}` (needs `{exc.name}`)")
            continue
        documented.append(name)
    if not documented and not skipped:
        return
    text = ["", "## Further modules", ""]
    if documented:
        text += ["```{eval-rst}"]
        for name in documented:
            text += [f".. automodule:: {name}", "   :members:", "   :ignore-module-all:", ""]
        text += ["```", ""]
    if skipped:
        text += ["Not documented in this build (optional dependency missing): " + ", ".join(skipped) + ".", ""]
    source[0] += "\n".join(text)


def setup(app):
    app.connect("source-read", drop_empty_glob)
    app.connect("source-read", add_further_modules)
    # the API page depends on the package's module list, not only on api.md: re-read it always
    app.connect("env-get-outdated", lambda app, env, added, changed, removed: ["api"])
    app.connect("doctree-resolved", link_code_to_api)
    return {"parallel_read_safe": True}
