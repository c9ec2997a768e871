"""What is computed once and reused, kept by the object that owns it: :class:`Memo`.

A scene's operators own one (:attr:`SceneOperators.memo <rollqp.operators.SceneOperators.memo>`):
its history and steady operators, and an influence model's expensive parts (the BEM's roller
compliances, :func:`rollqp.influence.bem.body_compliance`) live as long as the scene's operators and
no longer. A caller that builds several scenes on the same bodies — a study over loads, friction or
the method — may hand one memo to each (:meth:`SceneOperators.build
<rollqp.operators.SceneOperators.build>`'s ``memo``) so that they share what depends on the geometry
alone. Nothing is kept by the process.

Examples
--------
>>> from rollqp.influence import Memo
>>> memo = Memo(size=2)
>>> memo.get("a", lambda: 1), memo.get("a", lambda: 2), "a" in memo
(1, 1, True)
>>> _ = memo.get("b", lambda: 3); _ = memo.get("c", lambda: 4)
>>> "a" in memo, len(memo)
(False, 2)
"""
from __future__ import annotations

from typing import Callable, Hashable

__all__ = ["Memo"]


class Memo:
    """Values by key, each built once by :meth:`get` (module docstring).

    Parameters
    ----------
    size : int, optional
        At most this many values are kept, the oldest dropped first (default: no limit).
    """

    __slots__ = ("size", "_values")

    def __init__(self, size: int | None = None):
        self.size = size
        self._values: dict = {}

    def get(self, key: Hashable, build: Callable[[], object]):
        """The value of ``key``: the one kept, else ``build()``, kept."""
        values = self._values
        if key in values:
            return values[key]
        value = build()
        if self.size is not None and len(values) >= self.size:
            values.pop(next(iter(values)))
        values[key] = value
        return value

    def __contains__(self, key) -> bool:
        return key in self._values

    def __len__(self) -> int:
        return len(self._values)

    def __repr__(self) -> str:
        return f"Memo({len(self)} values, size={self.size})"
