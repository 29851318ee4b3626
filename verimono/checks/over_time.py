"""The sup over time of what a hypothesis bounds "for all t": a stated constant is a claim about every t.

A stated φ of (A3), σ of (LG) or θ of (YB), and the "for all t" hypotheses of Section 7 (the
relative-interior margin of ``thm: linear case`` iii, the bound of ``v`` of item iv), were compared at a few
fixed times, and a fixed set of times is blind to whatever happens between them: a ball whose centre is
``0.5 sin 6πt`` is at 0 at every ``k/6``, so the seven sample times ``k/6`` passed φ ≡ 0; ``F = (1 + 5 sin²
6πt) x`` passed σ ≡ 1 (the true sup of ``|F^0|/(1 + |x|)`` is 6); and a 16-cell grid with a local search at
its three worst nodes passed a σ broken on a window of width ``T/300`` at an irrational time.
:func:`sup_over_time` is the one search of :mod:`verimono.checks.engine.supremum` on the space ``t ∈ [lo, hi]``:
its design (the base grid of the jump search, :func:`verimono.checks.jumps.base_grid`, or the law's own
times), a coverage grid and DIRECT on the largest families, a bounded Brent maximisation around the largest
points (with ``refine=True`` a golden-section search down to adjacent floats), with the profile's budget
of points (``search["time"]``: ``ci`` resolves windows of ``T/384``).  The assumption laws search time by count
instead (:mod:`verimono.checks.engine.times`: jittered strata, ``ci`` to ``T/2048``).

The largest value seen by any evaluation is the result, with its time and family: the search can only
raise the design's value.  An evaluation that verimono's own solvers cannot verify
(:class:`~verimono.UnverifiedSolution`) is no evidence either way: it is counted (``harness_limited``) and
skipped, and only a design none of whose times could be evaluated raises it.  Evidence, not proof: a
violation on a window narrower than the recorded resolution is outside what was searched.
"""

from __future__ import annotations

from typing import Callable, Sequence

import numpy as np

from .jumps import base_grid
from .engine.supremum import NODES, PER_NODE, REFINE_STEPS, Space, Sup, maximise

#: the names this module had (the search is :mod:`verimono.checks.engine.supremum`'s)
SUP_NODES, SUP_FAMILIES, SUP_REFINE_STEPS = NODES, PER_NODE, REFINE_STEPS


def sup_over_time(values: Callable[[float, Sequence[int] | None], np.ndarray], lo: float, hi: float, *,
                  bounds: Callable[[int], tuple[float, float]] | None = None, grid: np.ndarray | None = None,
                  nodes: int = NODES, per_node: int = PER_NODE, refine: bool = False, points: int | None = None,
                  seed: int = 0, design: Sequence[float] = ()) -> Sup:
    """The sup over ``t ∈ [lo, hi]`` and the families of ``values(t, which)`` — an array over the families
    ``which`` (``None``: all of them, in a fixed order; ``-inf`` where a family is not defined at ``t``) —
    by :func:`verimono.checks.engine.supremum.maximise`.  ``grid`` replaces the base grid as the design, ``design``
    adds times to it (the times just after a jump); ``bounds(f)`` restricts family ``f`` to a sub-interval
    (the times ``s ≤ T − λ`` of a step ``λ``); ``points``: the budget (default: the profile's)."""
    ts = base_grid(hi, lo) if grid is None else np.asarray(grid, dtype=float)
    extra = np.asarray([d for d in design if lo <= d <= hi], dtype=float)
    return maximise(values, Space("t", float(lo), float(hi)), design=np.r_[ts, extra], points=points,
                    kind="time", nodes=nodes, per_node=per_node, refine=refine, seed=seed, bounds=bounds)


__all__ = ["sup_over_time", "Sup", "SUP_NODES", "SUP_FAMILIES", "SUP_REFINE_STEPS"]
