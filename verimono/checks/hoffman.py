"""Hoffman's bound ``e:hoffman`` as a law of a Hoffman-constant estimator (by default
:func:`verimono.lcs.hoffman.hoffman_constant`): on sampled polyhedra ``{ζ : Rζ = 0, Qζ ≤ q}`` and points
``x`` around them, ``dist(x, 𝓡) ≤ α(|Rx| + |max(0, Qx − q)|)`` with the estimator's ``α``, the distance by
the KKT-verified projection of :class:`verimono.core.sets.Polyhedron`.

Polyhedra: a triangle, a box cut by a hyperplane (an equality), the thin wedge ``{0 ≤ ζ_2 ≤ ε ζ_1}``
(Hoffman's constant ``≈ 1/ε``: a bound that ignores the angle between rows fails there), and
``HOFFMAN_RANDOM`` random ones per seed (``Q`` Gaussian, ``q`` making a sampled point interior, with an
equality row half the time).  Evidence, not proof: the sup of ``dist/residual`` is sampled.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ..lcs.hoffman import hoffman_constant
from ..records.results import CheckResult
from ..core.sets import Polyhedron
from ..core.tolerances import tolerance
from .core import Outcome, law, run, subject_name

#: random polyhedra per seed
HOFFMAN_RANDOM = 4
#: sampled points per polyhedron (at three radii around it)
HOFFMAN_POINTS = 48
#: the thin wedge's opening
WEDGE = 0.05


def hoffman_polyhedra(seed: int = 0) -> list[tuple[str, np.ndarray, np.ndarray | None, np.ndarray]]:
    """``(name, Q, R, q)``: the fixed polyhedra and ``HOFFMAN_RANDOM`` random ones."""
    out = [("triangle", np.array([[-1.0, 0.0], [0.0, -1.0], [1.0, 1.0]]), None, np.array([0.0, 0.0, 1.0])),
           ("box cut by ζ_1 = ζ_2", np.vstack([np.eye(3), -np.eye(3)]), np.array([[1.0, -1.0, 0.0]]), np.ones(6)),
           (f"wedge 0 ≤ ζ_2 ≤ {WEDGE} ζ_1", np.array([[0.0, -1.0], [-WEDGE, 1.0]]), None, np.zeros(2))]
    rng = np.random.default_rng(seed)
    for i in range(HOFFMAN_RANDOM):
        n = int(rng.integers(2, 4))
        m = int(rng.integers(n, n + 3))
        Q = rng.standard_normal((m, n))
        z = rng.standard_normal(n)
        R = rng.standard_normal((1, n)) if i % 2 else None
        if R is not None:
            z = z - R[0] * (R[0] @ z) / (R[0] @ R[0])       # Rz = 0
        q = Q @ z + rng.uniform(0.1, 1.0, m)
        out.append((f"random {i} (n = {n}, {m} inequalities{', an equality' if R is not None else ''})", Q, R, q))
    return out


def run_hoffman(decl: Any, estimator: Callable | None = None, *, seed: int = 0) -> CheckResult:
    """The law of a Hoffman-constant estimator ``estimator(Q, R) -> α`` (default :func:`hoffman_constant`)."""
    est = hoffman_constant if estimator is None else estimator
    return run(decl, subject_name(est), lambda: decl.evaluate(est, seed=seed), seed=seed)


@law("hoffman_bound", "e:hoffman", subject="estimator", driver=run_hoffman, battery=False)
def check_hoffman(est: Callable, *, seed: int = 0) -> Outcome:
    """``dist(x, 𝓡) ≤ α (|Rx| + |max(0, Qx − q)|)`` on every sampled polyhedron and point (module docstring)."""
    rng = np.random.default_rng(seed)
    worst, counter, rows = 0.0, None, []
    for name, Q, R, q in hoffman_polyhedra(seed):
        alpha = float(est(Q, R))
        P = Polyhedron(Q, q, R, None if R is None else np.zeros(R.shape[0]))
        n = Q.shape[1]
        u = rng.standard_normal((HOFFMAN_POINTS, n))
        X = np.vstack([r * u / np.linalg.norm(u, axis=1, keepdims=True) for r in (0.5, 2.0, 10.0)])
        sup = 0.0
        for x in X:
            d = float(np.linalg.norm(x - P.project(x)))
            res = (0.0 if R is None else float(np.linalg.norm(R @ x))) + float(np.linalg.norm(np.maximum(0.0, Q @ x - q)))
            r = d / (alpha * res + tolerance(x, q))
            sup = max(sup, d / res if res > 0 else 0.0)
            if r > worst:
                worst = r
                counter = {"polyhedron": name, "x": x, "dist": d, "residual": res, "alpha": alpha, "seed": seed}
        rows.append({"polyhedron": name, "alpha": alpha, "sampled_sup": sup})
    c = counter or {"polyhedron": "", "dist": 0.0, "residual": 0.0, "alpha": 0.0}
    return Outcome(worst, details={"polyhedra": rows},
                   counter={**c, "message": f"dist(x, 𝓡) = {c['dist']:.4g} > α·(|Rx| + |max(0, Qx − q)|) = "
                                            f"{c['alpha'] * c['residual']:.4g} on the {c['polyhedron']} (α = "
                                            f"{c['alpha']:.4g}, e:hoffman)"},
                   message=f"dist(x, 𝓡) ≤ α (|Rx| + |max(0, Qx − q)|) on {len(rows)} polyhedra × {3 * HOFFMAN_POINTS} "
                           f"points (sampled sup of dist/residual over α: "
                           f"{max(r['sampled_sup'] / r['alpha'] for r in rows):.3g}; evidence, not proof)")


__all__ = ["check_hoffman", "hoffman_polyhedra", "HOFFMAN_RANDOM", "HOFFMAN_POINTS"]
