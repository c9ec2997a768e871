"""``python -m rollqp.cli``: the ``rollqp`` command."""
import sys

from . import main

sys.exit(main())
