"""The validators of :mod:`rollqp.validate`, under the name they had inside the scene package."""
from ..validate import *  # noqa: F401,F403
from ..validate import __all__  # noqa: F401
