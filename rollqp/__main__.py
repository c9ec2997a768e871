"""``python -m rollqp``: the ``rollqp`` command (:mod:`rollqp.cli`)."""
import sys

from .cli import main

sys.exit(main())
