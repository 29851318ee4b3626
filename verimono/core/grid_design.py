"""How a convergence study chooses its grids for the scheme it studies (``thm:main``'s order, or a claim's).

A study starts from the grids it is given — the problem's recommended step sizes, sized for the proximal scheme
at the reference's order — and judges them (:mod:`verimono.core.verdicts`).  Those grids suit a scheme of order 1
or 2; an order-5 or order-8 scheme has left round-off behind after one or two of them, and a scheme whose finest
refinement stops reducing the error needs finer grids before any verdict.  So the verdict may ask for more:

* **coarser grids** — fewer than :data:`MIN_GRIDS` grids lie above the floor (round-off in the stepper's
  precision, or what a stated ``solve_tol`` accumulates): the study adds, in one batch, every grid of the
  *ladder* below the coarsest tried, down to :data:`K_MIN` cells (or the largest step of a ``step_range``).  The
  ladder's cell counts are 3-smooth (``2^a 3^b``: a fine reference for a problem without an exact solution then
  holds every node) and spaced by :func:`ladder_ratio`, about ``8^{1/p}`` for an order ``p ≥ 3`` (errors falling
  8-fold per grid, so several lie between round-off and the pre-asymptotic coarse end) and 2 below (errors falling
  ``2^p``-fold, as the references' grids do).  A grid the study added on which the stepper raises or diverges
  (an explicit scheme far outside its stability region) is left out, never held against the stepper;
* **a finer grid** — the finest refinement fell short of the order far above the floor, or the fit misses the
  order while its finest local slope reaches it (a pre-asymptotic regime from below), or too few grids follow a
  pause: one grid ``ladder_ratio(p)`` times finer (twice finer below order 3), at most
  :data:`EXTRA_REFINEMENTS` times, never finer than as many refinements of the finest given grid (4 times its
  cells below order 3), never past the smallest step of a ``step_range``.

A scheme of an order higher than the given grids were sized for (a claim of order 5 on a reference whose steps
suit the proximal scheme's order 1) starts from the ladder up to the coarsest given grid, not from the finer given
grids, on which its errors would be round-off: an order-5 scheme on ``x' = -Mx`` runs 9 grids of 2 to 200 cells
(694 cells in all) instead of 200 to 3200.

A ``step_range = (h_min, h_max)`` (the user knows where the scheme's asymptotic range lies) replaces all of this:
the study runs the ladder from ``h_max`` down to ``h_min`` at once (at least :data:`MIN_GRIDS` grids) and adds
nothing outside it.  Explicit grids (arrays) are run as given.
"""

from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from .errors import InvalidProblem
from ._validate import step_range_of

#: a study's verdict rests on at least this many grids above the floor when the budget allows it
MIN_GRIDS = 4
#: the coarsest grid a study adds itself has this many cells
K_MIN = 2
#: a study refines at most this many times beyond the grids it was given (a finest refinement falling short)
EXTRA_REFINEMENTS = 2
#: the ladder's grids are spaced so that an order-p scheme's errors fall about this much from one to the next
ERROR_RATIO = 8.0


def ladder_ratio(order: float | None) -> float:
    """The ratio of successive step sizes of the ladder for a scheme of order ``order``: ``min(2, 8^{1/p})``."""
    if order is None or not math.isfinite(order) or order <= 0.0:
        return 2.0
    return min(2.0, ERROR_RATIO ** (1.0 / float(order)))


def smooth_counts(lo: int, hi: int) -> list[int]:
    """The 3-smooth integers ``2^a 3^b`` in ``[lo, hi]``, increasing."""
    out, a = [], 1
    while a <= hi:
        b = a
        while b <= hi:
            if b >= lo:
                out.append(b)
            b *= 3
        a *= 2
    return sorted(out)


def ladder(lo: int, hi: int, ratio: float) -> list[int]:
    """Cell counts from ``hi`` down to ``lo`` (both included when 3-smooth or the ends), each at most the previous
    one divided by ``ratio``, chosen among 3-smooth numbers: increasing."""
    counts = smooth_counts(lo, hi)
    if not counts:
        return [hi] if lo <= hi else []
    out = [hi]
    for k in reversed(counts):
        if k * ratio <= out[-1] * (1.0 + 1e-12):
            out.append(k)
    return sorted(set(out))


def cells_of(grid: np.ndarray, T: float) -> int | None:
    """The cell count of a uniform grid of ``[0, T]`` (``None`` for a nonuniform one)."""
    K = len(grid) - 1
    if np.allclose(grid, np.linspace(0.0, T, K + 1), rtol=0.0, atol=1e-12 * T):
        return K
    return None


def cells_range(T: float, step_range: Any) -> tuple[int, int]:
    """The cell counts ``(K_lo, K_hi)`` of uniform grids of ``[0, T]`` whose step lies in ``step_range = (h_min,
    h_max)`` (either order); an :class:`InvalidProblem` when no two counts fit."""
    h_min, h_max = step_range_of(step_range)
    k_lo = max(1, math.ceil(T / h_max * (1.0 - 1e-12)))
    k_hi = math.floor(T / h_min * (1.0 + 1e-12))
    if k_hi < k_lo + 1:
        raise InvalidProblem(f"step_range {step_range!r} holds fewer than two uniform grids of [0, {T:g}] "
                             f"(cells {k_lo}..{k_hi}); widen it")
    return k_lo, k_hi


class GridPlan:
    """The grids a study runs, and what it may add (module docstring).

    ``initial``: the grids to run first; :meth:`coarser` and :meth:`finer` the grids to add when the verdict asks
    (empty when the budget, the range or fixed grids allow none).  ``design_order``: the order the given grids were
    sized for (the reference's order for the proximal scheme); a scheme of a higher order starts from the ladder
    below the coarsest given grid instead of running the finer ones, whose errors would be round-off."""

    def __init__(self, T: float, grids: Sequence[np.ndarray], order: float | None, *, adaptive: bool,
                 step_range: Any = None, design_order: float | None = None) -> None:
        self.T = float(T)
        self.ratio = ladder_ratio(order)
        self.refined = 0
        self.coarsened = False
        if step_range is not None:
            k_lo, k_hi = cells_range(self.T, step_range)
            counts = ladder(k_lo, k_hi, self.ratio)
            if len(counts) < MIN_GRIDS:      # a narrow range: MIN_GRIDS counts spread evenly in log
                counts = sorted(set(np.unique(np.round(np.geomspace(k_lo, k_hi, MIN_GRIDS))).astype(int).tolist()))
            self.initial = [np.linspace(0.0, self.T, k + 1) for k in counts]
            self.k_lo, self.k_cap, self.adaptive = k_lo, k_hi, False
            self.given = set(counts)
            return
        self.initial = list(grids)
        self.given = {len(g) - 1 for g in grids}
        self.k_lo = K_MIN
        self.adaptive = adaptive and bool(grids) and all(cells_of(g, self.T) is not None for g in self.initial)
        if not self.adaptive:
            self.k_cap = 0
            return
        given = sorted(len(g) - 1 for g in self.initial)
        #: no grid finer than EXTRA_REFINEMENTS refinements of the finest given one
        self.k_cap = given[-1] * (2 ** EXTRA_REFINEMENTS if self.ratio >= 2.0 else
                                  math.ceil(self.ratio ** EXTRA_REFINEMENTS))
        if order is not None and design_order is not None and order > design_order + 0.5:
            # a higher order than the grids were sized for: the ladder up to the coarsest given grid
            self.initial = [np.linspace(0.0, self.T, k + 1) for k in ladder(self.k_lo, given[0], self.ratio)]
            self.coarsened = True

    def is_given(self, grid: np.ndarray) -> bool:
        """Whether ``grid`` is one the study was given (a step range's grids are), not one it chose itself."""
        return len(grid) - 1 in self.given

    def coarser(self, tried: Sequence[np.ndarray]) -> list[np.ndarray]:
        """The ladder's grids below the coarsest tried, down to ``K_MIN`` cells (once)."""
        if not self.adaptive or self.coarsened:
            return []
        self.coarsened = True
        k_min = min(len(g) - 1 for g in tried)
        counts = [k for k in ladder(self.k_lo, k_min, self.ratio) if k < k_min]
        return [np.linspace(0.0, self.T, k + 1) for k in counts]

    def _next(self, tried: Sequence[np.ndarray]) -> int:
        k = max(len(g) - 1 for g in tried)
        return 2 * k if self.ratio >= 2.0 else min(smooth_counts(math.ceil(k * self.ratio), 4 * k + 8))

    def can_refine(self, tried: Sequence[np.ndarray]) -> bool:
        return (self.adaptive and bool(tried) and self.refined < EXTRA_REFINEMENTS
                and self._next(tried) <= self.k_cap)

    def finer(self, tried: Sequence[np.ndarray]) -> list[np.ndarray]:
        """One grid finer than the finest tried: twice the cells below order 3, else the next 3-smooth count
        ``ladder_ratio`` times more; at most ``EXTRA_REFINEMENTS`` of them, none finer than as many refinements of
        the finest given grid."""
        if not self.can_refine(tried):
            return []
        self.refined += 1
        return [np.linspace(0.0, self.T, self._next(tried) + 1)]


__all__ = ["GridPlan", "ladder", "ladder_ratio", "smooth_counts", "cells_of", "cells_range", "MIN_GRIDS", "K_MIN",
           "EXTRA_REFINEMENTS", "ERROR_RATIO"]
