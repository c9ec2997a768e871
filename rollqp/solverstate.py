"""What a method carries from one step to the next, journaled so that a resumed march repeats the uninterrupted one.

Newton's iteration keeps the LU factors of the reduced systems of the last few free sets and solves later
directions on them, bordered (:class:`~rollqp.methods.newton.linear.ReducedSystem`), and it starts each step
from the product ``A x`` of the last solution. Which factorization a direction is solved on, and what the
bordered solves have kept on it, change the last bits of the direction; a march that set out without them
would take other (equally valid) iterations and stop elsewhere within the tolerance. So a march that
journals its states (:mod:`rollqp.journal`) records, with each state, what it needs to rebuild them
(:class:`Recorder`), and a resumed march rebuilds them (:func:`restore`): the same LU of the same matrix,
its store grown by the same bordered solves in the same order, the same flags. The record is small: per
state the factorizations made (their free sets as runs of nodes) and the bordered solves (the nodes
added and released), and, when it changed, which ones are kept.

The record of a state, the ``"solver"`` entry of its journal frame's notes::

    {"v": 1,
     "ev": [["f", system, id, with_load, runs], ["b", system, id, added, released], ...],
     "sys": [[system, kind, role, dqh, state, last], ...],   # when it changed
     "nw": {"last": system, "large": int, "dropped": [[kind, role, dqh], ...]}}  # when it changed

``system`` is the recorder's number for a :class:`ReducedSystem`, ``role`` the operator it was built on
(``"Ann"``, ``"Att"``, or ``None``: another one, e.g. the steady start's, never asked for again),
``state`` :meth:`ReducedSystem.state`, and ``last`` ``[field, k]``: the state ``k`` (the record's own
state if ``k`` is left out) whose ``field`` (``"p"`` or ``"t"``) is the system's last solution (its product
is computed again as it was).
"""
from __future__ import annotations

import types

import numpy as np

from .methods.blocks import partial_product

VERSION = 1

__all__ = ["Recorder", "restore", "newton_of", "VERSION"]


def newton_of(meth):
    """The :class:`~rollqp.methods.newton.NewtonMethod` that solves ``meth``'s uncoupled halves (through the
    compositions that wrap it: N–T alternation, friction fixed point, continuation), or ``None``: what the
    method's record declares (``capabilities.carries_state``) and its ``carrier()`` gives."""
    return meth.carrier() if meth.capabilities.carries_state else None


def _runs(idx) -> list:
    """Sorted indices as ``[start, stop, start, stop, ...]``."""
    idx = np.asarray(idx)
    if idx.size == 0:
        return []
    brk = np.flatnonzero(np.diff(idx) != 1)
    starts = idx[np.concatenate(([0], brk + 1))]
    stops = idx[np.concatenate((brk, [idx.size - 1]))] + 1
    return np.column_stack([starts, stops]).ravel().tolist()


def _indices(runs, n: int) -> np.ndarray:
    """The indices of ``[start, stop, ...]`` runs, each within ``0 … n`` (a record is read from a file)."""
    r = np.asarray(runs, dtype=np.intp).reshape(-1, 2)
    if r.size and (r.min() < 0 or r.max() > n or np.any(r[:, 1] < r[:, 0])):
        raise ValueError("a recorded free set outside the nodes")
    return np.concatenate([np.arange(a, b) for a, b in r]) if r.size else np.zeros(0, np.intp)


def _counts(kind) -> list:
    """An array of small codes as ``[value, count, value, count, ...]`` (run lengths)."""
    kind = np.asarray(kind)
    if kind.size == 0:
        return []
    brk = np.flatnonzero(np.diff(kind)) + 1
    starts = np.concatenate(([0], brk))
    counts = np.diff(np.concatenate((starts, [kind.size])))
    return np.column_stack([kind[starts], counts]).ravel().tolist()


def _uncounted(runs, size: int) -> np.ndarray:
    """The codes of :func:`_counts`, ``size`` of them (a record is read from a file)."""
    r = np.asarray(runs, dtype=np.int64).reshape(-1, 2)
    if r.size and (r[:, 1].min() < 0 or r[:, 1].sum() != size or r[:, 0].min() < 0 or r[:, 0].max() > 5):
        raise ValueError("recorded row kinds that are not the coupled step's")
    return np.repeat(r[:, 0], r[:, 1]).astype(np.int8)


def _coupled_role(ops, A):
    for name in ("Ann", "Att", "Ant", "Atn"):
        if A is getattr(ops, name):
            return name
    return "other"


def _role(ops, A):
    return "Ann" if A is ops.Ann else "Att" if A is ops.Att else None


class Recorder:
    """Records, state by state, what :func:`restore` needs (module docstring): :meth:`note` after each state."""

    def __init__(self, meth, ops):
        self.newton, self.ops = newton_of(meth), ops
        self.tags = 0
        self.lasts = {}  # system -> (its last solution tuple, [k, field] or None)
        self.summary = self.hist = self.sig = None
        if self.newton is not None:
            self.newton.record = True  # (an instance attribute: this method's systems only)
            for s in self.newton._systems.values():
                if getattr(s, "tag", None) is not None:
                    self.tags = max(self.tags, s.tag + 1)
                    if s.events is None:
                        s.events = []

    def note(self, k: int, state, cache=None) -> dict | None:
        """The record of state ``k`` (its :class:`~rollqp.march.State` ``state``; ``cache`` the march's
        :class:`~rollqp.kinematics.HistoryCache`), or ``None`` (nothing to record)."""
        out = {"v": VERSION}
        if cache is not None:
            hist = [[dq, d] for dq, d, _ in cache.items]
            if hist != self.hist:
                out["hist"] = self.hist = hist
        nw = self.newton
        if nw is None:
            return out if len(out) > 1 else None
        sig = self._signature(nw, k, state)
        if sig is not None and sig == self.sig:  # nothing happened that the record would say
            return out if len(out) > 1 else None
        ops = self.ops
        events, systems = [], []
        for key, s in nw._systems.items():
            if not hasattr(s, "events"):  # the place of a system that is not rebuilt (:func:`restore`)
                systems.append([s.tag, None, None, None, None, None])
                continue
            for e in self._events(s):
                if e[0] == "f":
                    events.append(["f", s.tag, e[1], int(e[2]), _runs(e[3])])
                else:
                    events.append(["b", s.tag, e[1], e[2].tolist(), e[3].tolist()])
            s.events.clear()
            where = self._last(k, state, s, key[0])  # (this state's as [field]: a record that repeats)
            systems.append([s.tag, key[0], _role(ops, key[1]), key[4], s.state(),
                            None if where is None else [where[1]] if where[0] == k else [where[1], where[0]]])
        coupled = self._coupled(nw, events)
        last = None if nw._last is None else next((s.tag for s in nw._systems.values() if s is nw._last[5]), None)
        summary = {"sys": systems, "cp": coupled,
                   "nw": {"last": last, "large": nw._large,
                          "dropped": sorted([k[0], _role(ops, k[1]), k[4]] for k in nw._dropped
                                            if _role(ops, k[1]) is not None)}}
        if events:
            out["ev"] = events
        if summary != self.summary:
            out.update(summary)
            self.summary = summary
        self.sig = self._signature(nw, k, state)
        return out if len(out) > 1 else None  # nothing new: no record (the last one holds)

    def _signature(self, nw, k, state):
        """What the summary of :meth:`note` says, as a tuple of numbers (cheap to form and compare); ``None`` if a
        system has events to record or no name yet (the record is then made in full)."""
        sig = []
        for key, s in nw._systems.items():
            events = getattr(s, "events", False)
            if events is False:  # a placeholder (:func:`restore`)
                sig.append(s.tag)
                continue
            if events or s.tag is None:
                return None
            where = self._last(k, state, s, key[0])
            b0, b1 = s._base.get(False), s._base.get(True)
            sig.append((s.tag, tuple([b[5].id for b in s._factors.values()]), None if b0 is None else b0[5].id,
                        None if b1 is None else b1[5].id, s.settled, s.exact, s._serial,
                        None if where is None else where[1] if where[0] == k else (where[1], where[0])))
        for _, cf in nw._coupled.values():
            if cf.events or cf.tag is None:
                return None
            sig.append(("coupled", cf.tag))
        last = nw._last
        sig.append((None if last is None else getattr(last[5], "tag", None), nw._large, len(nw._dropped)))
        return tuple(sig)

    def _events(self, system) -> list:
        """The events of ``system`` (a reduced system or coupled factors) since its last record, which the caller
        empties; the system gets its tag the first time it is seen."""
        if system.tag is None:
            system.tag, self.tags = self.tags, self.tags + 1
        if system.events is None:
            system.events = []
        return system.events

    def _coupled(self, nw, events) -> list:
        """The coupled steps' factorizations (:class:`~rollqp.methods.newton.linear.CoupledFactors`): their events
        appended to ``events``; ``[[tag, roles of A_nn, A_tt, A_nt, A_tn, Δq, P prescribed, Q prescribed], ...]``."""
        out = []
        for key, (_, cf) in nw._coupled.items():
            for e in self._events(cf):
                if e[0] == "F":
                    events.append(["F", cf.tag, None if e[1] is None else _counts(e[1]),
                                   None if e[2] is None else float(e[2])])
                else:
                    events.append(["C", cf.tag, [int(c) for c in e[1]]])
            cf.events.clear()
            roles = [None if a is None else _coupled_role(self.ops, a) for a in key[:4]]
            out.append([cf.tag, roles, key[6], not key[8], not key[9]])
        return out

    def _last(self, k, state, s, kind):
        """``[k, field]`` of the state whose pressure or traction is the system's last solution."""
        last = s.last
        seen = self.lasts.get(s.tag)
        if seen is not None and seen[0] is last:
            return seen[1]
        where = None
        if last is not None and state is not None:
            field = "p" if kind == "normal" else "t"
            x = state.p if field == "p" else state.t
            if x is not None and (x is last[0] or np.array_equal(x, last[0])):
                where = [int(k), field]
        self.lasts[s.tag] = (last, where)
        return where


def restore(meth, ops, notes, upto: int, state_at, recorder: Recorder | None = None):
    """Rebuild ``meth``'s Newton systems as they were after state ``upto`` from the journal's ``notes``
    (``[(k, notes), ...]`` in order); ``state_at(k)`` gives ``{"p": …, "t": …}`` of a stored state.

    Returns ``(products, history)``: ``{(k, field): A x}``, the products of the systems' last solutions
    (the state's ``w`` of a tangential one), and the ``(Δq, d)`` of the march's history operators
    (:class:`~rollqp.kinematics.HistoryCache`, in order); ``None`` when there is nothing to rebuild from
    (a journal written without the records, or by another version): the march then sets out without them.
    """
    nw = newton_of(meth)
    made, factored, summary, hist, seen = {}, {}, None, None, False  # (a state without a record: nothing changed)
    for k, note in notes:
        rec = note.get("solver") if isinstance(note, dict) else None
        if rec is None:
            continue
        if not isinstance(rec, dict) or rec.get("v") != VERSION:
            return None
        if recorder is not None:  # the systems this run makes are named after every one named so far
            recorder.tags = max([recorder.tags] + [e[1] + 1 for e in rec.get("ev", ())]
                                + [s[0] + 1 for s in rec.get("sys", ())])
        if k > upto:
            continue
        seen = True
        if "hist" in rec:
            hist = rec["hist"]
        for ev in rec.get("ev", ()):
            if ev[0] == "f":
                made[(ev[1], ev[2])] = (bool(ev[3]), _indices(ev[4], ops.n), [])
            elif ev[0] == "b":
                made[(ev[1], ev[2])][2].append((ev[3], ev[4]))
            elif ev[0] == "F":
                factored[ev[1]] = (None if ev[2] is None else ev[2], ev[3], [])
            else:
                factored[ev[1]][2].append(ev[2])
        if "sys" in rec:
            summary = rec
            alive = {(s[0], i) for s in rec["sys"] for i in s[4]["kept"] + list(s[4]["base"].values())}
            made = {key: v for key, v in made.items() if key in alive}
            factored = {t: v for t, v in factored.items() if t in {c[0] for c in rec.get("cp", ())}}
    if not seen:
        return None
    if recorder is not None:
        recorder.hist = None  # (the next state's record says it again)
    products = {} if nw is None or summary is None else _rebuild(nw, ops, summary, upto, made, state_at, recorder)
    if nw is not None and summary is not None:
        _rebuild_coupled(nw, ops, summary.get("cp", ()), factored, recorder)
    return products, hist


def _rebuild(nw, ops, summary, at, made, state_at, recorder):
    nw._systems, nw._last = {}, None
    nw._large, nw._dropped = int(summary["nw"]["large"]), set()
    products, tags = {}, {}
    n = ops.n
    for tag, kind, role, dqh, state, last in summary["sys"]:
        if role is None:  # another operator's system (the steady start's): holds its place only
            nw._systems[("restored", tag)] = types.SimpleNamespace(K=np.broadcast_to(0.0, (n, n + 1)), tag=tag)
            if recorder is not None:
                recorder.tags = max(recorder.tags, tag + 1)
            continue
        A = ops.Ann if role == "Ann" else ops.Att
        pb = types.SimpleNamespace(kind=kind, A=A, f=ops.f, scales=ops.scales, n=n)
        s = nw.system(pb, dqh)
        s.restore(state, {i: made[(tag, i)] for i in state["kept"] + list(state["base"].values())})
        s.tag, tags[tag] = tag, (pb, dqh, s)
        if last is not None:
            where = [at if len(last) == 1 else int(last[1]), last[0]]
            x = np.asarray(state_at(where[0])[where[1]], dtype=float)
            Ax = A @ x if s.exact else partial_product(A.dense(), np.arange(n), x, np.flatnonzero(x))
            s.last = (x, Ax)
            products[(where[0], where[1])] = Ax
            if recorder is not None:
                recorder.lasts[tag] = (s.last, where)
        if recorder is not None:
            recorder.tags = max(recorder.tags, tag + 1)
    last = summary["nw"]["last"]
    if last in tags:
        pb, dqh, s = tags[last]
        nw._last = (pb.A, pb.f, pb.kind, dqh, pb.scales, s)
    for kind, role, dqh in summary["nw"]["dropped"]:
        nw._dropped.add((kind, ops.Ann if role == "Ann" else ops.Att, ops.f.tobytes(), ops.scales, dqh, nw.r))
    return products


def _rebuild_coupled(nw, ops, coupled, factored, recorder):
    """The coupled steps' factorizations of the record (:meth:`CoupledFactors.restore
    <rollqp.methods.newton.linear.CoupledFactors.restore>`), in its order."""
    nw._coupled = {}
    for tag, roles, dq, P_given, Q_given in coupled:
        if recorder is not None:
            recorder.tags = max(recorder.tags, tag + 1)
        if "other" in roles:  # another operator's (the steady start's): never asked for again
            continue
        Ann, Att, Ant, Atn = (None if r is None else getattr(ops, r) for r in roles)
        pb = types.SimpleNamespace(Ann=Ann, Att=Att, Ant=Ant, Atn=Atn, f=ops.f, scales=ops.scales, dq=dq,
                                   P=1.0 if P_given else None, Q=1.0 if Q_given else None, n=ops.n)
        _, cf = nw.coupled_system(pb)
        cf.tag = tag
        if tag in factored:
            kind, mu, batches = factored[tag]
            cf.restore((None if kind is None else _uncounted(kind, cf.N), mu, batches))
