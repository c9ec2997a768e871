#!/bin/sh
# Build the HTML documentation; any Sphinx warning fails the build (CI runs this).
# Needs the docs extra: pip install -e '.[docs]'. Run from anywhere; output in docs/_build/html.
set -e
cd "$(dirname "$0")/.."
exec python -m sphinx -W --keep-going -b html docs docs/_build/html "$@"
