#!/bin/sh
# Build the HTML documentation; any Sphinx warning fails the build (CI runs this).
# Needs the docs extra: pip install -e '.[docs]'. Run from anywhere; output in docs/_build/html.
# The pages must read offline: MathJax ships with the build (sphinx-mathjax-offline), and a
# page that loads anything from the network fails the build.
set -e
cd "$(dirname "$0")/.."
python -m sphinx -W --keep-going -b html docs docs/_build/html "$@"
if grep -l -E "<script[^>]+src=\"https?://|<link[^>]+href=\"https?://[^\"]+\\.(css|js)" docs/_build/html/*.html; then
  echo "docs/build.sh: the pages above load a script or style sheet from the network (must work offline)" >&2
  exit 1
fi
