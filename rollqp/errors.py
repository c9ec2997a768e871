"""rollqp's own exceptions.

Every error a user can provoke is one of these; the command line prints their
message on one line and exits non-zero (no traceback).
"""
from __future__ import annotations


class RollqpError(Exception):
    """Base class of all rollqp errors."""


class InputError(RollqpError, ValueError):
    """Invalid input: names the offending key (or argument) and the allowed range.

    Parameters
    ----------
    key : str
        The scene key (``"contact.friction"``) or argument name (``"mu"``).
    message : str
        What is wrong and what is allowed.
    """

    #: Longest message kept: a message that shows the input it refuses could be megabytes long (a table
    #: of a million numbers); the rest is cut, with the length said.
    MAX_MESSAGE = 2000

    def __init__(self, key: str, message: str):
        self.key = key
        if len(message) > self.MAX_MESSAGE:
            message = f"{message[:self.MAX_MESSAGE]}… ({len(message)} characters)"
        self.message = message
        super().__init__(f"{key}: {message}")

    def __reduce__(self):
        """Pickled as its key and message (a worker process's error reaches the caller whole)."""
        return (type(self), (self.key, self.message))


class SolverError(RollqpError, RuntimeError):
    """A step solver did not reach the requested accuracy.

    Carries the step number (``None`` outside a transient), the method, the
    solver's own status and rollqp's nondimensional residual at the returned
    iterate, so that a failure can be reported precisely.
    """

    def __init__(self, message: str, *, step: int | None = None, method: str | None = None,
                 status: str | None = None, residual: float | None = None,
                 iterations: int | None = None):
        self.message = message
        self.step = step
        self.method = method
        self.status = status
        self.residual = residual
        self.iterations = iterations
        super().__init__(self._text())

    def _text(self) -> str:
        where = ", ".join(str(v) for v in (f"step {self.step}" if self.step is not None else None,
                                           self.method) if v)
        text = f"{where}: {self.message}" if where else self.message
        extra = [f"status {self.status}" if self.status is not None else None,
                 f"{self.iterations} iterations" if self.iterations is not None else None,
                 f"residual {self.residual:.3e}" if self.residual is not None else None]
        extra = [e for e in extra if e]
        return text + (f" ({', '.join(extra)})" if extra else "")

    def with_step(self, step: int) -> "SolverError":
        """The same error, labelled with the transient step it happened in."""
        return SolverError(self.message, step=step, method=self.method, status=self.status,
                           residual=self.residual, iterations=self.iterations)


class MissingBackendError(RollqpError, ImportError):
    """An optional backend is not installed; the message names the pip extra."""
