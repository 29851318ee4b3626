"""Vladimirov's pseudo-distance estimator checked both ways against an exact value (``def:dis``).

For normal cones of closed convex sets ``C1``, ``C2`` the pseudo-distance *is* the Hausdorff distance,
``dis(N_C1, N_C2) = d_H(C1, C2)`` (Vladimirov 1991; Kunze & Monteiro Marques 1997):

* ``≤``: for ``y1 ∈ N_C1(x1)``, ``⟨y1, x2 − x1⟩ = ⟨y1, x2 − P_C1 x2⟩ + ⟨y1, P_C1 x2 − x1⟩ ≤ |y1| dist(x2, C1)``
  (the second term is ``≤ 0`` by normality), and symmetrically, so the quotient is at most
  ``d_H (|y1| + |y2|)/(1 + |y1| + |y2|) < d_H``;
* ``≥``: ``x1 ∈ C1`` with ``y1 = 0`` and ``x2 = P_C2 x1``, ``y2 = s (x1 − x2)`` give
  ``s |x1 − x2|² / (1 + s|x1 − x2|) → dist(x1, C2)`` as ``s → ∞``; the sup over ``x1`` is the excess.

:func:`check_pseudo_distance` runs an estimator (by default :func:`verimono.pseudo_distance_lower_bound`)
on pairs of catalog sets whose ``d_H`` is known in closed form (balls: ``|c1 − c2| + |r1 − r2|``; boxes:
the larger of the two excesses ``sqrt(Σ_i max(l2_i − l1_i, u1_i − u2_i, 0)²)``; parallel half-spaces
``{⟨a, x⟩ ≤ b_i}``, ``|a| = 1``: ``|b1 − b2|``) and requires, on every pair,
``value ≤ d_H + tol`` (it is a *lower* bound) and ``value ≥ d_H / PSEUDO_DISTANCE_FACTOR`` (it is a
useful one).  Samples: random points around both sets, their projections onto each set (a boundary
point ``x1`` of ``C1`` fed to ``N_C2`` gives exactly the pair of the ``≥`` argument, with ``s = 1/λ``),
and a few projected ascent steps from those towards the farthest points (:func:`_ascend`).
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ..core import sets
from ..core.operators import NormalCone
from ..core.pseudo_distance import pseudo_distance_lower_bound
from ..records.results import CheckResult
from ..core.tolerances import PSEUDO_DISTANCE_FACTOR, tolerance
from .core import Outcome, law, run, subject_name

#: step sizes of the sampled graph points: a large one (y ≈ 0 at boundary points) and a small one
#: (|y| = dist/λ ≈ 1e6 dist, so s/(1 + s) is within 1e-6 of 1)
LAMS = (1e3, 1e-6)
#: random directions per pair (around the midpoint of the two sets, at three radii)
DIRECTIONS = 32
#: projected ascent steps from sampled boundary points towards the farthest points (:func:`_ascend`)
ASCENT_STEPS = 8


def _box_excess(l1, u1, l2, u2) -> float:
    return float(np.sqrt(np.sum(np.maximum(np.maximum(l2 - l1, u1 - u2), 0.0) ** 2)))


def hausdorff_pairs() -> list[tuple[str, Any, Any, float, np.ndarray]]:
    """``(name, C1, C2, d_H(C1, C2), centre)``: catalog sets with their exact Hausdorff distance."""
    out = []
    for c1, r1, c2, r2 in (([0.0, 0.0], 1.0, [0.5, 0.0], 1.0), ([0.0, 0.0], 1.0, [0.3, -0.4], 2.0),
                           ([1.0, 0.0, 0.0], 0.5, [0.0, 1.0, 0.5], 1.5)):
        c1, c2 = np.array(c1), np.array(c2)
        out.append((f"balls B({c1.tolist()}, {r1}), B({c2.tolist()}, {r2})", sets.Ball(c1, r1), sets.Ball(c2, r2),
                    float(np.linalg.norm(c1 - c2) + abs(r1 - r2)), 0.5 * (c1 + c2)))
    for l1, u1, l2, u2 in (([0.0, 0.0], [1.0, 1.0], [0.5, -0.2], [1.2, 2.0]),
                           ([-1.0, -1.0, 0.0], [1.0, 0.0, 1.0], [0.0, -0.5, -1.0], [0.5, 1.0, 2.0])):
        l1, u1, l2, u2 = map(np.array, (l1, u1, l2, u2))
        dH = max(_box_excess(l1, u1, l2, u2), _box_excess(l2, u2, l1, u1))
        out.append((f"boxes [{l1.tolist()}, {u1.tolist()}], [{l2.tolist()}, {u2.tolist()}]", sets.Box(l1, u1),
                    sets.Box(l2, u2), dH, 0.25 * (l1 + u1 + l2 + u2)))
    a = np.array([0.6, 0.8])
    out.append(("half-spaces <a, x> ≤ 0, <a, x> ≤ 0.7 (|a| = 1)", sets.HalfSpace(a, 0.0), sets.HalfSpace(a, 0.7),
                0.7, 0.35 * a))
    return out


def _ascend(C1, C2, X: np.ndarray, reach: float) -> np.ndarray:
    """``ASCENT_STEPS`` projected ascent steps ``x ← P_C1(x + reach·d)``, ``d`` the unit gradient of
    ``dist(·, C2)`` at ``x`` (towards the farthest points of ``C1`` from ``C2``, where the excess is
    attained; a long step lands on the face of ``C1`` exposed by ``d``)."""
    for _ in range(ASCENT_STEPS):
        G = X - np.array([C2.project(x) for x in X])
        n = np.linalg.norm(G, axis=1, keepdims=True)
        G = np.divide(G, n, out=np.zeros_like(G), where=n > 0)
        X = np.array([C1.project(x + reach * g) for x, g in zip(X, G)])
    return X


def _samples(C1, C2, centre: np.ndarray, rng) -> np.ndarray:
    n = centre.size
    u = rng.standard_normal((DIRECTIONS, n))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    P = np.vstack([centre + r * u for r in (0.5, 2.0, 5.0)])
    B1, B2 = np.array([C1.project(p) for p in P]), np.array([C2.project(p) for p in P])
    reach = 10.0 * (1.0 + float(np.abs(P).max()))
    return np.vstack([P, B1, B2, _ascend(C1, C2, B1[-DIRECTIONS:], reach), _ascend(C2, C1, B2[-DIRECTIONS:], reach)])


def run_estimator(decl: Any, estimator: Callable | None = None, *, seed: int = 0) -> CheckResult:
    """A law of a pseudo-distance estimator (by default :func:`verimono.pseudo_distance_lower_bound`)."""
    est = pseudo_distance_lower_bound if estimator is None else estimator
    rec = run(decl, subject_name(est), lambda: decl.evaluate(est, seed=seed), seed=seed)
    return rec


@law("pseudo_distance_hausdorff", "def:dis", subject="estimator", driver=run_estimator)
def check_pseudo_distance(est: Callable, *, seed: int = 0) -> Outcome:
    """``d_H/PSEUDO_DISTANCE_FACTOR ≤ estimator(N_C1, N_C2, samples) ≤ d_H`` on every pair of
    :func:`hausdorff_pairs` (module docstring).  ``estimator(F1, F2, samples, lams=...)`` returns a number or
    a :class:`~verimono.core.pseudo_distance.PseudoDistanceBound`."""
    name = subject_name(est)
    rng = np.random.default_rng(seed)
    worst, counter, rows = 0.0, None, []
    for label, C1, C2, dH, centre in hausdorff_pairs():
        samples = _samples(C1, C2, centre, rng)
        value = float(est(NormalCone(C1), NormalCone(C2), samples, lams=LAMS))
        tol = tolerance(dH, samples)
        over = value / (dH + tol)                                  # a lower bound: ≤ 1
        under = dH / (PSEUDO_DISTANCE_FACTOR * max(value, 0.0) + tol)     # a useful one: ≤ 1
        rows.append({"pair": label, "d_H": dH, "value": value})
        r = max(over, under)
        if r > worst:
            worst = r
            counter = {"pair": label, "d_H": dH, "value": value, "seed": seed,
                       "side": "above d_H: not a lower bound" if over >= under else
                               f"below d_H/{PSEUDO_DISTANCE_FACTOR:g}: too weak"}
    counter = counter or {"pair": "", "d_H": 0.0, "value": 0.0, "seed": seed, "side": ""}
    ratios = [r["value"] / r["d_H"] for r in rows]
    return Outcome(worst, details={"pairs": rows, "factor": PSEUDO_DISTANCE_FACTOR, "lams": LAMS},
                   counter={**counter, "message": f"{name} gives {counter['value']:.6g} for d_H = {counter['d_H']:.6g} "
                                                  f"on {counter['pair']}: {counter['side']} (dis(N_C1, N_C2) = "
                                                  "d_H(C1, C2), def:dis)"},
                   message=f"d_H/{PSEUDO_DISTANCE_FACTOR:g} ≤ {name} ≤ d_H on {len(rows)} pairs of balls, boxes and "
                           f"half-spaces (ratios value/d_H {min(ratios):.4g} … {max(ratios):.4g}; "
                           "dis(N_C1, N_C2) = d_H(C1, C2))")


__all__ = ["check_pseudo_distance", "hausdorff_pairs", "LAMS", "DIRECTIONS"]
