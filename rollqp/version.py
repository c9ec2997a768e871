"""The version of rollqp (one place: the package, the result files and the sweeps read it here)."""
__version__ = "0.1.0"
