"""Adaptive search for jumps of a sampled function of time ``t ↦ V(t) ∈ R^N``.

For any vector-valued ``V``: on a grid of
``JUMP_GRID`` cells, the cells with the largest increments ``|V(b) − V(a)|`` and those least like their
neighbours' (``|ΔV_i − ½(ΔV_{i−1} + ΔV_{i+1})|``: a small jump on a steep slope) are bisected, keeping
the half whose increment is further off the neighbours' trend, until no float lies strictly between the
ends (or ``JUMP_MAX_LEVELS`` bisections).  On a continuous ``V`` the increment goes to 0 (halving per
bisection when ``V`` is Lipschitz, by ``2^{-1/2}`` when it is Hölder-½); across a jump of size ``J`` it
stays ``≥ J``.  A jump is an increment above the rounding floor that *stalled*: still above
``STALL_RATIO`` times its value ``STALL_WINDOW`` bisections earlier (``verimono.tolerances``; any
Hölder-``p`` ``V`` with ``p > 0.006`` drops below that ratio).  Evidence, not proof: a jump up and back
inside one grid cell is not seen.

Used by ``assumption_A3`` (``V`` = projections of sample points onto ``dom F(t)``) and ``assumption_A2``
(``V`` = resolvents ``J_λ(t) p``) in :mod:`verimono.checks.assumptions`, and by ``lcs.v_ac`` (``V = v``) in
:mod:`verimono.checks.section7`.
"""

from __future__ import annotations

import dataclasses
from typing import Callable

import numpy as np

from ..tolerances import STALL_RATIO, STALL_WINDOW, tolerance

#: cells of the grid on which candidate cells are chosen
JUMP_GRID = 32
#: candidate cells bisected: this many with the largest increments, and this many least like their neighbours
JUMP_CANDIDATES = 2
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


def find_jumps(value: Callable[[float], np.ndarray], T: float, *, grid: int = JUMP_GRID,
               candidates: int = JUMP_CANDIDATES, min_width: float = 0.0) -> tuple[list[Jump], dict]:
    """The stalled increments of ``value`` on ``[0, T]`` (see the module docstring), largest first, and
    what was searched (``{"cells": ..., "bisected": ..., "floor": ...}``); brackets are split down to
    adjacent floats, or to ``min_width`` when that is wider."""
    times = np.linspace(0.0, T, grid + 1)
    V = np.array([np.ravel(value(float(t))) for t in times])
    dV = np.diff(V, axis=0)
    inc = np.linalg.norm(dV, axis=1)
    floor = tolerance(V)
    padded = np.concatenate([dV[:1], dV, dV[-1:]])
    excess = np.linalg.norm(dV - 0.5 * (padded[:-2] + padded[2:]), axis=1)
    cands = dict.fromkeys(np.concatenate([np.argsort(inc)[::-1][:candidates],
                                          np.argsort(excess)[::-1][:candidates]]).tolist())
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
    return jumps, {"cells": grid, "bisected": bisected, "floor": floor}


def jump_time(jump: Jump) -> float | None:
    """The time of a jump bracketed by adjacent floats ``a < b``: the one whose shortest decimal
    representation is shorter (a parameter switches at a number written in the source: ``t <= 0.45`` puts
    the switch right after ``a = 0.45``, ``t < 0.45`` right before ``b = 0.45``); ``None`` when neither is
    shorter (in floating point both readings are the same function: the side of the jump is undecidable)."""
    la, lb = len(repr(float(jump.a))), len(repr(float(jump.b)))
    if la == lb:
        return None
    return jump.a if la < lb else jump.b


__all__ = ["find_jumps", "jump_time", "Jump", "JUMP_GRID", "JUMP_CANDIDATES", "JUMP_MAX_LEVELS"]
