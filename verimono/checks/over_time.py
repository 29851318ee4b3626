"""The sup over time of what a hypothesis bounds "for all t": a stated constant is a claim about every t.

A stated φ of (A3), σ of (LG) or θ of (YB), and the "for all t" hypotheses of Section 7 (the
relative-interior margin of ``thm: linear case`` iii, the bound of ``v`` of item iv), were compared at a few
fixed times, and a fixed set of times is blind to whatever happens between them: a ball whose centre is
``0.5 sin 6πt`` is at 0 at every ``k/6``, so the seven sample times ``k/6`` passed φ ≡ 0; ``F = (1 + 5 sin²
6πt) x`` passed σ ≡ 1 (the true sup of ``|F^0|/(1 + |x|)`` is 6); the margin of ``v = |t − 0.4567|`` is 0 at
``t = 0.4567`` but 0.0036 at the nearest of 64 samples.  :func:`sup_over_time` searches instead:

1. every *family* (a sample point and step size whose ratio is a function of ``t``) on the base grid of the
   jump search (:func:`verimono.checks.jumps.base_grid`, ``JUMP_GRID`` cells — not a multiple of 6 or 7);
2. around each of the :data:`SUP_NODES` worst nodes, for its :data:`SUP_FAMILIES` worst families, a bounded
   scalar maximisation (``scipy.optimize.minimize_scalar(method="bounded")``, Brent) over the two cells
   next to the node, to ``xatol = SUP_XATOL·(hi − lo)``; with ``refine=True`` a golden-section search then
   narrows the maximiser down to adjacent floats (a margin that touches 0 at one point is ``O(|t − t*|)``
   there, and Brent's own ``√ε·|t|`` stopping rule leaves it at ``~1e-8``, the size of the tolerance).

The largest value seen by any evaluation is the result, with its time and family: the search can only
raise the grid's value.  An evaluation that verimono's own solvers cannot verify
(:class:`~verimono.UnverifiedSolution`) is no evidence either way: it is counted (``harness_limited``) and
skipped, and only a grid none of whose times could be evaluated raises it.  Evidence, not proof: a sup reached inside a cell away from every worst node
(a narrow bump where the grid sees nothing) is not found.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Callable, Sequence

import numpy as np
from scipy.optimize import minimize_scalar

from ..core.errors import UnverifiedSolution
from .jumps import base_grid

#: worst grid nodes around which the sup is searched locally
SUP_NODES = 3
#: worst families at each such node searched locally
SUP_FAMILIES = 2
#: Brent's absolute tolerance, relative to the length of the interval (a ratio's maximum is flat: a relative
#: error ``δ`` in its place costs ``O(δ²)`` of its value)
SUP_XATOL = 1e-6
#: Brent's iterations at most per local search
SUP_MAXITER = 40
#: golden-section steps of the refinement (``refine=True``): from ``~1e-8`` to below one ulp of ``t``
SUP_REFINE_STEPS = 80

_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


@dataclasses.dataclass
class Sup:
    """The largest value found (``value``, at time ``t``, family ``family``), the grid's largest before the
    local search (``grid_value`` at ``grid_t``), and what was evaluated."""

    value: float
    t: float
    family: int
    grid_value: float
    grid_t: float
    evaluations: int
    nodes: int
    local: list
    harness_limited: int = 0

    def as_dict(self) -> dict:
        return {"sup": self.value, "t": self.t, "family": self.family, "grid_sup": self.grid_value,
                "grid_t": self.grid_t, "evaluations": self.evaluations, "grid_nodes": self.nodes,
                "local_searches": self.local, "harness_limited": self.harness_limited}


def _finite(v: np.ndarray) -> np.ndarray:
    """A NaN ratio counts as the largest (a NaN never passes)."""
    v = np.asarray(v, dtype=float)
    return np.where(np.isnan(v), np.inf, v)


def sup_over_time(values: Callable[[float, Sequence[int] | None], np.ndarray], lo: float, hi: float, *,
                  bounds: Callable[[int], tuple[float, float]] | None = None, grid: np.ndarray | None = None,
                  nodes: int = SUP_NODES, per_node: int = SUP_FAMILIES, xatol: float | None = None,
                  maxiter: int = SUP_MAXITER, refine: bool = False) -> Sup:
    """The sup over ``t ∈ [lo, hi]`` and the families of ``values(t, which)`` — an array over the families
    ``which`` (``None``: all of them, in a fixed order; ``-inf`` where a family is not defined at ``t``) —
    by the search of the module docstring.  ``bounds(f)`` restricts family ``f`` to a sub-interval (the
    times ``s ≤ T − λ`` of a step ``λ``); ``grid`` replaces the base grid."""
    ts = base_grid(hi, lo) if grid is None else np.asarray(grid, dtype=float)
    span = float(hi - lo)
    xatol = SUP_XATOL * span if xatol is None else float(xatol)
    limited = [0]

    def one_family(t: float, f: int) -> float:
        try:
            return float(_finite(values(t, [f]))[0])
        except UnverifiedSolution:      # verimono's own solver, not the subject: no evidence here
            limited[0] += 1
            return -np.inf

    def all_families(t: float) -> np.ndarray:
        try:
            return _finite(values(t, None))
        except UnverifiedSolution:      # family by family, so that one unverified solve costs one value
            return None

    rows = [all_families(float(t)) for t in ts]
    width = next((r.size for r in rows if r is not None), None)
    if width is None:
        raise UnverifiedSolution(f"no time of the grid could be evaluated ({len(ts)} tried)")
    table = np.array([r if r is not None else np.array([one_family(float(t), f) for f in range(width)])
                      for r, t in zip(rows, ts)])
    if table.ndim != 2 or table.shape[1] == 0:
        raise ValueError("values(t, None) must return a nonempty 1-D array (one value per family)")
    count = [len(ts)]
    i0, f0 = np.unravel_index(int(np.argmax(table)), table.shape)
    best = {"value": float(table[i0, f0]), "t": float(ts[i0]), "family": int(f0)}
    grid_value, grid_t = best["value"], best["t"]
    local = []

    def one(f: int, t: float) -> float:
        count[0] += 1
        v = one_family(float(t), f)
        if v > best["value"]:
            best.update(value=v, t=float(t), family=int(f))
        return v

    node_score = table.max(axis=1)
    for i in np.argsort(-node_score, kind="stable")[:nodes]:
        if not node_score[i] > -np.inf:
            continue
        a, b = float(ts[max(i - 1, 0)]), float(ts[min(i + 1, len(ts) - 1)])
        for f in np.argsort(-table[i], kind="stable")[:per_node]:
            f = int(f)
            if not table[i, f] > -np.inf:
                continue
            fa, fb = (lo, hi) if bounds is None else bounds(f)
            a2, b2 = max(a, fa), min(b, fb)
            if not a2 < b2:
                continue

            def neg(t: float, _f: int = f) -> float:
                v = one(_f, t)
                return -v if math.isfinite(v) else (-1e300 if v > 0 else 1e300)

            res = minimize_scalar(neg, bounds=(a2, b2), method="bounded",
                                  options={"xatol": xatol, "maxiter": maxiter})
            x = float(res.x)
            if refine:
                x = _golden(neg, max(a2, x - 64 * (xatol + 1.5e-8 * abs(x))), min(b2, x + 64 * (xatol + 1.5e-8 * abs(x))))
            local.append({"node": float(ts[i]), "family": f, "bracket": [a2, b2], "argmax": x, "value": -neg(x)})
    return Sup(best["value"], best["t"], best["family"], grid_value, grid_t, count[0], len(ts), local, limited[0])


def _golden(neg: Callable[[float], float], a: float, b: float) -> float:
    """Golden-section minimisation of ``neg`` on ``[a, b]`` down to adjacent floats (or
    :data:`SUP_REFINE_STEPS` steps)."""
    c, d = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
    fc, fd = neg(c), neg(d)
    for _ in range(SUP_REFINE_STEPS):
        if not (a < c < d < b):
            break
        if fc <= fd:
            b, d, fd = d, c, fc
            c = b - _GOLDEN * (b - a)
            fc = neg(c)
        else:
            a, c, fc = c, d, fd
            d = a + _GOLDEN * (b - a)
            fd = neg(d)
    return c if fc <= fd else d


__all__ = ["sup_over_time", "Sup", "SUP_NODES", "SUP_FAMILIES", "SUP_XATOL", "SUP_MAXITER", "SUP_REFINE_STEPS"]
