"""One run of a stepper per (problem, partition) within a battery: the laws judge the same solutions.

A stepper is a function of its problem and partition, and the battery's laws ask for the same ones over and
over: ``selections`` and ``in_domain`` run on every partition the battery builds (:func:`every_battery_grid`),
``contraction`` and the a-priori bounds as well, ``unique_limit`` on the refinement levels among them — and the step
laws on the partitions of the stepper's convergence study too (:func:`note_partitions`: the study's grids, which
it chose for the scheme and may have refined, are partitions the battery computed; a stepper that leaves the
proximal scheme only on steps finer than the battery's own partitions is judged there).  Inside :func:`shared_runs` (opened by the stepper stages around a problem's
laws and by :func:`verimono.check_stepper` around its battery) :func:`verimono.checks.partitions.run_stepper`
answers a repeated ``(stepper, problem, partition)`` from the first run instead of running the stepper again
(measured on the ``ci`` battery of ``verimono.solve``: 881 runs, 367 distinct, 0.69 s of 1.2 s saved).

Every law still judges the stepper's own output on its own partition; only repeats are answered from the
first answer (the same array, read-only: a law that writes into its array gets NumPy's error and cannot change
another's; a copy per reuse cost 1 s per 161-node run at n = 10^6, in page faults), and the precision the
stepper computed in is reported again to the judgement that reuses it (:func:`verimono.core.tolerances.observe`:
a float32 stepper is judged as float32 by every law).  What is kept is bounded
(:data:`MAX_BYTES` of runs, oldest first out): a larger problem is run again rather than held.  A stepper that
raises or returns what :func:`run_stepper` refuses is not remembered: every law sees it fail.  A kept run has a
serial number (:func:`run_serial`) that values derived from it can be keyed by, without reading its states again.

:func:`remembered_value` does the same for what laws derive from a run and ask for alike — the resolvent
points ``J_μ(x_{k+1} + μ y_k)`` that ``in_domain`` takes as witnesses of ``dom F`` and ``selections`` judges
(:func:`verimono.checks.trajectory_laws.resolvent_witnesses`) — with the precision the operator computed
them in, observed again on every reuse.
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from contextlib import contextmanager
from typing import Any, Callable, Iterator

import numpy as np

from ..core.tolerances import coarser, judged_precision, observe

#: bytes of states a :func:`shared_runs` block keeps at most (its oldest runs are dropped first): a count, the
#: same on every machine.  The stepper battery's partitions of one problem hold 680 nodes (10 partitions,
#: :func:`verimono.checks.partitions.every_battery_grid`): 5.4 GB at n = 10^6, all kept under 6 GiB, so each is
#: run once (at 64 MiB, the former bound, nothing was kept beyond n = 2·10^5 and the battery made 65 runs instead
#: of 12).  The runs are the arrays the laws judge anyway (kept read-only, never copied): what the bound
#: adds to a battery's peak memory is the runs of laws already finished.
MAX_BYTES = 6 * 2**30
#: bytes of derived values (:func:`remembered_value`) a block keeps at most
MAX_VALUE_BYTES = 64 * 2**20

_ACTIVE: list["_Runs"] = []


class _Runs:
    """What one :func:`shared_runs` block keeps: ``key -> (owners, arrays, precision)``, at most :data:`MAX_BYTES`
    of runs (kept read-only, handed out as they are) and :data:`MAX_VALUE_BYTES` of derived values (copied in and
    out), the oldest dropped first; and the partitions of each (stepper, problem) the battery's convergence
    studies ran (:func:`note_partitions`)."""

    def __init__(self) -> None:
        self.kept: OrderedDict[tuple, tuple[tuple, tuple[np.ndarray, ...], str | None]] = OrderedDict()
        self.values: OrderedDict[tuple, tuple[tuple, tuple[np.ndarray, ...], str | None]] = OrderedDict()
        self.bytes = 0
        self.value_bytes = 0
        self.hits = 0
        self.partitions: dict[tuple, tuple[Any, list[np.ndarray]]] = {}
        #: id of a kept run's array -> its serial number (only while it is kept: the id cannot be reused then)
        self.serials: dict[int, int] = {}
        self.next_serial = 0

    def get(self, key: tuple) -> tuple[np.ndarray, ...] | None:
        """The read-only arrays kept for ``key`` (their precision observed again), or ``None``."""
        hit = self.kept.get(key)
        if hit is None:
            return None
        self.hits += 1
        self.kept.move_to_end(key)
        if hit[2] not in (None, "float64"):
            observe(hit[2])
        return hit[1]

    def put(self, key: tuple, owners: tuple, arrays: tuple[np.ndarray, ...], precision: str | None) -> None:
        """Keep the run ``arrays`` (the caller's own arrays, made read-only here)."""
        size = sum(a.nbytes for a in arrays)
        if size > MAX_BYTES:
            return
        for a in arrays:
            a.setflags(write=False)
            self.serials[id(a)] = self.next_serial
            self.next_serial += 1
        # the owners (stepper, problem) are held with their arrays, so the ids in the key cannot be reused
        self.kept[key] = (owners, tuple(arrays), precision)
        self.bytes += size
        while self.bytes > MAX_BYTES:
            _, (_, old, _) = self.kept.popitem(last=False)
            self.bytes -= sum(a.nbytes for a in old)
            for a in old:
                self.serials.pop(id(a), None)

    def get_value(self, key: tuple) -> tuple[np.ndarray, ...] | None:
        """Copies of the derived value kept for ``key`` (its precision observed again), or ``None``."""
        hit = self.values.get(key)
        if hit is None:
            return None
        self.hits += 1
        if hit[2] not in (None, "float64"):
            observe(hit[2])
        return tuple(a.copy() for a in hit[1])

    def put_value(self, key: tuple, owners: tuple, arrays: tuple[np.ndarray, ...], precision: str | None) -> None:
        size = sum(a.nbytes for a in arrays)
        if size > MAX_VALUE_BYTES:
            return
        self.values[key] = (owners, tuple(a.copy() for a in arrays), precision)
        self.value_bytes += size
        while self.value_bytes > MAX_VALUE_BYTES:
            _, (_, old, _) = self.values.popitem(last=False)
            self.value_bytes -= sum(a.nbytes for a in old)


@contextmanager
def shared_runs() -> Iterator[None]:
    """Within the block, :func:`remembered` answers a repeated ``(stepper, problem, partition)`` from its first
    run (nested blocks share the outermost one's runs)."""
    _ACTIVE.append(_ACTIVE[-1] if _ACTIVE else _Runs())
    try:
        yield
    finally:
        _ACTIVE.pop()


def fingerprint(a: Any) -> tuple:
    """``(shape, dtype, SHA-1 of the bytes)`` of an array: a key for its contents that reads them once without
    copying them (``a.tobytes()`` in a key copied the whole array per lookup: 800 MB for a 100-step trajectory
    at n = 10^6, and it was held by the key)."""
    a = np.ascontiguousarray(a)
    return a.shape, a.dtype.str, hashlib.sha1(a.data).digest()


def _key(stepper: Any, problem: Any, grid: np.ndarray) -> tuple:
    return (id(stepper), id(problem), float(problem.T), fingerprint(np.asarray(problem.x0)), fingerprint(grid))


def remembered(stepper: Any, problem: Any, grid: np.ndarray,
               run: Callable[[], tuple[np.ndarray, str | None]]) -> np.ndarray:
    """The states of ``run()`` — ``(states, precision)``: the validated float64 states of ``stepper`` on
    ``problem`` and ``grid`` and the precision it computed them in — or, inside :func:`shared_runs`, those it
    returned the first time for the same three (the same read-only array, its precision observed again; the
    first caller gets it read-only too)."""
    if not _ACTIVE:
        return run()[0]
    key = _key(stepper, problem, np.asarray(grid, dtype=float))
    hit = _ACTIVE[-1].get(key)
    if hit is not None:
        return hit[0]
    # the precision kept is the coarsest seen while it ran — its states' and what its calls of the operator returned
    # (a stepper returning float64 states of a float32 operator computes in float32): a law reading the kept run
    # later is judged as the one that ran it
    with judged_precision() as seen:
        x, precision = run()
    _ACTIVE[-1].put(key, (stepper, problem), (x,), coarser(precision, seen.name))
    return x


def _partition_key(stepper: Any, name: str, T: float) -> tuple:
    return (id(stepper), str(name), float(T))


def note_partitions(stepper: Any, problem: Any, grids: Any) -> None:
    """Inside :func:`shared_runs`: ``stepper`` ran on ``grids`` (partitions of ``[0, problem.T]``) for ``problem`` —
    a convergence study's grids — so the step laws judge it there too (:func:`noted_partitions`).  ``problem`` is a
    :class:`verimono.Problem` or its ``(name, T)``."""
    if not _ACTIVE:
        return
    name, T = (problem.name, problem.T) if hasattr(problem, "name") else problem
    key = _partition_key(stepper, name, T)
    _, known = _ACTIVE[-1].partitions.get(key, (stepper, []))
    for g in grids:
        g = np.asarray(g, dtype=float)
        if not any(len(g) == len(k) and np.array_equal(g, k) for k in known):
            known.append(g)
    _ACTIVE[-1].partitions[key] = (stepper, known)     # the stepper is held: its id cannot be reused


def noted_partitions(stepper: Any, problem: Any) -> list[np.ndarray]:
    """The partitions noted for ``stepper`` on ``problem`` (by name and horizon) in this block, coarse to fine."""
    if not _ACTIVE:
        return []
    _, known = _ACTIVE[-1].partitions.get(_partition_key(stepper, problem.name, problem.T), (None, []))
    return sorted(known, key=len)


def remembered_value(key: tuple, owners: tuple, compute: Callable[[], tuple[np.ndarray, ...]]) -> tuple[np.ndarray, ...]:
    """``compute()`` — a tuple of arrays derived from a run — or, inside :func:`shared_runs`, copies of what it
    returned the first time for the same ``key`` (the precision observed while it ran is observed again).
    ``owners``: the objects whose ids ``key`` holds, kept alive with the value so no id is reused.  A
    ``compute`` that raises is not remembered."""
    if not _ACTIVE:
        return compute()
    hit = _ACTIVE[-1].get_value(key)
    if hit is not None:
        return hit
    with judged_precision() as seen:      # reports what it saw to the judgement in progress as well
        value = compute()
    _ACTIVE[-1].put_value(key, owners, value, seen.name)
    return value


def run_serial(x: np.ndarray) -> int | None:
    """Inside :func:`shared_runs`: the serial number of the kept run whose states are the array ``x`` (the object
    :func:`remembered` returned), ``None`` when ``x`` is not a kept run.  Unique within the block while the run is
    kept, never reused: a key for what is derived from that run, without fingerprinting its states."""
    if not _ACTIVE:
        return None
    return _ACTIVE[-1].serials.get(id(x))


__all__ = ["shared_runs", "remembered", "remembered_value", "note_partitions", "noted_partitions", "MAX_BYTES",
           "MAX_VALUE_BYTES", "fingerprint", "run_serial"]
