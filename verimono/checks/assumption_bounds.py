"""(A3), (LG), (YB): the assumptions with a bounding function φ, σ, θ — each stated function a claim about
every ``t`` (and every ``x``), compared with the sup of what it bounds, searched over ``t`` by count
(:mod:`verimono.checks.engine.times`: both ends, jittered strata, refined at the worst windows) from the sample
times and the times just after every jump found, and for (LG) over the distance of ``x`` from ``x0`` and from the kink ``0``.

* ``assumption_A3`` — ``D(s,t) = max_z dist(z, dom F(t))`` over sampled ``z ∈ dom F(s)`` (``project_domain`` of
  ``x0`` and the points around it);
  the least nondecreasing ``φ̂`` with ``φ̂(t) - φ̂(s) ≥ D(s,t)`` on the sampled times is reported.  A stated
  ``problem.phi`` is compared with ``D`` at the sample times and on every window ``[s, s + w]``,
  ``w ∈`` :data:`A3_WINDOWS` ``·T``, searched over ``s``, and at the worst windows over the boundary points of
  ``dom F(s)`` exposed in every direction (:mod:`verimono.checks.engine.sphere`): the motion's sup over
  ``z ∈ dom F(s)`` is attained on the boundary, which the points around ``x0`` meet only at an angle.  With or without a stated φ, a jump of φ̂ disproves (A3) (φ must be absolutely continuous):
  the jumps of the projections ``t ↦ proj_{dom F(t)} p`` are searched (:mod:`verimono.checks.jumps`), and
  one across which ``D(a, b)`` stays above tolerance (stalled) fails, with its time and size.
* ``assumption_LG`` — ``σ̂(t) = max |F^0(t,z)|/(1 + |z|)``; a stated ``problem.sigma`` below a sample is
  disproved — at the sampled points (far ones and ones near the kink included), over ``t``, and along rays
  ``x0 + s u`` and ``s u`` with ``s`` from ``10^-9 r`` to ``10^7 r``; without one, growth of the ratio by
  more than ``GROWTH_FLAG`` as ``λ`` (and with it ``z``'s distance to the boundary of the domain) shrinks
  1000-fold, or along the rays from ``10^4 r`` to ``10^7 r``, is evidence that (LG) fails.
* ``assumption_YB`` — ``D_λ(s) = |Y_λ(s+λ, z)| - |F^0(s, z)|`` (YB) and ``|Y_λ(s+λ, z)| - |Y_λ(s, z)|``
  (YB'); the estimate ``θ̂(t) = ρ t`` with ``ρ = max D/λ``; a stated ``problem.theta`` with
  ``θ(s+λ) - θ(s) < D`` is disproved; ``ρ(λ)`` growing like ``1/λ`` is evidence that (YB) fails (a moving
  domain: ``|Y_λ(s+λ, z)| ≈ dist(z, dom F(s+λ))/λ``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..core.errors import OutsideDomain, UnverifiedSolution
from ..core.operators import resolvent_rows
from ..core.tolerances import GROWTH_FLAG, current_data_scale, current_rtol, STALL_RATIO, STALL_WINDOW, quotient_tolerance, tolerance
from ..records.results import FAILED, PASSED, SKIPPED
from ..core.operator_protocol import accepts_times
from ..core.tolerances import row_tolerances
from .assumption_samples import (EVIDENCE, f0_norm, f0_norms, growth, min_norm_or_none, min_norms, norms,
                                 on_times, run_assumption, sampled)
from .core import Outcome, law
from .jumps import find_jumps, jump_time
from .engine.supremum import Sup
from .engine.times import search_time, searched_t, strata
from .engine.sphere import DRAWN_PER_DIM, sphere_maximise
from .engine.supremum import Space, budget, maximise

#: the rays of the (LG) search: ``s`` from ``RAY_RANGE[0]·r`` to ``RAY_RANGE[1]·r`` (r = 1 + |x0|)
RAY_RANGE = (1e-9, 1e7)
#: rays per centre (x0 and the kink 0) of the (LG) search's first phase (the directions of sample points);
#: the direction is then searched over the whole sphere
RAY_DIRECTIONS = 3
#: the (LG) growth evidence without a stated σ: the raw ratio from ``RAY_GROWTH[0]·r`` to ``RAY_GROWTH[1]·r``
RAY_GROWTH = (1e4, 1e7)
#: the (LG) direction search evaluates :func:`budget` ``("points")·(1 + n/RAY_SPHERE_DIM)`` directions of
#: ``S^{n-1}``: a sphere of more dimensions needs more draws before the ascent climbs
RAY_SPHERE_DIM = 10
#: the (LG) rays' time search has ``1/RAY_TIME_SHARE`` of the strata of the law's own (ci: 1024, ``T/680``): it
#: follows two families (the worst direction and its opposite), each evaluation a call of ``min_norm``
RAY_TIME_SHARE = 3
#: (A3): boundary points exposed in this many seeded directions (at most 2n) are families of the search over
#: time; the far point ``x0 + R d`` projected has ``R = EXPOSED_RADIUS·(1 + |x0|)``; the direction is searched
#: over the sphere at the ``EXPOSED_WINDOWS`` worst windows
EXPOSED = 8
EXPOSED_RADIUS = 100.0
EXPOSED_WINDOWS = 3
#: (A3): the widths of the windows ``[s, s + w]`` searched over ``s``, relative to T
A3_WINDOWS = (1 / 16, 1 / 256, 1 / 4096)


def _searched(S, sup: Sup, **more: Any) -> dict:
    """The record's ``details["searched"]``: the time search, the range of ``|p|``, and ``more``."""
    return {"t": searched_t(sup), "x_range": S.x_range(), **more}


@law("assumption_A3", "(A3)", subject="problem", driver=run_assumption, over=("t", "points", "direction"))
def check_assumption_A3(S) -> Outcome:
    """(A3): ``sup_{z ∈ dom F(s)} dist(z, dom F(t)) ≤ φ(t) - φ(s)``: the least nondecreasing ``φ̂`` of the
    sampled domain motion, compared with a stated ``φ``; a jump of the domain fails it (φ must be absolutely
    continuous)."""
    ts = S.times
    n = len(ts)
    D = np.zeros((n, n))
    arg: dict[tuple[int, int], Any] = {}
    off = np.zeros(len(S.near))         # how far each point lies from the domain: ties of the φ search
    for a in range(n):
        Z = _domain(S, S.near, float(ts[a]))
        off = np.maximum(off, np.linalg.norm(S.near - Z, axis=1))
        for b in range(a + 1, n):
            Q = _domain(S, Z, float(ts[b]))
            d = np.linalg.norm(Z - Q, axis=1)
            m = int(np.argmax(d))
            D[a, b], arg[(a, b)] = float(d[m]), Z[m]
    phi_hat = np.zeros(n)
    for b in range(1, n):
        phi_hat[b] = max(phi_hat[b - 1], max(phi_hat[a] + D[a, b] for a in range(b)))
    rate = max((D[a, b] / (ts[b] - ts[a]) for a in range(n) for b in range(a + 1, n)), default=0.0)
    details = {"evidence": EVIDENCE, "times": ts, "phi_hat": phi_hat, "max_rate": rate,
               "stated": S.problem.phi is not None}
    jump = _a3_jump(S, details)
    if jump is not None:
        return Outcome(jump["worst"], details=details, status=FAILED, counter={**jump, "message":
                       f"dom F jumps at t ≈ {jump['t']!r}: sup_z dist(z, dom F(b)) over z ∈ dom F(a) "
                                   f"stays {jump['excess']:.4g} on brackets [a, b] around it down to width "
                                   f"{jump['bracket'][1] - jump['bracket'][0]:.2g} — no absolutely continuous φ "
                                   f"bounds it ({EVIDENCE})"})
    if S.problem.phi is None:
        return Outcome(None, status=PASSED, details=details,
                       message=f"estimated least φ: φ̂(T) - φ̂(0) = {phi_hat[-1]:.4g}, max rate {rate:.4g} "
                                   f"({EVIDENCE})")
    phi = np.array([float(S.problem.phi(float(s))) for s in ts])
    worst, counter = 0.0, None
    for a in range(n):
        for b in range(a + 1, n):
            r = _phi_ratio(D[a, b], phi[a], phi[b])
            if r > worst:
                worst, counter = r, {"s": ts[a], "t": ts[b], "z": arg[(a, b)], "dist": D[a, b], "phi_s": phi[a],
                                     "phi_t": phi[b]}
    details["phi_stated"] = phi
    sup, c = _phi_sup(S, off)
    details["sup_search"] = sup.as_dict()
    details["searched"] = _searched(S, sup, boundary=sup.local[-1]["exposed_search"])
    if sup.value > worst:
        worst, counter = sup.value, c
    return sampled("assumption_A3", worst, counter, details,
                   lambda c: f"dist(z, dom F(t)) = {c['dist']:.4g} > φ(t) - φ(s) = {c['phi_t'] - c['phi_s']:.4g} "
                             f"for z in dom F(s), s = {c['s']!r}, t = {c['t']!r}"
                             + (" (found by the search over time)" if c.get("found_by") else "")
                             + ": the stated φ is contradicted",
                   f"stated φ bounds every sampled domain motion: at {n} sample times, and on windows of lengths "
                   + ", ".join(f"T/{round(1 / f)}" for f in A3_WINDOWS)
                   + f" searched over s ({sup.searched.points} windows, resolution {sup.searched.resolution:.3g}: "
                   f"{sup.searched.outside()}), and at the worst windows over the boundary points of dom F(s) "
                   f"exposed in every direction of {details['searched']['boundary']['sphere']} "
                   f"({details['searched']['boundary']['points']} directions); largest ratio {sup.value:.3g} at "
                   f"s = {sup.t:.4g} ({EVIDENCE})")


def _domain(S, P: np.ndarray, t: float) -> np.ndarray:
    """``proj_{dom F(t)} p`` of every row of ``P``: one call with the time on every row when the operator takes a
    time per row (each row as its own call gives it), else one call per row."""
    if accepts_times(S.op):
        return np.asarray(S.op.project_domain(P, np.full(len(P), float(t))), dtype=float)
    return np.array([S.op.project_domain(p, t) for p in P])


def _phi_ratio(dist: float, phi_s: float, phi_t: float) -> float:
    """``dist / (φ(t) − φ(s) + tol)``; at least 2 when ``φ`` decreases (not allowed by (A3))."""
    rhs, rtol = phi_t - phi_s, current_rtol()     # tolerance() of three floats, without its array dispatch
    big = max(abs(phi_s), abs(phi_t))
    r = dist / (max(rhs, 0.0) + rtol * (1.0 + max(abs(dist), big, current_data_scale())))
    if rhs < -rtol * (1.0 + big):
        r = max(r, 2.0)
    return float(r)


def _phi_ratios(dist: np.ndarray, phi_s: np.ndarray, phi_t: np.ndarray) -> np.ndarray:
    """:func:`_phi_ratio` of every element (the same operations, elementwise)."""
    rhs, rtol = phi_t - phi_s, current_rtol()
    big = np.maximum(np.abs(phi_s), np.abs(phi_t))
    r = dist / (np.maximum(rhs, 0.0) + rtol * (1.0 + np.maximum(np.maximum(np.abs(dist), big), current_data_scale())))
    return np.where(rhs < -rtol * (1.0 + big), np.maximum(r, 2.0), r)


def _phi_sup(S, off: np.ndarray) -> tuple[Sup, dict]:
    """The stated φ against the domain motion on every window ``[s, s + w]``, ``w ∈`` :data:`A3_WINDOWS`
    ``·T``, searched over ``s`` (:func:`verimono.checks.engine.times.search_time`; families: the window's
    width and the point — the sample points around ``x0`` and the boundary points exposed in
    :data:`EXPOSED` seeded directions), then over the boundary of ``dom F(s)`` at the worst windows: the
    point exposed in a direction ``d`` searched over the sphere (:func:`_exposed_search`).  The excess of
    one set over another is subadditive (``e(A, C) ≤ e(A, B) + e(B, C)``) and φ's increments add up: a φ that
    bounds the motion on every short window bounds it on every longer one, and a motion periodic with a
    divisor of one width is seen by the others."""
    op, T, phi = S.op, S.T, S.problem.phi
    widths = [T * f for f in A3_WINDOWS]
    x0, R = S.points[0], EXPOSED_RADIUS * S.scale
    rng = np.random.default_rng([int(S.seed) % (2 ** 63), S.problem.dim, 0xA3])
    dirs = rng.standard_normal((min(EXPOSED, 2 * S.problem.dim), S.problem.dim))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    P = np.vstack([S.near, x0 + R * dirs])
    nP, hi = len(P), T - min(widths)

    def at(p: np.ndarray, s: float, w: float) -> tuple[float, dict]:
        t = min(s + w, T)
        z = np.asarray(op.project_domain(p, s), dtype=float)
        q = np.asarray(op.project_domain(z, t), dtype=float)
        d = float(np.linalg.norm(z - q))
        ps, pt = float(phi(s)), float(phi(t))
        return _phi_ratio(d, ps, pt), {"s": s, "t": t, "z": z, "dist": d, "phi_s": ps, "phi_t": pt}

    def one(f: int, s: float) -> float:
        wi, pi = divmod(int(f), nP)
        return at(P[pi], s, widths[wi])[0] if s + widths[wi] <= T else -np.inf

    def values(s: float, which):
        return np.array([one(f, s) for f in (range(len(widths) * nP) if which is None else which)])

    # ties (a φ never approached at the design times) broken toward the points farthest from the domain,
    # whose projections move with it (the exposed boundary points first), the shortest windows first
    rank = np.concatenate([np.r_[off, np.full(len(dirs), 1e300)] + k for k in range(len(widths))])
    def many(ss: np.ndarray, which) -> np.ndarray:
        """:func:`one` at every time of ``ss``: each window's two projections of every time in one call (an
        operator that takes a time per row: each row as a separate call gives it), φ once per time, the ratio's
        operations elementwise."""
        out = np.full((len(ss), len(which)), -np.inf)
        phi_s = np.array([float(phi(s)) for s in ss.tolist()])
        for k, f in enumerate(which):
            wi, pi = divmod(int(f), nP)
            w = widths[wi]
            ok = ss + w <= T
            if not ok.any():
                continue
            s_ok = ss[ok]
            t_ok = np.minimum(s_ok + w, T)
            Z = np.asarray(op.project_domain(np.tile(P[pi], (len(s_ok), 1)), s_ok), dtype=float)
            Q = np.asarray(op.project_domain(Z, t_ok), dtype=float)
            pt = np.array([float(phi(t)) for t in t_ok.tolist()])
            out[ok, k] = _phi_ratios(norms(Z - Q), phi_s[ok], pt)
        return out

    if accepts_times(op):
        values.many = many      # type: ignore[attr-defined]
    else:   # the coverage: every time's ratio by :func:`one`, without the engine's bookkeeping per time
        values.many = lambda ss, which: np.array([[one(f, s) for f in which] for s in ss.tolist()])  # type: ignore
    values.many.own = True      # type: ignore[attr-defined]  # the law's own ratio: nothing to evaluate again
    sup = search_time(values, 0.0, hi, design=S.design(0.0, hi), seed=S.seed, rank=rank,
                      bounds=lambda f: (0.0, T - widths[int(f) // nP]))
    wi, pi = divmod(sup.family, nP)
    value, c = at(P[pi], sup.t, widths[wi])
    c = dict(c, found_by="search over time", window=widths[wi])
    windows = [sup.t] + [e["argmax"] for e in sup.local if e["argmax"] != sup.t]
    ex = _exposed_search(S, at, x0, R, windows[:EXPOSED_WINDOWS], widths[wi], start=[P[pi] - x0])
    counter = ex.pop("counter")
    if ex["value"] > max(value, sup.value):
        c = dict(counter, found_by="search over time", window=widths[wi],
                 exposed_by="the search over the boundary points of dom F(s) exposed in every direction")
        sup.value, sup.at = ex["value"], c["s"]
    sup.local.append({"exposed_search": ex})
    return sup, c


def _exposed_search(S, at, x0: np.ndarray, R: float, windows, w: float, start=()) -> dict:
    """At each window ``[s, s + w]`` of ``windows``, the domain's motion at the boundary point of
    ``dom F(s)`` exposed in ``d`` (the projection of ``x0 + R d``) searched over ``d ∈ S^{n-1}``
    (:func:`verimono.checks.engine.sphere.sphere_maximise`, :func:`verimono.checks.engine.supremum.budget`
    ``("points")`` evaluations per window at least ``12 n + 60``)."""
    n = S.problem.dim
    points = max(budget("points"), 12 * n + 60)
    best = {"value": -np.inf, "counter": None, "windows": [], "points": 0, "sphere": f"S^{n - 1}", "radius": R}
    for k, s in enumerate(windows):
        if s + w > S.T:
            continue
        r = sphere_maximise(lambda d, _s=float(s): at(x0 + R * d, _s, w)[0], n, points=points,
                            seed=S.seed + 7919 * k, start=[u for u in start if np.linalg.norm(u) > 0])
        best["windows"].append(float(s))
        best["points"] += r["points"]
        best["resolution"] = r["resolution"]
        if r["value"] > best["value"]:
            best["value"] = r["value"]
            best["counter"] = dict(at(x0 + R * r["direction"], float(s), w)[1], direction=r["direction"])
    return best


def _excess(S, a: float, b: float) -> tuple[float, np.ndarray, float]:
    """``max_z dist(z, dom F(b))`` over the sampled ``z = proj_{dom F(a)} p``, the maximiser, and the
    tolerance of its projections (of ``p``'s size: a far point's projection carries its rounding)."""
    Z = _domain(S, S.near, a)
    Q = _domain(S, Z, b)
    d = np.linalg.norm(Z - Q, axis=1)
    m = int(np.argmax(d))
    return float(d[m]), Z[m], tolerance(S.near[m], Z[m], d[m])


def _a3_jump(S, details: dict) -> dict | None:
    """A jump of ``φ̂``: :func:`verimono.checks.jumps.find_jumps` on the projections ``t ↦ proj_{dom F(t)} p``
    (continuous when ``dom F`` moves continuously in the Hausdorff distance), then the excess of
    ``dom F(a)`` over ``dom F(b)`` on the final bracket: still above tolerance and stalled (≥ ``STALL_RATIO``
    times its value ``STALL_WINDOW`` bisections earlier) means ``φ(b) − φ(a) ≥ excess`` on ever shorter
    ``[a, b]``: no absolutely continuous φ (a domain that only grows jumps without violating (A3))."""
    grid = None
    if accepts_times(S.op):     # every grid time in one call, the rows time-major: what _domain gives per time
        m = len(S.near)
        P = np.asarray(S.near, dtype=float)
        def grid(times: np.ndarray) -> np.ndarray:
            return np.asarray(S.op.project_domain(np.tile(P, (len(times), 1)), np.repeat(times, m)), dtype=float)
    jumps, searched = find_jumps(lambda t: _domain(S, S.near, t), S.T, values=grid)
    details["jump_search"] = searched
    details["domain_jumps"] = []
    for j in jumps:
        e, z, tol = _excess(S, j.a, j.b)
        a0, b0 = j.brackets[max(len(j.brackets) - 1 - STALL_WINDOW, 0)]
        e0, _, _ = _excess(S, a0, b0)
        details["domain_jumps"].append({"t": j.time, "bracket": [j.a, j.b], "projection_jump": j.size, "excess": e})
        if e > tol and e >= STALL_RATIO * e0:
            tj = jump_time(j)
            return {"t": j.time if tj is None else tj, "bracket": [j.a, j.b], "excess": e, "excess_earlier": e0,
                    "earlier_bracket": [a0, b0], "z": z, "worst": e / tol, "projection_increments": j.increments}
    return None


# -- (LG) ---------------------------------------------------------------------------------------------

@law("assumption_LG", "(LG)", subject="problem", driver=run_assumption, over=("t", "points", "direction"))
def check_assumption_LG(S) -> Outcome:
    """(LG): ``|F^0(t, z)| ≤ σ(t)(1 + |z|)``: the estimated ``σ̂`` against a stated ``σ`` — at the sampled
    points, over ``t`` and along rays far from ``x0`` and near the kink ``0`` — or, without one, growth of
    the sampled ratio as ``z`` nears the boundary of the domain or goes far (evidence that (LG) fails)."""
    op, sigma = S.op, S.problem.sigma
    by_lam = {}
    worst, counter, how = 0.0, None, "min_norm"
    sig_hat = np.zeros(len(S.times))
    for lam in S.lambdas:
        best = 0.0
        for ti, t in enumerate(S.times):
            z_all, _, _ = S.graph(float(t), lam)
            if accepts_times(op) and len(z_all):     # every row's |F^0| in one call, each as its own call gives it
                vals, how = f0_norms(op, z_all, np.full(len(z_all), float(t)), 1e-6 * S.T, how=True)
                f0s = [None if v != v else v for v in vals.tolist()]
            else:
                f0s = None
            for k, z in enumerate(z_all):
                if f0s is None:
                    val, how = f0_norm(op, z, float(t), 1e-6 * S.T)
                else:
                    val = f0s[k]
                if val is None:
                    continue
                r = val / (1.0 + float(np.linalg.norm(z)))
                best = max(best, r)
                sig_hat[ti] = max(sig_hat[ti], r)
                if sigma is not None:
                    rhs = float(sigma(float(t))) * (1.0 + float(np.linalg.norm(z)))
                    q = val / (rhs + tolerance(rhs, val))
                    if q > worst:
                        worst, counter = q, {"t": t, "z": z, "F0_norm": val, "sigma_t": float(sigma(float(t)))}
        by_lam[lam] = best
    lams = sorted(by_lam, reverse=True)
    grow = by_lam[lams[-1]] / max(by_lam[lams[0]], 1e-12) if by_lam[lams[-1]] > 1e-9 else 1.0
    details = {"evidence": EVIDENCE, "times": S.times, "sigma_hat": sig_hat, "sup_ratio_by_lambda": by_lam,
               "growth": grow, "F0": how, "stated": sigma is not None}
    t_ray = 0.0
    if sigma is not None:
        sup, c = _sigma_sup(S)
        details["sup_search"] = sup.as_dict()
        if sup.value > worst:
            worst, counter = sup.value, c
        t_ray = sup.t
    ray, c_ray, far_growth, ray_searched = _rays(S, t_ray)
    details["ray_search"] = ray.as_dict()
    details["far_growth"] = far_growth
    details["searched"] = {"t": searched_t(sup) if sigma is not None else None,
                           "x_range": S.x_range(), "rays": ray_searched,
                           "direction": ray_searched["direction"], "decades": ray_searched["decades"]}
    if sigma is not None:
        if ray.value > worst:
            worst, counter = ray.value, c_ray
        return sampled("assumption_LG", worst, counter, details,
                       lambda c: f"|F^0(t,z)| = {c['F0_norm']:.4g} > σ(t)(1 + |z|) = "
                                 f"{c['sigma_t'] * (1 + np.linalg.norm(c['z'])):.4g} at t = {c['t']!r}, |z| = "
                                 f"{np.linalg.norm(c['z']):.4g}"
                                 + (f" (found by the {c['found_by']})" if c.get("found_by") else "")
                                 + ": the stated σ is contradicted",
                       f"stated σ bounds every sample, at {len(S.times)} sample times, searched over time "
                       f"({sup.searched.points} times, resolution {sup.searched.resolution:.3g}: "
                       f"{sup.searched.outside()}; largest ratio {sup.value:.3g} at t = {sup.t:.4g}) and along "
                       f"rays from x0 and 0 ({_describe_rays(ray_searched)}; largest ratio {ray.value:.3g}); |p| in "
                       f"[{S.x_range()[0]:.3g}, {S.x_range()[1]:.3g}] ({EVIDENCE})")
    if far_growth > GROWTH_FLAG:
        return Outcome(far_growth, bound=GROWTH_FLAG, details=details, counter={
            "far_growth": far_growth, "message": f"|F^0(t,z)|/(1+|z|) grows {far_growth:.3g}-fold along a ray from "
                                                 f"|z| = 1e4 r to 1e7 r: faster than linear growth, evidence that "
                                                 f"(LG) fails ({_describe_rays(ray_searched)})"})
    return growth(grow, {"sup_ratio_by_lambda": by_lam}, details,
                  f"sup |F^0(t,z)|/(1+|z|) grows {grow:.3g}-fold as z approaches the boundary of dom F: evidence "
                  "that (LG) fails",
                  f"estimated σ̂ ≤ {float(np.max(sig_hat)):.4g} ({EVIDENCE}; F^0 by {how}; rays up to |x| = "
                  f"{RAY_RANGE[1]:.0e} r grow {far_growth:.3g}-fold; {_describe_rays(ray_searched)})")


def _sigma_ratio(S, z: np.ndarray, t: float) -> tuple[float, dict | None]:
    val, _ = f0_norm(S.op, z, t, 1e-6 * S.T)
    if val is None:
        return -np.inf, None
    sig = float(S.problem.sigma(t))
    rhs = sig * (1.0 + math.sqrt(float(z @ z)))
    tol = current_rtol() * (1.0 + max(abs(rhs), abs(val), current_data_scale()))    # tolerance(rhs, val), without its array dispatch
    return val / (rhs + tol), {"t": t, "z": z, "F0_norm": val, "sigma_t": sig}


def _sigma_ratios(S, Z: np.ndarray, ts: np.ndarray) -> np.ndarray:
    """:func:`_sigma_ratio` of every row ``z_i`` at ``t_i`` (the same operations elementwise; σ once per time)."""
    val = f0_norms(S.op, Z, ts, 1e-6 * S.T)
    sig = np.array([float(S.problem.sigma(t)) for t in ts.tolist()])
    rhs = sig * (1.0 + norms(Z))
    tol = current_rtol() * (1.0 + np.maximum(np.maximum(np.abs(rhs), np.abs(val)), current_data_scale()))
    with np.errstate(invalid="ignore"):
        r = val / (rhs + tol)
    return np.where(np.isnan(val), -np.inf, r)


def _sigma_sup(S) -> tuple[Sup, dict]:
    """The stated σ against ``|F^0(t, z)|/(1 + |z|)`` searched over ``t`` (families: the sampled ``z =
    J_λ(t) p``, one per point ``p`` around ``x0`` and step ``λ``)."""
    op, P, lams = S.op, S.near, S.lambdas        # far from x0 and near the kink: the rays' job

    def values(t: float, which):
        if which is None:
            return np.array([_sigma_ratio(S, z, t)[0] for lam in lams for z in resolvent_rows(op, P, lam, t)])
        out = []
        for f in which:
            li, pi = divmod(int(f), len(P))
            out.append(_sigma_ratio(S, resolvent_rows(op, P[pi:pi + 1], lams[li], t)[0], t)[0])
        return np.array(out)

    def many(ts: np.ndarray, which) -> np.ndarray:
        """``values(t, which)`` at every time of ``ts``: each family's resolvents at every time in one call (an
        operator that takes a time per row), then :func:`_sigma_ratios`."""
        out = np.empty((len(ts), len(which)))
        for k, f in enumerate(which):
            li, pi = divmod(int(f), len(P))
            out[:, k] = _sigma_ratios(S, on_times(op, P[pi:pi + 1], lams[li], ts)[:, 0], ts)
        return out

    if accepts_times(op):
        values.many = many      # type: ignore[attr-defined]
    else:   # the coverage: every time's ratio as ``values`` computes it, without the engine's bookkeeping per time
        values.many = lambda ts, which: np.array([values(t, which) for t in ts.tolist()])   # type: ignore
    values.many.own = True      # type: ignore[attr-defined]
    sup = search_time(values, 0.0, S.T, design=S.design(), seed=S.seed)
    li, pi = divmod(sup.family, len(P))
    z = S.rows(P[pi:pi + 1], lams[li], sup.t)[0]
    _, c = _sigma_ratio(S, z, sup.t) if np.all(np.isfinite(z)) else (None, None)
    return sup, dict(c or {"t": sup.t, "z": P[pi], "F0_norm": np.nan, "sigma_t": np.nan}, lam=lams[li],
                     found_by="search over time")


def _rays(S, t: float):
    """The (LG) search over the coordinates of its statement away from the sampled points (module docstring):
    ``z = J_λ(t)(c + s u)`` with the smallest ``λ``, centre ``c ∈ {x0, 0}``, direction ``u ∈ S^{n-1}``,
    distance ``s ∈ RAY_RANGE·r`` (a decade coordinate) and time ``t``, in four phases through the engine —

    1. **decades**: ``s`` searched (:func:`~verimono.checks.engine.supremum.maximise`, ``coordinate`` kind) along
       :data:`RAY_DIRECTIONS` directions of the sample points from each centre, at ``t``;
    2. **direction**: at the worst centre and distance, ``u`` searched over the whole sphere
       (:func:`~verimono.checks.engine.sphere.sphere_maximise`: drawn, ascended, refined at the worst; at least
       :func:`budget` ``("points")·(1 + n/``:data:`RAY_SPHERE_DIM` ``)`` evaluations);
    3. **time**: ``t ∈ [0, T]`` by count (:data:`RAY_TIME_SHARE`) along the worst direction and its opposite at
       the worst centre and distance, the sphere searched again at a better ``t``;
    4. **decades again**: ``s`` searched along the worst direction from both centres at the worst time.

    The objective is the ratio against the stated σ, or without one the growth ``ρ(10^7 r)/ρ(10^4 r)`` of the
    raw ratio ``ρ = |F^0(t,z)|/(1+|z|)`` along the ray.  Returns ``(sup, counter, far_growth, searched)``:
    ``sup`` the largest ratio (phases 1–4), ``far_growth`` the largest growth met, ``searched`` what each
    coordinate reached (directions drawn and refined and the finest angle, the decades and their factor, the
    times)."""
    op, lam, r, T = S.op, S.lambdas[-1], S.scale, S.T
    n = S.problem.dim
    x0 = S.points[0]
    dirs = S.points[1:1 + RAY_DIRECTIONS] - x0
    dirs = dirs / np.maximum(np.linalg.norm(dirs, axis=1, keepdims=True), 1e-300)
    centres = (x0, np.zeros_like(x0))
    sigma = S.problem.sigma

    def raw(z: np.ndarray, tt: float) -> float:
        val, _ = f0_norm(op, z, tt, 1e-6 * T)
        return -np.inf if val is None else val / (1.0 + float(np.linalg.norm(z)))

    def point(c: np.ndarray, u: np.ndarray, s: float, tt: float) -> np.ndarray | None:
        try:
            z = resolvent_rows(op, (c + s * u)[None, :], lam, tt)[0]
        except UnverifiedSolution:      # verimono's own solver: no evidence at this point
            return None
        return z if np.all(np.isfinite(z)) else None

    def value(c: np.ndarray, u: np.ndarray, s: float, tt: float) -> float:
        z = point(c, u, s, tt)
        if z is None:
            return -np.inf
        return raw(z, tt) if sigma is None else _sigma_ratio(S, z, tt)[0]

    def grow(c: np.ndarray, u: np.ndarray, tt: float) -> float:
        za, zb = point(c, u, RAY_GROWTH[0] * r, tt), point(c, u, RAY_GROWTH[1] * r, tt)
        if za is None or zb is None:
            return -np.inf
        a, b = raw(za, tt), raw(zb, tt)
        return b / a if a > 1e-9 and np.isfinite(b) else 1.0

    space = Space("|x − c|", RAY_RANGE[0] * r, RAY_RANGE[1] * r, log=True)
    decades = [10.0 ** k * r for k in range(round(math.log10(RAY_RANGE[0])), round(math.log10(RAY_RANGE[1])) + 1)]

    def along(rays, tt: float) -> Sup:
        def values(s: float, which):
            return np.array([value(c, u, s, tt) for c, u in (rays if which is None else [rays[f] for f in which])])
        return maximise(values, space, design=decades, families=2, kind="coordinate", seed=S.seed)

    # 1. decades along the sample directions from both centres
    rays = [(c, u) for c in centres for u in dirs]
    first = along(rays, t)
    ci, u0 = first.family // len(dirs), dirs[first.family % len(dirs)]
    far = max([1.0] + [g for c, u in rays if np.isfinite(g := grow(c, u, t))])
    # 2. the direction over the whole sphere, at the worst centre and distance (without σ: the far growth)
    c_best, s_best = centres[ci], first.at
    per_sphere = round(budget("points") * (1 + n / RAY_SPHERE_DIM))

    def on_sphere(tt: float, start: np.ndarray) -> dict:
        goal = (lambda u: grow(c_best, u, tt)) if sigma is None else (lambda u: value(c_best, u, s_best, tt))
        return sphere_maximise(goal, n, points=per_sphere, seed=S.seed + 0x4C47, start=[start])

    sph = on_sphere(t, u0)
    u_best, t_best, best = sph["direction"], t, sph["value"]
    spheres = [sph]
    # 3. time by count (the engine's time design, both ends) along the worst direction and its opposite (a
    #    direction the ratio does not read at t may be the wrong half of the sphere at another time); at a
    #    better time the direction is searched again from there
    rays_t = [(c_best, u_best), (c_best, -u_best)]

    def t_values(tt: float, which):
        fams = range(len(rays_t)) if which is None else which
        if sigma is None:
            return np.array([grow(*rays_t[f], tt) for f in fams])
        return np.array([value(*rays_t[f], s_best, tt) for f in fams])

    def t_many(ts: np.ndarray, which) -> np.ndarray:
        """``t_values(t, which)`` at every time of ``ts``: at each time the points of every family's ray (two
        of each without σ) in one :func:`resolvent_rows` call (the catalog's map rows as separate calls do;
        one that verimono's own solver cannot verify: the points one by one, as :func:`point` takes them),
        then the ratios as :func:`raw`, :func:`grow` and :func:`value` compute them."""
        fams = list(which)
        dists = [RAY_GROWTH[0] * r, RAY_GROWTH[1] * r] if sigma is None else [s_best]
        rays_s = [(rays_t[f][0], rays_t[f][1], d) for f in fams for d in dists]
        X = np.array([c + d * u for c, u, d in rays_s])
        out = np.empty((len(ts), len(fams)))
        if accepts_times(op):       # every time in one call of each member, each row as a separate call gives it
            Z = on_times(op, X, lam, ts)                              # (times, rays, n)
            tt = np.repeat(ts, len(rays_s))
            Zf = Z.reshape(-1, Z.shape[2])
            ok = np.isfinite(Zf).all(axis=1)
            if sigma is not None:
                q = np.full(len(Zf), -np.inf)
                q[ok] = _sigma_ratios(S, Zf[ok], tt[ok])
                return q.reshape(len(ts), len(rays_s))
            val = np.full(len(Zf), np.nan)
            val[ok] = f0_norms(op, Zf[ok], tt[ok], 1e-6 * T)
            with np.errstate(invalid="ignore"):
                rho = np.where(np.isnan(val), -np.inf, val / (1.0 + norms(Zf)))    # raw(z, t)
            a, b = rho.reshape(len(ts), len(fams), 2)[..., 0], rho.reshape(len(ts), len(fams), 2)[..., 1]
            pair = ok.reshape(len(ts), len(fams), 2).all(axis=2)
            with np.errstate(invalid="ignore", divide="ignore"):
                g = np.where((a > 1e-9) & np.isfinite(b), b / a, 1.0)
            return np.where(pair, g, -np.inf)
        for k, tt in enumerate(ts.tolist()):
            try:
                Z = resolvent_rows(op, X, lam, tt)
                zs = [z if np.all(np.isfinite(z)) else None for z in Z]
            except UnverifiedSolution:
                zs = [point(c, u, d, tt) for c, u, d in rays_s]
            for j in range(len(fams)):
                if sigma is not None:
                    z = zs[j]
                    out[k, j] = -np.inf if z is None else _sigma_ratio(S, z, tt)[0]
                    continue
                za, zb = zs[2 * j], zs[2 * j + 1]
                if za is None or zb is None:
                    out[k, j] = -np.inf
                    continue
                a, b = raw(za, tt), raw(zb, tt)
                out[k, j] = b / a if a > 1e-9 and np.isfinite(b) else 1.0
        return out

    t_values.many = t_many      # type: ignore[attr-defined]
    if sigma is None:           # a growth ratio: its bound GROWTH_FLAG
        t_many.bound = GROWTH_FLAG      # type: ignore[attr-defined]
    count = max(1, strata() // RAY_TIME_SHARE)
    over_t = search_time(t_values, 0.0, T, design=np.r_[S.times, t], seed=S.seed, families=2, count=count)
    if over_t.value > best:
        t_best = over_t.t
        u_best, best = rays_t[over_t.family][1], over_t.value
        again = on_sphere(t_best, u_best)
        spheres.append(again)
        if again["value"] > best:
            u_best, best = again["direction"], again["value"]
    if sigma is None:
        far = max(far, best)
    # 4. decades again along the worst direction from both centres, at the worst time
    last = along([(c, u_best) for c in centres], t_best)
    sup = max((first, last), key=lambda s: s.value)
    if sigma is not None and best > sup.value:     # the sphere's or the time's own best
        sup.value, sup.at = best, s_best
        where = (c_best, u_best, s_best, t_best)
    elif sup is first:
        where = (rays[first.family][0], rays[first.family][1], first.at, t)
    else:
        where = (centres[last.family], u_best, last.at, t_best)
    c = None
    if sigma is not None:
        cc, uu, ss, tt = where
        z = point(cc, uu, ss, tt)
        _, c = _sigma_ratio(S, z, tt) if z is not None else (None, None)
        c = dict(c or {"t": tt, "z": cc + ss * uu, "F0_norm": np.nan, "sigma_t": np.nan},
                 found_by="search along rays (centre, direction, |x| decade, t)",
                 centre="x0" if cc is x0 else "0", direction=uu, distance=ss)
    turns = sum(h["points"] for h in spheres)
    points = sum(s.searched.points for s in (first, last)) + turns + over_t.searched.points
    searched = {"space": space.name, "range": [space.lo, space.hi], "log": True, "points": points,
                "resolution": max(first.searched.resolution, last.searched.resolution),
                "direction": {"sphere": sph["sphere"], "drawn": len(spheres) * (DRAWN_PER_DIM * n if n > 1 else 2),
                              "points": turns, "searches": len(spheres), "unit": "rad",
                              "resolution": max(h["resolution"] for h in spheres)},
                "decades": {"range": [math.log10(RAY_RANGE[0]), math.log10(RAY_RANGE[1])], "relative_to": r,
                            "points": first.searched.points + last.searched.points,
                            "resolution": max(first.searched.resolution, last.searched.resolution)},
                "t": searched_t(over_t, count), "centres": ["x0", "0"],
                "objective": "ratio against the stated σ" if sigma is not None else
                             f"growth of |F^0|/(1+|z|) from {RAY_GROWTH[0]:.0e} r to {RAY_GROWTH[1]:.0e} r"}
    return sup, c, far, searched


def _describe_rays(sr: dict) -> str:
    d, k = sr["direction"], sr["decades"]
    return (f"{sr['points']} ray points: directions over {d['sphere']} ({d['points']}, {d['drawn']} drawn, refined "
            f"to {d['resolution']:.2g} rad), |x − c| over 10^{k['range'][0]:.0f}..10^{k['range'][1]:.0f} r "
            f"({k['points']} points, to within a factor {k['resolution']:.3g}), t at {sr['t']['points']} points")


# -- (YB) ---------------------------------------------------------------------------------------------

def _theta_sup(S, key: str) -> tuple[Sup, dict]:
    """The stated θ against the Yosida increment of ``key`` ((YB) or (YB')) searched over ``s ∈ [0, T − λ]``
    (families: one per step ``λ`` and point ``p``, ``z = J_{T/10}(s) p ∈ dom F(s)``)."""
    op, P, theta, T = S.op, S.points, S.problem.theta, S.T
    lams = S.lambdas[1:]
    nP = len(P)

    def increments(s: float, lam: float, z: np.ndarray, f0: float | None) -> tuple[float, dict]:
        y_next = float(np.linalg.norm(op.yosida(z, lam, s + lam)))
        d = y_next - f0 if key == "YB" else y_next - float(np.linalg.norm(op.yosida(z, lam, s)))
        rhs = float(theta(s + lam)) - float(theta(s))
        q = d / (max(rhs, 0.0) + quotient_tolerance(lam, z)) if d > 0 else 0.0
        return q, {"form": key, "s": s, "lambda": lam, "z": z, "lhs": d, "rhs": rhs}

    def f0_of(z: np.ndarray, s: float) -> float | None:
        if key != "YB":
            return None
        v = min_norm_or_none(op, z, s)
        return None if v is None else float(np.linalg.norm(v))

    def one(f: int, s: float) -> tuple[float, dict | None]:
        li, pi = divmod(int(f), nP)
        lam = lams[li]
        if s + lam > T + 1e-12:
            return -np.inf, None
        z = resolvent_rows(op, P[pi:pi + 1], 0.1 * T, s)[0]
        f0 = f0_of(z, s)
        if key == "YB" and f0 is None:
            return -np.inf, None
        return increments(s, lam, z, f0)

    def values(s: float, which):
        if which is not None:
            return np.array([one(f, s)[0] for f in which])
        Z = resolvent_rows(op, P, 0.1 * T, s)
        F0 = [f0_of(z, s) for z in Z]
        out = []
        for lam in lams:
            for z, f0 in zip(Z, F0):
                ok = s + lam <= T + 1e-12 and not (key == "YB" and f0 is None)
                out.append(increments(s, lam, z, f0)[0] if ok else -np.inf)
        return np.array(out)

    def many(ss: np.ndarray, which) -> np.ndarray:
        """:func:`one` at every time of ``ss``: each member's rows at every time in one call (an operator that
        takes a time per row: each row as a separate call gives it), θ once per time, the increments' operations
        elementwise."""
        out = np.full((len(ss), len(which)), -np.inf)
        for k, f in enumerate(which):
            li, pi = divmod(int(f), nP)
            lam = lams[li]
            ok = ss + lam <= T + 1e-12
            if not ok.any():
                continue
            s_ok = ss[ok]
            Z = on_times(op, P[pi:pi + 1], 0.1 * T, s_ok)[:, 0]
            y_next = norms(np.asarray(op.yosida(Z, lam, s_ok + lam), dtype=float))
            if key == "YB":
                f0 = f0_norms_or_nan(Z, s_ok)
                d = y_next - f0
            else:
                d = y_next - norms(np.asarray(op.yosida(Z, lam, s_ok), dtype=float))
            th = np.array([float(theta(s + lam)) - float(theta(s)) for s in s_ok.tolist()])
            with np.errstate(invalid="ignore"):
                q = np.where(d > 0, d / (np.maximum(th, 0.0) + row_tolerances(Z) / float(lam)), 0.0)
            if key == "YB":
                q = np.where(np.isnan(f0), -np.inf, q)
            out[ok, k] = q
        return out

    def f0_norms_or_nan(Z: np.ndarray, ss: np.ndarray) -> np.ndarray:
        """``|F^0(s_i, z_i)|`` of every row, NaN where :func:`f0_of` is ``None``."""
        try:
            return norms(np.asarray(op.min_norm(Z, ss), dtype=float))
        except (OutsideDomain, UnverifiedSolution):
            vals = [f0_of(z, s) for z, s in zip(Z, ss.tolist())]
            return np.array([np.nan if v is None else v for v in vals], dtype=float)

    hi = T - min(lams)
    if accepts_times(op):
        values.many = many      # type: ignore[attr-defined]
    else:   # the coverage: every time's ratio by :func:`one`, without the engine's bookkeeping per time
        values.many = lambda ss, which: np.array([[one(f, s)[0] for f in which] for s in ss.tolist()])  # type: ignore
    values.many.own = True      # type: ignore[attr-defined]
    sup = search_time(values, 0.0, hi, design=S.design(0.0, hi), seed=S.seed,
                      bounds=lambda f: (0.0, T - lams[f // nP]))
    _, c = one(sup.family, sup.t)
    return sup, dict(c or {"form": key, "s": sup.t, "lambda": lams[sup.family // nP], "z": P[sup.family % nP],
                           "lhs": np.nan, "rhs": np.nan}, found_by="search over time")


@law("assumption_YB", "(YB)/(YB')", subject="problem", driver=run_assumption, over=("t", "points", "lam"))
def check_assumption_YB(S) -> Outcome:
    """(YB)/(YB'): the Yosida increment ``|Y_λ(s+λ, z)| - |F^0(s, z)| ≤ θ(s+λ) - θ(s)`` against a stated
    ``θ``, or, without one, growth of the increment per unit time like ``1/λ`` (evidence that (YB) fails)."""
    op, theta, T = S.op, S.problem.theta, S.T
    rates: dict[float, dict[str, float]] = {}
    worst = {"YB": 0.0, "YB'": 0.0}                          # a stated θ, judged per form
    counter: dict[str, dict | None] = {"YB": None, "YB'": None}
    has_f0 = True
    for lam in S.lambdas[1:]:
        rates[lam] = {"YB": 0.0, "YB'": 0.0}
        for s in S.times:
            s = float(s)
            if s + lam > T + 1e-12:
                continue
            Z = S.rows(S.points, 0.1 * T, s)  # z ∈ dom F(s)
            Zf = Z[np.all(np.isfinite(Z), axis=1)]
            pre = None
            if accepts_times(op) and len(Zf):   # each member once for every row, each as its own call gives it
                y1 = norms(np.asarray(op.yosida(Zf, lam, np.full(len(Zf), s + lam)), dtype=float)).tolist()
                y0 = norms(np.asarray(op.yosida(Zf, lam, np.full(len(Zf), s)), dtype=float)).tolist()
                f0s = None
                if has_f0:
                    try:
                        f0s = min_norms(op, Zf, s)
                    except NotImplementedError:
                        has_f0 = False
                pre = (y1, y0, f0s)
            for k, z in enumerate(Zf):
                if pre is None:
                    try:
                        y_next = float(np.linalg.norm(op.yosida(z, lam, s + lam)))
                        y_now = float(np.linalg.norm(op.yosida(z, lam, s)))
                    except UnverifiedSolution:      # verimono's own solver: no evidence at this point
                        S.unverified += 1
                        continue
                else:
                    y_next, y_now = pre[0][k], pre[1][k]
                tol = quotient_tolerance(lam, z)
                cands = {"YB'": y_next - y_now}
                if has_f0:
                    try:
                        f0 = min_norm_or_none(op, z, s) if pre is None else pre[2][k]
                        if f0 is not None:
                            cands["YB"] = y_next - float(np.linalg.norm(f0))
                    except NotImplementedError:
                        has_f0 = False
                for key, d in cands.items():   # the rate beyond the rounding of |Y_λ| (far points' is large)
                    rates[lam][key] = max(rates[lam][key], max(d - tol, 0.0) / lam)
                    if theta is not None:
                        rhs = float(theta(s + lam)) - float(theta(s))
                        q = d / (max(rhs, 0.0) + tol) if d > 0 else 0.0
                        if q > worst[key]:
                            worst[key] = q
                            counter[key] = {"form": key, "s": s, "lambda": lam, "z": z, "lhs": d, "rhs": rhs}
    lams = sorted(rates, reverse=True)
    key = "YB" if has_f0 else "YB'"
    small, big = rates[lams[-1]][key], rates[lams[0]][key]
    grow = small / max(big, 1e-12) if small > 1e-9 else 1.0
    rho = max(r[key] for r in rates.values())
    details = {"evidence": EVIDENCE, "rate_by_lambda": rates, "theta_hat_slope": rho, "growth": grow,
               "form": key, "stated": theta is not None,
               "searched": {"x_range": S.x_range(), "lambda": [min(lams), max(lams)]}}
    if theta is not None:
        sup, c = _theta_sup(S, key)
        details["sup_search"] = sup.as_dict()
        details["searched"]["t"] = searched_t(sup)
        if sup.value > worst[key]:
            worst[key], counter[key] = sup.value, c
        # (YB) is the assumption; (YB') is stronger (|Y_λ(s, z)| ≤ |F^0(s, z)|) and only implies it.  With
        # F^0 the stated θ is judged on (YB) itself; without it a sampled (YB') holds is evidence for (YB),
        # while a (YB') violation says nothing about (YB): no verdict then
        if key == "YB'" and worst[key] > 1.0:
            c = counter[key]
            return Outcome(None, status=SKIPPED, details=details,
                           message=f"the stated θ does not bound the (YB') increments (by {c['lhs'] - c['rhs']:.3g} "
                                   f"at s = {c['s']:.4g}, λ = {c['lambda']:.3g}), but (YB') is stronger than (YB), "
                                   "which needs |F^0(s, z)|: the operator has no min_norm")
        return sampled("assumption_YB", worst[key], counter[key], details,
                       lambda c: f"{c['form']}: |Y_λ(s+λ,z)| exceeds θ(s+λ) - θ(s) + ... by "
                                 f"{c['lhs'] - c['rhs']:.3g} at s = {c['s']!r}, λ = {c['lambda']:.3g}"
                                 + (" (found by the search over time)" if c.get("found_by") else "")
                                 + ": the stated θ is contradicted",
                       f"stated θ bounds every sampled Yosida increment, at {len(S.times)} sample times and "
                       f"searched over s ({sup.searched.points} times, resolution {sup.searched.resolution:.3g}: "
                       f"{sup.searched.outside()}; largest ratio {sup.value:.3g} at s = {sup.t:.4g}) ({key}; "
                       f"λ ∈ [{min(lams):.3g}, {max(lams):.3g}]; {EVIDENCE})")
    return growth(grow, {"rate_by_lambda": rates}, details,
                  f"the Yosida increment per unit time grows {grow:.3g}-fold as λ shrinks 1000-fold (like 1/λ: a "
                  f"moving domain): evidence that ({key}) fails",
                  f"estimated θ̂(t) = {rho:.4g} t ({key}; {EVIDENCE})")


__all__ = ["check_assumption_A3", "check_assumption_LG", "check_assumption_YB", "RAY_RANGE", "RAY_DIRECTIONS",
           "RAY_GROWTH", "RAY_SPHERE_DIM", "RAY_TIME_SHARE"]
