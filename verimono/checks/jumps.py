"""Adaptive search for jumps of a sampled function of time ``t ↦ V(t) ∈ R^N``.

For any vector-valued ``V``: on a grid of
``JUMP_GRID`` cells and ``JUMP_SHIFTS`` copies of it shifted by fractions of a cell (together the uniform grid
of ``JUMP_GRID·(JUMP_SHIFTS + 1)`` cells: a jump up and back — a *blip* — longer than one of its cells has a
node inside it), the cells whose increments ``|V(b) − V(a)|`` are local maxima, largest first, and those
whose distance from their neighbours' trend (``|ΔV_i − ½(ΔV_{i−1} + ΔV_{i+1})|``: a small jump on a steep
slope) is a local maximum, largest first, are bisected (local maxima: the neighbours of one jump, whose
increments are half off the trend too, take no candidate's place — a blip has two jumps, both found), keeping
the half whose increment is further off the neighbours' trend, until no float lies strictly between the
ends (or ``JUMP_MAX_LEVELS`` bisections).  On a continuous ``V`` the increment goes to 0 (halving per
bisection when ``V`` is Lipschitz, by ``2^{-1/2}`` when it is Hölder-½); across a jump of size ``J`` it
stays ``≥ J``.  A jump is an increment above the rounding floor that *stalled*: still above
``STALL_RATIO`` times its value ``STALL_WINDOW`` bisections earlier (``verimono.core.tolerances``; any
Hölder-``p`` ``V`` with ``p > 0.006`` drops below that ratio).  Evidence, not proof: a jump up and back
inside one cell of the search grid is not seen.

The base grid (``JUMP_GRID`` cells, :func:`base_grid`) is also where the sup over time of a stated
constant starts (:mod:`verimono.checks.over_time`).

Used by ``assumption_A3`` (``V`` = projections of sample points onto ``dom F(t)``) and ``assumption_A2``
(``V`` = resolvents ``J_λ(t) p``) in :mod:`verimono.checks.assumptions`, and by ``lcs.v_ac`` (``V = v``) in
:mod:`verimono.checks.section7`.
"""

from __future__ import annotations

import dataclasses
from typing import Callable

import numpy as np

from ..core.tolerances import STALL_RATIO, STALL_WINDOW, tolerance

#: cells of the base grid (where the sup searches of :mod:`verimono.checks.over_time` start: every node there
#: evaluates every sample, so it is kept coarse)
JUMP_GRID = 16
#: shifted copies of the base grid searched too, at offsets ``j/(JUMP_SHIFTS + 1)`` of a cell: the union is the
#: uniform grid of ``JUMP_GRID·(JUMP_SHIFTS + 1) = 128`` cells, so a blip longer than ``T/128`` has a node inside
#: it (a blip ``c = 2`` on ``(0.45, 0.46]`` of ``[0, 1]``, inside one cell of the old 32-cell grid, passed (A2)
#: with no jump found)
JUMP_SHIFTS = 7
#: candidate cells bisected: this many local maxima of the increments (largest first)
JUMP_CANDIDATES = 2
#: and this many local maxima of the distance from the neighbours' trend (largest first)
JUMP_EXTREMA = 4
#: bisections at most per candidate (from T/JUMP_GRID, 64 halvings reach below one ulp of T)
JUMP_MAX_LEVELS = 64


@dataclasses.dataclass
class Jump:
    """A stalled increment: ``V`` jumps by about ``size`` between ``a`` and ``b`` (adjacent floats, or the
    last bracket); ``increments`` are the bracket increments from the grid cell down."""

    a: float
    b: float
    size: float
    va: np.ndarray
    vb: np.ndarray
    increments: list
    brackets: list

    @property
    def time(self) -> float:
        return 0.5 * (self.a + self.b)

    def as_dict(self) -> dict:
        return {"t": self.time, "bracket": [self.a, self.b], "jump": self.size, "increments": self.increments}


def _bisect(value: Callable[[float], np.ndarray], a: float, b: float, va, vb, slope, floor: float,
            min_width: float = 0.0):
    seq, brackets = [float(np.linalg.norm(vb - va))], [(a, b)]
    for _ in range(JUMP_MAX_LEVELS):
        mid = 0.5 * (a + b)
        if not a < mid < b or b - a <= min_width:
            break                      # adjacent floats (or the width asked for): nothing left to split
        vm = value(mid)
        trend = slope * (0.5 * (b - a))
        if np.linalg.norm(vm - va - trend) >= np.linalg.norm(vb - vm - trend):    # the half off the trend
            b, vb = mid, vm
        else:
            a, va = mid, vm
        seq.append(float(np.linalg.norm(vb - va)))
        brackets.append((a, b))
        if seq[-1] <= floor and len(seq) > STALL_WINDOW:
            break                      # below rounding: no jump down this path
    stalled = (len(seq) > STALL_WINDOW and seq[-1] > floor and seq[-1] >= STALL_RATIO * seq[-1 - STALL_WINDOW])
    return stalled, a, b, va, vb, seq, brackets


def base_grid(T: float, lo: float = 0.0) -> np.ndarray:
    """The base grid of the search on ``[lo, T]``: ``JUMP_GRID`` equal cells."""
    return np.linspace(lo, T, JUMP_GRID + 1)


def _local_maxima(a: np.ndarray, count: int) -> list[int]:
    """Indices of the ``count`` largest local maxima of ``a`` (``≥`` both neighbours; plateaus count)."""
    if count <= 0 or a.size == 0:
        return []
    padded = np.concatenate([[-np.inf], a, [-np.inf]])
    peak = (a >= padded[:-2]) & (a >= padded[2:])
    idx = np.flatnonzero(peak)
    return idx[np.argsort(a[idx], kind="stable")[::-1][:count]].tolist()


def find_jumps(value: Callable[[float], np.ndarray], T: float, *, grid: int = JUMP_GRID,
               shifts: int = JUMP_SHIFTS, candidates: int = JUMP_CANDIDATES, extrema: int | None = None,
               min_width: float = 0.0, values: Callable[[np.ndarray], np.ndarray] | None = None
               ) -> tuple[list[Jump], dict]:
    """The stalled increments of ``value`` on ``[0, T]`` (see the module docstring), largest first, and
    what was searched (``{"cells": ..., "bisected": ..., "floor": ...}``); the grid is ``grid`` cells and
    ``shifts`` shifted copies (``grid·(shifts + 1)`` cells); ``candidates`` local maxima of the increments
    and ``extrema`` (default :data:`JUMP_EXTREMA`, at least ``candidates``) of the distance from the trend are
    bisected; brackets are split down to adjacent floats, or to ``min_width`` when that is wider.  ``values``: the
    grid's values at once, ``values(times)`` of shape ``(len(times), ·)`` with row ``k`` what ``value(times[k])``
    gives (an operator that takes a time per row: one call for the grid where there were ``grid·(shifts + 1) + 1``;
    the bisection still calls ``value``)."""
    extrema = max(JUMP_EXTREMA if extrema is None else extrema, candidates)
    cells = grid * (shifts + 1)
    times = np.linspace(0.0, T, cells + 1)
    if values is None:
        V = np.array([np.ravel(value(float(t))) for t in times])
    else:
        V = np.asarray(values(times), dtype=float).reshape(len(times), -1)
    dV = np.diff(V, axis=0)
    inc = np.linalg.norm(dV, axis=1)
    floor = tolerance(V)
    padded = np.concatenate([dV[:1], dV, dV[-1:]])
    excess = np.linalg.norm(dV - 0.5 * (padded[:-2] + padded[2:]), axis=1)
    cands = dict.fromkeys(_local_maxima(inc, candidates) + _local_maxima(excess, extrema))
    flat = lambda t: np.ravel(value(t))           # noqa: E731
    jumps, bisected = [], 0
    for i in cands:
        if inc[i] <= floor:
            continue
        bisected += 1
        slope = 0.5 * (padded[i] + padded[i + 2]) / (times[i + 1] - times[i])
        stalled, a, b, va, vb, seq, brackets = _bisect(flat, float(times[i]), float(times[i + 1]), V[i], V[i + 1],
                                                       slope, floor, min_width)
        if stalled:
            jumps.append(Jump(a, b, seq[-1], va, vb, seq, brackets))
    jumps.sort(key=lambda j: -j.size)
    return jumps, {"cells": cells, "bisected": bisected, "floor": floor}


def jump_time(jump: Jump) -> float | None:
    """The time of a jump bracketed by adjacent floats ``a < b``: the one whose shortest decimal
    representation is shorter (a parameter switches at a number written in the source: ``t <= 0.45`` puts
    the switch right after ``a = 0.45``, ``t < 0.45`` right before ``b = 0.45``); ``None`` when neither is
    shorter (in floating point both readings are the same function: the side of the jump is undecidable)."""
    la, lb = len(repr(float(jump.a))), len(repr(float(jump.b)))
    if la == lb:
        return None
    return jump.a if la < lb else jump.b


__all__ = ["find_jumps", "jump_time", "base_grid", "Jump", "JUMP_GRID", "JUMP_SHIFTS", "JUMP_CANDIDATES",
           "JUMP_EXTREMA", "JUMP_MAX_LEVELS"]
