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

import math
from typing import Any, Callable

import numpy as np

from ..core.errors import UnverifiedSolution
from ..core.qp import ACTIVE_RTOL
from ..lcs.hoffman import hoffman_constant
from ..records.results import CheckResult
from ..core.sets import Polyhedron
from ..core.tolerances import QP_RTOL, tolerance
from .core import Outcome, law, run, subject_name
from .engine.sphere import sphere_maximise
from .engine.supremum import Space, budget, maximise

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
#: the far box (:func:`far_box`): its faces' distance from the origin, and the range of its short row's norm
FAR_FACES = 1e3
SHORT_ROW = (0.02, 0.1)
#: the decades of the distance searched (:func:`_point_search`): ``|x|`` from the origin, and ``s`` from the
#: boundary point exposed in a direction, ``10^DECADES[0]`` to ``10^DECADES[1]``
DECADES = (-6, 5)
#: the boundary point exposed in the direction ``d``: the projection of ``EXPOSED_RADIUS · r · d``, ``r`` the
#: polyhedron's size (``1 +`` its faces' largest distance from the origin)
EXPOSED_RADIUS = 10.0


def _norm(v: np.ndarray) -> float:
    """``float(np.linalg.norm(v))`` of a real vector, bit for bit: its own path (``sqrt(w·w)`` of ``w =
    v.ravel(order="K")``) without the wrapper's dispatch (a correctly rounded square root either way)."""
    w = v.ravel(order="K")
    return math.sqrt(float(w.dot(w)))


#: active sets (with their factorizations) a polyhedron's projector keeps, most recently verified first
ACTIVE_SETS = 8


class ActiveSetProjector:
    """Projections onto ``{ζ : Rζ = 0, Qζ ≤ q}`` (the law's ``dist``), cheaper than a QP each, and as verified.

    A point inside is its own projection.  Otherwise the active sets of the last verified projections (at most
    :data:`ACTIVE_SETS`, the rows of ``R`` and some rows of ``Q``, each with ``(MMᵀ)⁻¹`` of its rows ``M``
    factorised once) are tried in turn: ``z = x − Mᵀy`` with ``MMᵀy = Mx − c`` solves the equality-constrained
    projection (at a vertex ``v`` with more active rows than coordinates, ``z = v`` when ``x − v`` lies in the
    cone of its rows: nonnegative least squares, residual to the same tolerance), and ``z`` is accepted only on its KKT certificate — stationarity ``z − x + Mᵀy = 0`` by
    construction, multipliers ``y ≥ 0`` on the ``Q`` rows (exactly: a degenerate vertex goes to the QP), primal
    feasibility and complementary slackness (the active rows tight) to
    :data:`~verimono.core.tolerances.QP_RTOL` relative to the data, as the QP's own check
    (:func:`verimono.core.qp.kkt_residual`) — which for this strictly convex problem makes ``z`` *the*
    minimiser.  No cached set verifying, the point goes to ``P.project`` (the KKT-verified QP of
    :class:`~verimono.core.sets.Polyhedron`; its errors, e.g. :class:`UnverifiedSolution`, pass through) and the
    answer's active set is cached.  Measured on ``check_hoffman(seed=0)``: the QP's 3,878 projections (0.4 ms
    each, 80% of the law's time) are 3,8xx here, of which about one in ten reaches the QP."""

    def __init__(self, P: Polyhedron, Q: np.ndarray, q: np.ndarray, R: np.ndarray | None) -> None:
        self.P, self.Q, self.q = P, np.asarray(Q, float), np.asarray(q, float)
        self.R = None if R is None else np.atleast_2d(np.asarray(R, float))
        self.sets: list[tuple] = []          # (rows of Q, M, c, (MMᵀ)⁻¹, number of R rows)
        self._q_max = float(np.abs(self.q).max(initial=0.0))      # |q|∞, of every projection's scale
        self.hits = self.solves = 0

    def project(self, x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        Q, q, R = self.Q, self.q, self.R
        Qx = Q @ x
        # NumPy's reductions through the arrays' own methods (what np.all, np.any and np.max call: the same
        # values; their wrappers cost more than the reductions on these few coordinates)
        if (Qx <= q).all() and (R is None or (R @ x == 0.0).all()):
            return x.copy()                  # Polyhedron.project's own test, the same arithmetic
        scale = 1.0 + max(float(np.abs(x).max(initial=0.0)), self._q_max)
        tol = QP_RTOL * scale
        for i, (rows, M, c, C, k, vertex) in enumerate(self.sets):
            if vertex is None:
                y = C @ (M @ x - c)
                if (y[k:] < 0.0).any():
                    continue
                z = x - M.T @ y
            else:      # a vertex: x − v must lie in the cone of its active rows (the R rows' both signs)
                from scipy.optimize import nnls     # SciPy's optimizers where they are used (docs/architecture.md)

                y, res = nnls(C, x - vertex)
                if res > tol:
                    continue
                z = vertex.copy()
            slack = Q @ z - q
            if (float(slack.max(initial=0.0)) > tol or float(np.abs(slack[rows]).max(initial=0.0)) > tol
                    or (R is not None and float(np.abs(R @ z).max()) > tol)):
                continue
            if i:
                self.sets.insert(0, self.sets.pop(i))
            self.hits += 1
            return z
        self.solves += 1
        z = np.asarray(self.P.project(x), dtype=float)
        self._learn(z)
        return z

    def _learn(self, z: np.ndarray) -> None:
        """Cache the active set of the verified projection ``z`` (rows within the QP check's active tolerance)."""
        scale = 1.0 + float(np.abs(z).max(initial=0.0))
        rows = np.flatnonzero(self.Q @ z - self.q >= -ACTIVE_RTOL * scale)
        if any(np.array_equal(rows, s[0]) for s in self.sets):
            return
        k = 0 if self.R is None else self.R.shape[0]
        M = self.Q[rows] if self.R is None else np.vstack([self.R, self.Q[rows]])
        if M.shape[0] == 0:
            return
        c = np.concatenate([np.zeros(k), self.q[rows]])
        if M.shape[0] > M.shape[1]:          # more active rows than coordinates: a vertex, when they span R^n
            sv = np.linalg.svd(M, compute_uv=False)
            if sv[-1] <= 1e-5 * sv[0]:
                return
            cone = M.T if self.R is None else np.hstack([-self.R.T, M.T])
            self.sets.insert(0, (rows, M, c, cone, k, z.copy()))
        else:
            G = M @ M.T
            if np.linalg.cond(G) > 1e10:     # (nearly) dependent rows: multipliers not unique, leave it to the QP
                return
            self.sets.insert(0, (rows, M, c, np.linalg.inv(G), k, None))
        del self.sets[ACTIVE_SETS:]


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
    out.append(far_box(seed))
    return out


def far_box(seed: int = 0) -> tuple[str, np.ndarray, None, np.ndarray]:
    """A rotated box ``{ζ : |w_i (Uᵀζ)_i| ≤ w_i D}`` of ``R^n`` (``n`` from 2 to :data:`HOFFMAN_MAX_DIM`) whose
    faces all lie at the distance ``D =`` :data:`FAR_FACES` from the origin, one of its rows short (``w_n`` from
    :data:`SHORT_ROW`, the others 1): Hoffman's constant is ``1/w_n``, attained beyond that face only — a
    polyhedron no point within ``10`` of the origin leaves (its own generator: the other polyhedra's draws are
    unchanged)."""
    rng = np.random.default_rng([int(seed) % (2 ** 63), 0xFA8])
    n = int(rng.integers(2, HOFFMAN_MAX_DIM + 1))
    w = np.ones(n)
    w[-1] = float(np.exp(rng.uniform(np.log(SHORT_ROW[0]), np.log(SHORT_ROW[1]))))
    U, _ = np.linalg.qr(rng.standard_normal((n, n)))
    rows = w[:, None] * U.T
    return (f"far box (n = {n}, faces at {FAR_FACES:.0e}, a row of norm {w[-1]:.3g})", np.vstack([rows, -rows]),
            None, np.r_[w, w] * FAR_FACES)


def run_hoffman(decl: Any, estimator: Callable | None = None, *, seed: int = 0) -> CheckResult:
    """The law of a Hoffman-constant estimator ``estimator(Q, R) -> α`` (default :func:`hoffman_constant`)."""
    est = hoffman_constant if estimator is None else estimator
    return run(decl, subject_name(est), lambda: decl.evaluate(est, seed=seed), seed=seed)


def _point_search(measure: Callable[[np.ndarray], tuple], P: ActiveSetProjector, Q: np.ndarray, q: np.ndarray,
                  d0: np.ndarray, seed: int) -> dict:
    """The largest ratio of ``measure`` over the points of ``R^n`` (module docstring), through the engine: the
    point ``x = s d`` (from the origin) or ``x = b(d) + s w(d)`` (from the boundary point ``b(d)`` exposed in
    the direction ``d`` — the projection of ``EXPOSED_RADIUS · d`` — along its outer normal ``w(d)``: a face's
    or vertex's own cone, where the ratio is largest as ``s → 0``), in three phases —

    1. **decades**: ``s ∈ 10^DECADES`` (:func:`~verimono.checks.engine.supremum.maximise`, ``coordinate``
       budget) along ``d0`` (the worst sampled direction), both families;
    2. **direction**: ``d ∈ S^{n-1}`` at the worst family and ``s``
       (:func:`~verimono.checks.engine.sphere.sphere_maximise`, :func:`budget` ``("points")`` evaluations);
    3. **decades again** along the worst direction, both families.

    Returns ``{"value", "x", "points", "direction": {...}, "decades": {...}}``."""
    n = d0.size
    exposed: dict[bytes, tuple] = {}
    size = 1.0 + float(np.max(np.abs(q) / np.maximum(np.linalg.norm(Q, axis=1), 1e-300), initial=0.0))

    def normal(d: np.ndarray) -> tuple:
        key = d.tobytes()
        if key not in exposed:
            far = EXPOSED_RADIUS * size * d
            b = np.asarray(P.project(far), dtype=float)     # P: the polyhedron's ActiveSetProjector
            w = far - b
            nw = float(np.linalg.norm(w))
            exposed[key] = (b, w / nw if nw > 0 else None)
        return exposed[key]

    def point(f: int, d: np.ndarray, s: float) -> np.ndarray | None:
        if f == 0:
            return s * d
        b, w = normal(d)
        return None if w is None else b + s * w     # d in the recession cone: no boundary exposed

    unverified = [0]

    def value(f: int, d: np.ndarray, s: float) -> float:
        try:
            x = point(f, d, s)
            return -np.inf if x is None else measure(x)[0]
        except UnverifiedSolution:      # verimono's own QP could not verify a projection: no evidence there
            unverified[0] += 1
            return -np.inf

    space = Space("s", 10.0 ** DECADES[0], 10.0 ** DECADES[1], log=True)
    design = [10.0 ** k for k in range(DECADES[0], DECADES[1] + 1)]

    def decades(d: np.ndarray):
        return maximise(lambda s, which: np.array([value(f, d, s) for f in ((0, 1) if which is None else which)]),
                        space, design=design, families=2, kind="coordinate", seed=seed)

    first = decades(d0)
    f, s_best = first.family, first.at
    sph = sphere_maximise(lambda d: value(f, d, s_best), n, points=budget("points"), seed=seed + 0x40FF,
                          start=[d0])
    last = decades(sph["direction"])
    runs = [(first.value, first.family, d0, first.at), (sph["value"], f, sph["direction"], s_best),
            (last.value, last.family, sph["direction"], last.at)]
    v, fam, d, s_at = max(runs, key=lambda r: r[0])
    try:
        x = point(fam, d, s_at) if np.isfinite(v) else None
    except UnverifiedSolution:
        x = None
    return {"value": v, "x": x, "unverified": unverified[0], "family": "from the origin" if fam == 0 else "from the boundary",
            "points": first.searched.evaluations + sph["points"] + last.searched.evaluations,
            "direction": {"sphere": sph["sphere"], "points": sph["points"], "resolution": sph["resolution"]},
            "decades": {"range": list(DECADES), "points": first.searched.points + last.searched.points,
                        "resolution": max(first.searched.resolution, last.searched.resolution)}}


@law("hoffman_bound", "e:hoffman", subject="estimator", driver=run_hoffman, battery=False,
     over=("points", "direction", "scale"))
def check_hoffman(est: Callable, *, seed: int = 0) -> Outcome:
    """``dist(x, 𝓡) ≤ α (|Rx| + |max(0, Qx − q)|)`` on every polyhedron, at the sampled points and the
    worst direction searched (module docstring)."""
    rng = np.random.default_rng(seed)
    worst, counter, rows, searched = 0.0, None, [], 0
    for name, Q, R, q in hoffman_polyhedra(seed):
        alpha = float(est(Q, R))
        P = ActiveSetProjector(Polyhedron(Q, q, R, None if R is None else np.zeros(R.shape[0])), Q, q, R)
        n = Q.shape[1]

        def measure(x: np.ndarray) -> tuple[float, float, float]:
            d = _norm(x - P.project(x))
            res = (0.0 if R is None else _norm(R @ x)) + _norm(np.maximum(0.0, Q @ x - q))
            return d / (alpha * res + tolerance(x, q)), d, res

        u = rng.standard_normal((HOFFMAN_POINTS, n))
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        radii = (0.5, 2.0, 10.0)
        X = np.vstack([r * u for r in radii])
        found = [(measure(x), x) for x in X]
        sup = max((d / res if res > 0 else 0.0) for (_, d, res), _ in found)
        # the search: the point's direction and distance decades, from the origin and from the boundary
        d0 = X[max(range(len(found)), key=lambda k: found[k][0][0])]
        got = _point_search(measure, P, Q, q, d0 / float(np.linalg.norm(d0)), seed)
        used = got["points"]
        searched += used
        if got["x"] is not None:
            found.append((measure(got["x"]), got["x"]))
        for (r, d, res), x in found:
            sup = max(sup, d / res if res > 0 else 0.0)
            if r > worst:
                worst = r
                counter = {"polyhedron": name, "x": x, "dist": d, "residual": res, "alpha": alpha, "seed": seed}
        rows.append({"polyhedron": name, "alpha": alpha, "sampled_sup": sup, "dimension": n, "searched": used,
                     "unverified": got["unverified"],
                     "worst_from": got["family"], "direction": got["direction"], "decades": got["decades"]})
    c = counter or {"polyhedron": "", "dist": 0.0, "residual": 0.0, "alpha": 0.0}
    dims = sorted({r["dimension"] for r in rows})
    return Outcome(worst, details={"polyhedra": rows, "searched": {"polyhedra": len(rows), "dimensions": dims,
                                                                   "points": len(rows) * 3 * HOFFMAN_POINTS + searched,
                                                                   "directions_searched": searched,
                                                                   "direction": {
                                                                       "points": sum(r["direction"]["points"] for r in rows),
                                                                       "resolution": max(r["direction"]["resolution"] for r in rows)},
                                                                   "decades": {"range": list(DECADES), "points": sum(
                                                                       r["decades"]["points"] for r in rows)}}},
                   counter={**c, "message": f"dist(x, 𝓡) = {c['dist']:.4g} > α·(|Rx| + |max(0, Qx − q)|) = "
                                            f"{c['alpha'] * c['residual']:.4g} on the {c['polyhedron']} (α = "
                                            f"{c['alpha']:.4g}, e:hoffman)"},
                   message=f"dist(x, 𝓡) ≤ α (|Rx| + |max(0, Qx − q)|) on {len(rows)} polyhedra of dimensions "
                           f"{dims[0]}–{dims[-1]} (thin cones included) × {3 * HOFFMAN_POINTS} points and the worst "
                           f"direction searched ({searched} evaluations; largest dist/residual over α: "
                           f"{max(r['sampled_sup'] / r['alpha'] for r in rows):.3g}; evidence, not proof)")


__all__ = ["check_hoffman", "ActiveSetProjector", "ACTIVE_SETS", "hoffman_polyhedra", "thin_cone", "far_box", "HOFFMAN_RANDOM", "HOFFMAN_POINTS",
           "HOFFMAN_MAX_DIM", "THIN", "FAR_FACES", "SHORT_ROW", "DECADES", "EXPOSED_RADIUS"]
