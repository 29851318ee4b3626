"""Hoffman's bound ``e:hoffman`` as a law of a Hoffman-constant estimator (by default
:func:`verimono.lcs.hoffman.hoffman_constant`): on polyhedra ``{ζ : Rζ = 0, Qζ ≤ q}`` and points ``x`` around
them, ``dist(x, 𝓡) ≤ α(|Rx| + |max(0, Qx − q)|)`` with the estimator's ``α``, the distance by the
KKT-verified projection of :class:`verimono.core.sets.Polyhedron`.

Polyhedra: a triangle, a box cut by a hyperplane (an equality), the thin wedge ``{0 ≤ ζ_2 ≤ ε ζ_1}``
(Hoffman's constant ``≈ 1/ε``: a bound that ignores the angle between rows fails there), the ray
``{ζ_2 = −ε ζ_1 ≥ 0}`` (the same angle between an equality and an inequality: a bound that forgets the
equalities fails there),
``HOFFMAN_RANDOM`` random ones per seed in dimensions 2 to :data:`HOFFMAN_MAX_DIM` (``Q`` Gaussian, ``q``
making a sampled point interior, with an equality row half the time), and thin cones per seed in
dimensions 3 to :data:`HOFFMAN_MAX_DIM` (:func:`thin_cone`: ``n`` rows ``u_i − ε a`` with ``u_i`` the
vertices of a regular simplex of ``a^⊥`` (three times in four), or ``2(n − 1)`` rows ``±b_j − ε a``, rotated at
random; ``ε`` drawn from :data:`THIN` — every ``n − 1`` of the simplex rows are well conditioned and all ``n`` nearly dependent,
so an estimator that looks at too few rows at once understates the constant).

Points: :data:`HOFFMAN_POINTS` random directions at three radii around each polyhedron, then the worst
direction **searched** (:mod:`verimono.checks.engine.supremum`'s ``points`` budget per polyhedron):
``scipy.optimize.differential_evolution`` over directions ``u ∈ [−1, 1]^n`` (at the radius of the worst
sample), its first population the largest sampled ratios, then a Nelder–Mead polish.  Evidence, not proof.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np
from scipy.optimize import differential_evolution, minimize

from ..lcs.hoffman import hoffman_constant
from ..records.results import CheckResult
from ..core.sets import Polyhedron
from ..core.tolerances import tolerance
from .core import Outcome, law, run, subject_name
from .engine.supremum import budget

#: random polyhedra per seed
HOFFMAN_RANDOM = 4
#: sampled points per polyhedron (at three radii around it)
HOFFMAN_POINTS = 32
#: the thin wedge's opening
WEDGE = 0.05
#: dimensions of the random polyhedra and thin cones: up to this
HOFFMAN_MAX_DIM = 5
#: the openings ε of the thin cones, drawn log-uniformly from this range
THIN = (0.01, 0.2)
#: the population of the direction search (rows of its first generation: the best sampled directions)
POPULATION = 10


def thin_cone(n: int, eps: float, rng: np.random.Generator, simplex: bool = True) -> np.ndarray:
    """``Q`` of a thin cone ``{ζ : Qζ ≤ 0}`` around a random axis ``a`` of ``R^n``: rows ``u_i − ε a`` with
    ``u_i`` the ``n`` vertices of a regular simplex of ``a^⊥`` (``simplex``), else ``±`` an orthonormal basis
    of ``a^⊥`` (``2(n − 1)`` rows); the cone's opening is about ``ε`` and Hoffman's constant about ``1/ε``."""
    basis, _ = np.linalg.qr(rng.standard_normal((n, n)))
    a, perp = basis[:, 0], basis[:, 1:]
    if simplex:
        E = np.eye(n) - 1.0 / n                     # n points of R^n centred: a simplex of an (n−1)-plane
        U, _, _ = np.linalg.svd(E)
        coords = E @ U[:, : n - 1]                  # its vertices in R^(n−1)
        coords /= np.linalg.norm(coords, axis=1, keepdims=True)
        dirs = coords @ perp.T
    else:
        dirs = np.vstack([perp.T, -perp.T])
    return dirs - eps * a[None, :]


def hoffman_polyhedra(seed: int = 0) -> list[tuple[str, np.ndarray, np.ndarray | None, np.ndarray]]:
    """``(name, Q, R, q)``: the fixed polyhedra, ``HOFFMAN_RANDOM`` random ones and the thin cones."""
    out = [("triangle", np.array([[-1.0, 0.0], [0.0, -1.0], [1.0, 1.0]]), None, np.array([0.0, 0.0, 1.0])),
           ("box cut by ζ_1 = ζ_2", np.vstack([np.eye(3), -np.eye(3)]), np.array([[1.0, -1.0, 0.0]]), np.ones(6)),
           (f"wedge 0 ≤ ζ_2 ≤ {WEDGE} ζ_1", np.array([[0.0, -1.0], [-WEDGE, 1.0]]), None, np.zeros(2)),
           (f"ray ζ_2 = −{WEDGE} ζ_1 ≥ 0 (an equality at a small angle to an inequality)", np.array([[0.0, -1.0]]),
            np.array([[WEDGE, 1.0]]), np.zeros(1))]
    rng = np.random.default_rng(seed)
    for i in range(HOFFMAN_RANDOM):
        n = int(rng.integers(2, HOFFMAN_MAX_DIM + 1))
        m = int(rng.integers(n, n + 3))
        Q = rng.standard_normal((m, n))
        z = rng.standard_normal(n)
        R = rng.standard_normal((1, n)) if i % 2 else None
        if R is not None:
            z = z - R[0] * (R[0] @ z) / (R[0] @ R[0])       # Rz = 0
        q = Q @ z + rng.uniform(0.1, 1.0, m)
        out.append((f"random {i} (n = {n}, {m} inequalities{', an equality' if R is not None else ''})", Q, R, q))
    for n in range(3, HOFFMAN_MAX_DIM + 1):
        simplex = bool(rng.integers(0, 4))          # the simplex kind three times in four
        eps = float(np.exp(rng.uniform(np.log(THIN[0]), np.log(THIN[1]))))
        Q = thin_cone(n, eps, rng, simplex)
        out.append((f"thin cone (n = {n}, {'simplex' if simplex else 'square'}, ε = {eps:.3g})", Q, None,
                    np.zeros(Q.shape[0])))
    return out


def run_hoffman(decl: Any, estimator: Callable | None = None, *, seed: int = 0) -> CheckResult:
    """The law of a Hoffman-constant estimator ``estimator(Q, R) -> α`` (default :func:`hoffman_constant`)."""
    est = hoffman_constant if estimator is None else estimator
    return run(decl, subject_name(est), lambda: decl.evaluate(est, seed=seed), seed=seed)


def _worst_direction(ratio: Callable[[np.ndarray], float], starts: np.ndarray, points: int, seed: int):
    """The largest ``ratio(u)`` over ``u ∈ [−1, 1]^n``: differential evolution whose first population is
    ``starts``, then Nelder–Mead from its best; returns ``(u, value, evaluations)``."""
    count = [0]

    def neg(u: np.ndarray) -> float:
        count[0] += 1
        v = ratio(u)
        return -v if np.isfinite(v) else -1e300

    n = starts.shape[1]
    gens = max(1, (3 * points // 4) // len(starts) - 1)
    de = differential_evolution(neg, [(-1.0, 1.0)] * n, init=np.clip(starts, -1.0, 1.0), maxiter=gens, tol=0.0,
                                atol=0.0, polish=False, seed=seed, updating="immediate")
    nm = minimize(neg, de.x, method="Nelder-Mead", options={"maxfev": max(points // 4, 2 * n), "xatol": 1e-9,
                                                            "fatol": 0.0})
    best = nm if nm.fun < de.fun else de
    return np.asarray(best.x), -float(best.fun), count[0]


@law("hoffman_bound", "e:hoffman", subject="estimator", driver=run_hoffman, battery=False)
def check_hoffman(est: Callable, *, seed: int = 0) -> Outcome:
    """``dist(x, 𝓡) ≤ α (|Rx| + |max(0, Qx − q)|)`` on every polyhedron, at the sampled points and the
    worst direction searched (module docstring)."""
    rng = np.random.default_rng(seed)
    worst, counter, rows, searched = 0.0, None, [], 0
    per = budget("points")
    for name, Q, R, q in hoffman_polyhedra(seed):
        alpha = float(est(Q, R))
        P = Polyhedron(Q, q, R, None if R is None else np.zeros(R.shape[0]))
        n = Q.shape[1]

        def measure(x: np.ndarray) -> tuple[float, float, float]:
            d = float(np.linalg.norm(x - P.project(x)))
            res = (0.0 if R is None else float(np.linalg.norm(R @ x))) + float(np.linalg.norm(np.maximum(0.0, Q @ x - q)))
            return d / (alpha * res + tolerance(x, q)), d, res

        u = rng.standard_normal((HOFFMAN_POINTS, n))
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        radii = (0.5, 2.0, 10.0)
        X = np.vstack([r * u for r in radii])
        found = [(measure(x), x) for x in X]
        sup = max((d / res if res > 0 else 0.0) for (_, d, res), _ in found)
        # the search: directions at the radius of the worst sample, from the best sampled ones
        order = sorted(range(len(found)), key=lambda k: -found[k][0][0])
        radius = radii[order[0] // HOFFMAN_POINTS]
        starts = np.array([X[k] / radius for k in order[:POPULATION]])

        def ratio(v: np.ndarray) -> float:
            nv = float(np.linalg.norm(v))
            return measure(radius * v / nv)[0] if nv > 1e-12 else 0.0

        v, _, used = _worst_direction(ratio, starts, per, seed)
        searched += used
        x = radius * v / max(float(np.linalg.norm(v)), 1e-300)
        found.append((measure(x), x))
        for (r, d, res), x in found:
            sup = max(sup, d / res if res > 0 else 0.0)
            if r > worst:
                worst = r
                counter = {"polyhedron": name, "x": x, "dist": d, "residual": res, "alpha": alpha, "seed": seed}
        rows.append({"polyhedron": name, "alpha": alpha, "sampled_sup": sup, "dimension": n, "searched": used})
    c = counter or {"polyhedron": "", "dist": 0.0, "residual": 0.0, "alpha": 0.0}
    dims = sorted({r["dimension"] for r in rows})
    return Outcome(worst, details={"polyhedra": rows, "searched": {"polyhedra": len(rows), "dimensions": dims,
                                                                   "points": len(rows) * 3 * HOFFMAN_POINTS + searched,
                                                                   "directions_searched": searched}},
                   counter={**c, "message": f"dist(x, 𝓡) = {c['dist']:.4g} > α·(|Rx| + |max(0, Qx − q)|) = "
                                            f"{c['alpha'] * c['residual']:.4g} on the {c['polyhedron']} (α = "
                                            f"{c['alpha']:.4g}, e:hoffman)"},
                   message=f"dist(x, 𝓡) ≤ α (|Rx| + |max(0, Qx − q)|) on {len(rows)} polyhedra of dimensions "
                           f"{dims[0]}–{dims[-1]} (thin cones included) × {3 * HOFFMAN_POINTS} points and the worst "
                           f"direction searched ({searched} evaluations; largest dist/residual over α: "
                           f"{max(r['sampled_sup'] / r['alpha'] for r in rows):.3g}; evidence, not proof)")


__all__ = ["check_hoffman", "hoffman_polyhedra", "thin_cone", "HOFFMAN_RANDOM", "HOFFMAN_POINTS",
           "HOFFMAN_MAX_DIM", "THIN"]
