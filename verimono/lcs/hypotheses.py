"""Evidence for the hypotheses of Theorems ``thm: linear case`` and ``e: linear case-comp`` (Section 7).

:func:`check_hypotheses` returns :class:`verimono.CheckResult` records, one per hypothesis, each labelled
as **evidence, not proof** where it rests on samples (times ``t``, points ``x``) rather than on an exact
argument:

* ``lcs.passivity`` (item i): ``Σ(A,B,C,D)`` passive with storage ``½|x|²`` — the eigenvalue test of the KYP
  matrix ``Q(I)``; ``lcs.pass_D_psd`` and ``lcs.pass_kernel`` — Proposition ``p:pass`` i, ii with ``K = I``;
* ``lcs.relation_maxmon`` (item ii): exact for Complementarity/Relay (normal cones of boxes), sampled
  firm nonexpansiveness of the resolvent for an operator relation;
* ``lcs.rel_int`` (item iii / ``e: linear case-comp`` ii): ``im C ∩ ri(im(𝓜 + D) − v(t)) ≠ ∅`` on sampled
  ``t`` by linear programming.  For a box relation with ``D + Dᵀ ⪰ 0``, ``im(𝓜 + D) = {η : ∃ z ∈ [0, u−l],
  s ≥ 0 : Dz + Es + Dl + η ≥ 0}`` (Proposition ``p:lcp2``: solvable ⟺ feasible), the linear image of a polyhedron
  ``P`` in ``(η, z, s)`` whose only implicit equalities are the rows of degenerate bounds ``u_i = l_i``;
  since ``ri L(P) = L(ri P)`` (Rockafellar Thm 6.6) the condition is ``max τ > 0`` over
  ``{Cx + v(t) = η, every other row of P with slack ≥ τ}``;
* ``lcs.v_bounded`` (item iv): sup of ``|v|`` on a sample grid; ``lcs.v_ac`` (``e: linear case-comp`` iii,
  ``v ∈ AC``): no jump — the largest increments of ``v`` must vanish when bisected (:func:`_v_ac_record`) —
  and a settled total variation; a jump fails with its location;
* ``lcs.least_norm_growth`` (item vi, from Proposition ``p:lcp2`` iv–v for PSD ``D``): the least-norm
  multiplier ``z*`` of sampled unit ``q ∈ Q_D^+`` is homogeneous (``z*(sq) = s z*(q)``) and least-norm;
  ``|z*(q)| ≤ α|q|`` is checked against the explicit ``α = 1/λ_min((D + Dᵀ)/2)`` when that is positive
  (:func:`verimono.lcs.lcp.lcp_alpha`), and otherwise ``α`` is only estimated from below by the samples
  (said so in the record) (:func:`_least_norm_record`);
* ``lcs.A1``, ``lcs.A2``, ``lcs.A3``, ``lcs.LG``: the main theorem's assumptions, passed when the items the
  Section 7 theorem derives them from passed, skipped (not established, with the items that did not pass
  and their status) otherwise — those items are sufficient conditions, so their failure refutes nothing.
  ``lcs.A2`` rests on ``lcs.v_ac`` too: its proof needs ``v(t_ℓ) → v(t)``.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linprog

from ..errors import InvalidCheckArgument, VerimonoError
from ..results import FAILED, PASSED, SKIPPED, CheckResult, Report
from ..tolerances import EPS, RTOL, STALL_RATIO, STALL_WINDOW, tolerance
from .lcp import is_psd, lcp_alpha, lcp_residual, sol_polyhedron, solve_lcp
from .passivity import is_passive
from .relations import BoxRelation, OperatorRelation

EVIDENCE = "evidence from samples, not a proof"


def _rec(check, subject, ok, message, worst=None, bound=None, details=None, counterexample=None):
    status = ok if isinstance(ok, str) else (PASSED if ok else FAILED)
    return CheckResult(check, subject, status, worst=worst, bound=bound, message=message,
                       details=dict(details or {}), counterexample=counterexample)


def _rel_int_margin(system, t: float) -> float | None:
    """``max τ`` of the LP above (``> 0`` iff ``im C ∩ ri(im(𝓜 + D) − v(t)) ≠ ∅``), or None if undecidable."""
    rel = system.relation
    if not isinstance(rel, BoxRelation) or not is_psd(system.D):
        return None
    n, m = system.n, system.m
    lo, hi = rel.bounds(m)
    fin = np.flatnonzero(np.isfinite(hi))
    f = fin.size
    E = np.eye(m)[:, fin]
    # variables y = (x, z, s, τ); rows "expr ≥ τ" written as −expr + τ ≤ 0
    nv = n + m + f + 1
    rows, rhs, eq_rows, eq_rhs = [], [], [], []
    v = system.v(t)
    # D z + E s + D l + C x + v ≥ τ
    G = np.hstack([-system.C, -system.D, -E, np.ones((m, 1))])
    rows.append(G); rhs.append(system.D @ lo + v)
    degenerate = np.zeros(m, bool)
    degenerate[fin] = (hi - lo)[fin] <= 0
    for i in range(m):  # z_i ≥ τ, unless the bound is degenerate (then z_i = 0 is an implicit equality)
        r = np.zeros(nv)
        if degenerate[i]:
            r[n + i] = 1.0; eq_rows.append(r); eq_rhs.append(0.0)
        else:
            r[n + i] = -1.0; r[-1] = 1.0; rows.append(r[None]); rhs.append(np.zeros(1))
    for j, i in enumerate(fin):  # (u − l)_i − z_i ≥ τ and s_j ≥ τ
        if degenerate[i]:
            continue
        r = np.zeros(nv); r[n + i] = 1.0; r[-1] = 1.0
        rows.append(r[None]); rhs.append(np.array([(hi - lo)[i]]))
        r = np.zeros(nv); r[n + m + j] = -1.0; r[-1] = 1.0
        rows.append(r[None]); rhs.append(np.zeros(1))
    c = np.zeros(nv); c[-1] = -1.0
    bounds = [(None, None)] * (n + m + f) + [(None, 1.0)]
    res = linprog(c, A_ub=np.vstack(rows), b_ub=np.concatenate(rhs),
                  A_eq=np.vstack(eq_rows) if eq_rows else None, b_eq=np.array(eq_rhs) if eq_rows else None,
                  bounds=bounds, method="highs")
    return float(-res.fun) if res.status == 0 else float("-inf")


#: sample grid of ``v`` on ``[0, T]`` (intervals); the total variation is compared on its last two dyadic
#: coarsenings, the increments of its finest level are the starting brackets of the jump search
AC_GRID = 4096
#: brackets bisected in search of a jump: this many of the finest grid's largest increments ``Δv_i`` of ``v``,
#: and as many of its largest ``|Δv_i − ½(Δv_{i−1} + Δv_{i+1})|`` (increments unlike their neighbours')
AC_CANDIDATES = 8
#: bisection stops at width ``AC_FLOOR·ε·T``: about a thousand ulps of ``T``, where ``v(t)`` is still
#: evaluated at distinct times (about 30 bisections from ``T/AC_GRID``, more than the ``STALL_WINDOW`` the stall
#: test compares over)
AC_FLOOR = 2.0 ** 10
#: the grid total variation of a ``v`` of bounded variation increases to its limit under refinement; a
#: relative growth of more than this between the last two grids is reported as unbounded variation
#: (a Lipschitz ``v`` changes by ``O(h)``; ``t sin(1/t)``-like oscillation keeps growing)
TV_SETTLE = 0.05
#: scale factors ``s`` for the homogeneity ``z*(sq) = s z*(q)`` of the least-norm solution
#: (``SOL(sq, D) = s SOL(q, D)``): a selection that is off by anything not proportional to ``|q|`` (an
#: element of the recession cone of ``SOL`` added in absolute units, an absolute threshold) shows at
#: ``s = 10^±6`` as a defect of order ``1/s`` or ``s`` against ``RTOL``
LN_SCALES = (1e-6, 1e-3, 1e3, 1e6)


def _v_ac_record(system, T: float, fine: np.ndarray, V: np.ndarray, finite: bool) -> CheckResult:
    """``lcs.v_ac`` (Theorem ``e: linear case-comp`` iii, ``v ∈ AC``): continuity and bounded variation of ``v``.

    *Continuity*: the intervals of the sample grid with the largest increments ``|v(b) − v(a)|``, and those
    least like their neighbours' (:data:`AC_CANDIDATES` each), are bisected, keeping the half whose increment
    is further from the neighbours' trend, down to width
    ``AC_FLOOR·ε·T``.  On a continuous ``v`` the increment goes to 0 (halving per bisection for a Lipschitz
    ``v``); across a jump of size ``J`` it stays ``≥ J``.  A jump is an increment above ``tolerance(v)``
    that stalled — above ``STALL_RATIO`` times its value ``STALL_WINDOW`` bisections earlier — and is
    reported with its location.  *Bounded variation*: the grid total variation on the last two dyadic
    grids settles (relative change ≤ ``TV_SETTLE``).  Evidence, not proof (a Cantor-like ``v`` passes both).
    """
    subj = system.name
    if not finite:
        return _rec("lcs.v_ac", subj, FAILED, "v is not finite on the sample grid", details={"evidence": True})
    dV = np.diff(V, axis=0)
    inc = np.linalg.norm(dV, axis=1)
    levels = [AC_GRID // 8, AC_GRID // 4, AC_GRID // 2, AC_GRID]
    largest = [float(np.linalg.norm(np.diff(V[::AC_GRID // k], axis=0), axis=1).max(initial=0.0)) for k in levels]
    floor = tolerance(V)
    min_width = AC_FLOOR * EPS * T
    worst, jump = 0.0, None
    # candidates: the largest increments, and the largest |Δv_i − ½(Δv_{i−1} + Δv_{i+1})| (a small jump on a
    # steep slope is not among the largest increments, but stands out of its neighbours: O(h²|v''|) there)
    padded = np.concatenate([dV[:1], dV, dV[-1:]])
    excess = np.linalg.norm(dV - 0.5 * (padded[:-2] + padded[2:]), axis=1)
    cands = dict.fromkeys(np.concatenate([np.argsort(inc)[::-1][:AC_CANDIDATES],
                                          np.argsort(excess)[::-1][:AC_CANDIDATES]]).tolist())
    for i in cands:
        if inc[i] <= floor:
            continue
        a, b, va, vb = float(fine[i]), float(fine[i + 1]), V[i], V[i + 1]
        slope = 0.5 * (padded[i] + padded[i + 2]) / (b - a)   # the neighbours' trend, to tell a jump from it
        seq = [float(inc[i])]
        while b - a > min_width and len(seq) < 64:
            mid = 0.5 * (a + b)
            vm = np.asarray(system.v(mid), float)
            trend = slope * (0.5 * (b - a))
            if np.linalg.norm(vm - va - trend) >= np.linalg.norm(vb - vm - trend):   # the half off the trend
                b, vb = mid, vm
            else:
                a, va = mid, vm
            seq.append(float(np.linalg.norm(vb - va)))
        stalled = (len(seq) > STALL_WINDOW and seq[-1] > floor and seq[-1] >= STALL_RATIO * seq[-1 - STALL_WINDOW])
        if stalled and seq[-1] > worst:
            worst = seq[-1]
            jump = {"t": 0.5 * (a + b), "bracket": [a, b], "v_left": np.asarray(va).tolist(),
                    "v_right": np.asarray(vb).tolist(), "jump": seq[-1], "increments": seq}
    tv = [float(np.sum(np.linalg.norm(np.diff(V[::s], axis=0), axis=1))) for s in (4, 2, 1)]
    settled = abs(tv[2] - tv[1]) <= max(TV_SETTLE * tv[2], tolerance(tv[2]))
    details = {"evidence": True, "largest_increment": dict(zip(map(str, levels), largest)), "total_variation": tv}
    if jump is not None:
        msg = (f"v jumps by {jump['jump']:.4g} at t ≈ {jump['t']:.9g}: |v(b) − v(a)| stays {jump['jump']:.4g} on "
               f"brackets [a, b] around it down to width {jump['bracket'][1] - jump['bracket'][0]:.2g} — v is not "
               f"continuous, let alone absolutely continuous ({EVIDENCE})")
    elif not settled:
        msg = f"grid total variation of v still grows under refinement: {tv} (unbounded variation?) ({EVIDENCE})"
    else:
        msg = (f"largest increment of v on grids of {levels} intervals: {[f'{d:.3g}' for d in largest]}; "
               f"no jump in {len(cands)} candidate intervals bisected to width {min_width:.2g}; total variation "
               f"{tv[2]:.6g} settled ({EVIDENCE})")
    if jump is None and not settled:
        worst, floor = abs(tv[2] - tv[1]) / tv[2], TV_SETTLE
    return _rec("lcs.v_ac", subj, jump is None and settled, msg, worst=worst, bound=floor, details=details,
                counterexample=jump if jump is not None else (None if settled else {"total_variation": tv}))


def _sample_q(D: np.ndarray, rng) -> np.ndarray:
    """A unit ``q ∈ Q_D^+``: ``q = w₀ − D z₀`` with ``z₀, w₀ ≥ 0`` of random supports, so ``z₀`` is feasible
    (Proposition ``p:lcp2``: feasible ⟺ ``q ∈ Q_D^+``); sparse supports put ``q`` on the boundary of the
    cone with positive probability, where ``SOL(q, D)`` is not a singleton and the selection matters."""
    m = D.shape[0]
    while True:
        z0 = np.abs(rng.normal(size=m)) * (rng.random(m) < 0.5)
        w0 = np.abs(rng.normal(size=m)) * (rng.random(m) < 0.5)
        q = w0 - D @ z0
        nq = float(np.linalg.norm(q))
        if nq > 0:
            return q / nq


def _shorter_solution(D, q, z):
    """A solution of ``LCP(q, D)`` shorter than ``z`` by more than ``tolerance(z)``, or None.

    ``z`` is the least-norm point of the convex ``SOL(q, D)`` iff ``zᵀ(y − z) ≥ 0`` for every ``y ∈ SOL``;
    the LP ``min zᵀy`` over ``SOL`` (:func:`verimono.lcs.lcp.sol_polyhedron`) finds a violating ``y``, and
    the segment ``z + τ(y − z)`` its shortest point."""
    G, h, Aeq, beq = sol_polyhedron(D, q, z)
    res = linprog(z, A_ub=G, b_ub=h, A_eq=Aeq if len(Aeq) else None, b_eq=beq if len(Aeq) else None,
                  bounds=[(None, None)] * q.size, method="highs")
    if res.status != 0:
        return None
    d = res.x - z
    dd = float(d @ d)
    if dd == 0.0 or z @ d >= 0:
        return None
    p = z + min(1.0, -float(z @ d) / dd) * d
    # y comes from HiGHS, feasible to its ~1e-9 tolerances, not to QP_RTOL: p is accepted as a solution at
    # RTOL, and only a norm drop far beyond what such a perturbation could explain counts
    ok = lcp_residual(D, q, p) <= tolerance(q, D @ p)
    return p if ok and np.linalg.norm(p) < np.linalg.norm(z) - tolerance(z) else None


def _least_norm_record(system, rng, samples: int) -> CheckResult:
    """``lcs.least_norm_growth`` (Theorem ``thm: linear case`` vi via Proposition ``p:lcp2`` iv–v).

    Bounded boxes: ``|Bz| ≤ ‖B‖ max|bounds| √m`` exactly.  Complementarity with ``D + Dᵀ ⪰ 0``: on sampled
    unit ``q ∈ Q_D^+`` (:func:`_sample_q`) the least-norm solution ``z*`` of :func:`verimono.lcs.solve_lcp`
    must be homogeneous, ``z*(sq) = s z*(q)`` for ``s`` in :data:`LN_SCALES` (to ``tolerance(z*)``), and
    least-norm (no shorter solution, :func:`_shorter_solution`); then ``α = max |z*(q)|`` over the unit
    samples estimates the constant of ``|z*(q)| ≤ α|q|`` and ``|Bz*(η)| ≤ ‖B‖α|η|``.
    """
    subj, rel, D, B = system.name, system.relation, system.D, system.B
    if isinstance(rel, BoxRelation) and np.all(np.isfinite(rel.bounds(system.m)[1])):
        bnd = float(np.linalg.norm(B, 2) * np.abs(np.concatenate(rel.bounds(system.m))).max() * np.sqrt(system.m))
        return _rec("lcs.least_norm_growth", subj, True, f"bounded multipliers: |Bz| ≤ {bnd:.4g} (exact)")
    if not (isinstance(rel, BoxRelation) and rel.is_lcp and is_psd(D)):
        return _rec("lcs.least_norm_growth", subj, SKIPPED, "needs a bounded box, or complementarity with "
                    "D + Dᵀ ⪰ 0 (Proposition p:lcp2)")
    alpha, worst, bad, shorter_checked, q_alpha = 0.0, 0.0, None, 0, None
    explicit = lcp_alpha(D)
    for _ in range(samples):
        q = _sample_q(D, rng)
        try:
            z = solve_lcp(D, q)
        except VerimonoError as exc:
            bad = {"q": q, "error": f"{type(exc).__name__}: {exc}"}
            worst = np.inf
            break
        tol = tolerance(z, q)
        for s in LN_SCALES:
            try:
                zs = solve_lcp(D, s * q)
            except VerimonoError as exc:
                bad, worst = {"q": q, "s": s, "error": f"{type(exc).__name__}: {exc}"}, np.inf
                break
            defect = float(np.abs(zs / s - z).max()) / tol
            if defect > worst:
                worst = defect
                if defect > 1.0:
                    bad = {"q": q, "s": s, "z(q)": z, "z(sq)/s": zs / s,
                           "ratio |z(sq)|/|sq|": float(np.linalg.norm(zs) / s),
                           "ratio |z(q)|/|q|": float(np.linalg.norm(z))}
        if bad is not None:
            break
        if float(np.linalg.norm(z)) > alpha:
            alpha, q_alpha = float(np.linalg.norm(z)), (q, z)
        p = _shorter_solution(D, q, z)
        shorter_checked += 1
        if p is not None:
            worst = max(worst, float(np.linalg.norm(z) - np.linalg.norm(p)) / tolerance(z))
            bad = {"q": q, "z": z, "shorter solution": p}
            break
    bn = float(np.linalg.norm(B, 2))
    if bad is None and explicit is not None and alpha > explicit * (1.0 + RTOL) + tolerance(alpha):
        worst = alpha / (explicit * (1.0 + RTOL) + tolerance(alpha))
        bad = {"q": q_alpha[0], "z": q_alpha[1], "|z|/|q|": alpha, "alpha": explicit}
    a_used = explicit if explicit is not None else alpha
    a_kind = ("explicit 1/λ_min((D + Dᵀ)/2)" if explicit is not None else
              "sampled sup |z*(q)|/|q|, a lower estimate: D + Dᵀ is singular, p:lcp2 v gives no α")
    if bad is None:
        msg = (f"Proposition p:lcp2 iv–v on {samples} unit q ∈ Q_D^+: z*(sq) = s z*(q) for s ∈ {list(LN_SCALES)} "
               f"(worst defect {worst:.2g}·tolerance), no shorter solution (linear programming); "
               + (f"|z*(q)| ≤ α|q| with the explicit α = 1/λ_min((D + Dᵀ)/2) = {explicit:.4g} (sampled sup "
                  f"{alpha:.4g}), so |B z*(η)| ≤ {bn * explicit:.4g}|η|" if explicit is not None else
                  f"α ≥ {alpha:.4g} (sampled sup of |z*(q)|/|q|; D + Dᵀ is singular, so p:lcp2 v gives no explicit "
                  f"α and this is an estimate from below)") + f" ({EVIDENCE})")
    elif "error" in bad:
        msg = f"Proposition p:lcp2: q ∈ Q_D^+ (feasible by construction) but no least-norm solution: {bad['error']}"
    elif "alpha" in bad:
        msg = (f"Proposition p:lcp2 v: |z*(q)|/|q| = {bad['|z|/|q|']:.6g} exceeds α = 1/λ_min((D + Dᵀ)/2) = "
               f"{bad['alpha']:.6g} at q = {np.array2string(np.asarray(bad['q']), precision=4)}")
    elif "shorter solution" in bad:
        msg = (f"Proposition p:lcp2 iv: solve_lcp's z (|z| = {np.linalg.norm(bad['z']):.6g}) is not the least-norm "
               f"solution: a solution of norm {np.linalg.norm(bad['shorter solution']):.6g} exists")
    else:
        msg = (f"Proposition p:lcp2 v: the least-norm solution is not homogeneous: |z*(sq)|/|sq| = "
               f"{bad['ratio |z(sq)|/|sq|']:.4g} at s = {bad['s']:g} but |z*(q)|/|q| = {bad['ratio |z(q)|/|q|']:.4g}: "
               "no α with |z*(q)| ≤ α|q| for this selection")
    return _rec("lcs.least_norm_growth", subj, bad is None, msg, worst=worst, bound=1.0, counterexample=bad,
                details={"evidence": True, "alpha": a_used, "alpha_kind": a_kind, "alpha_sampled": alpha,
                         "B_alpha": bn * a_used, "samples": samples,
                         "least_norm_checked": shorter_checked, "scales": list(LN_SCALES)})


def check_hypotheses(system, T: float, *, samples: int = 64, seed: int = 0) -> Report:
    """Evidence for each hypothesis of the Section 7 theorems on ``[0, T]`` (see the module docstring).

    ``T`` must be a finite positive horizon and ``samples`` a positive integer
    (:class:`verimono.InvalidCheckArgument` otherwise: an empty interval is evidence of nothing)."""
    import math

    if isinstance(T, bool) or not isinstance(T, (int, float, np.integer, np.floating)) \
            or not math.isfinite(float(T)) or T <= 0:
        raise InvalidCheckArgument(f"check_hypotheses needs a finite horizon T > 0, got {T!r}")
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
        raise InvalidCheckArgument(f"samples must be a positive integer, got {samples!r}")
    T = float(T)
    subj = system.name
    out = Report(meta={"evidence": EVIDENCE})
    rng = np.random.default_rng(seed)
    A, B, C, D = system.A, system.B, system.C, system.D
    # i. passivity with K = I and Proposition p:pass
    p = is_passive(A, B, C, D, K=np.eye(system.n))
    out.add(_rec("lcs.passivity", subj, p.passive, f"Theorem thm: linear case i (K = I): {p.message}",
                 worst=-p.margin, bound=p.tol))
    out.add(_rec("lcs.pass_D_psd", subj, p.D_psd, "Proposition p:pass i: D + Dᵀ ⪰ 0",
                 worst=float(-np.linalg.eigvalsh(D + D.T)[0]), bound=p.tol))
    out.add(_rec("lcs.pass_kernel", subj, p.kernel_ok, "Proposition p:pass ii: (B − Cᵀ) ker(D + Dᵀ) = {0}",
                 worst=p.kernel_residual, bound=p.tol))
    # ii. maximal monotone relation
    rel = system.relation
    if isinstance(rel, BoxRelation):
        out.add(_rec("lcs.relation_maxmon", subj, True, f"{rel.name}: the normal cone of a nonempty box is "
                     "maximal monotone (exact)"))
    elif isinstance(rel, OperatorRelation):
        op, worst = rel.op, -np.inf
        X, Y = rng.normal(size=(2, samples, op.dim)) * 3.0
        bad = None
        for x, y in zip(X, Y):
            jx, jy = op.resolvent(x, 1.0), op.resolvent(y, 1.0)
            d = jx - jy
            gap = d @ d - d @ (x - y) - tolerance(x, y, jx, jy)
            if gap > worst:
                worst = gap
                if gap > 0:
                    bad = {"x": x, "y": y}
        out.add(_rec("lcs.relation_maxmon", subj, bad is None, f"resolvent firmly nonexpansive on {samples} "
                     f"sampled pairs ({EVIDENCE})", worst=float(worst), bound=0.0, counterexample=bad,
                     details={"evidence": True}))
    ts = np.linspace(0.0, T, 17 if system.v_constant else max(17, samples))
    # iii. relative interior condition
    margins = [_rel_int_margin(system, float(t)) for t in ts]
    if any(mg is None for mg in margins):
        out.add(_rec("lcs.rel_int", subj, SKIPPED, "im(𝓜 + D) is known as a polyhedron only for box relations "
                     "with D + Dᵀ ⪰ 0"))
    else:
        worst_t = float(ts[int(np.argmin(margins))])
        out.add(_rec("lcs.rel_int", subj, min(margins) > tolerance(C, D),
                     f"im C ∩ ri(im(𝓜 + D) − v(t)) ≠ ∅ on {ts.size} sampled t by linear programming ({EVIDENCE}); "
                     f"smallest margin {min(margins):.3g} at t = {worst_t:g}", worst=-min(margins), bound=0.0,
                     details={"evidence": True, "t": ts.tolist(), "margins": margins},
                     counterexample=None if min(margins) > 0 else {"t": worst_t}))
    # iv / e: linear case-comp iii: v bounded and absolutely continuous (sampled)
    fine = np.linspace(0.0, T, AC_GRID + 1)
    V = np.array([system.v(float(t)) for t in fine])
    finite = bool(np.all(np.isfinite(V)))
    out.add(_rec("lcs.v_bounded", subj, finite,
                 f"sup |v| = {np.abs(V).max():.4g} on {AC_GRID + 1} samples ({EVIDENCE})",
                 worst=float(np.abs(V).max()) if finite else None, details={"evidence": True}))
    out.add(_v_ac_record(system, T, fine, V, finite))
    # vi. least-norm growth bound |B z*(η)| ≤ α(1 + |η|), from Proposition p:lcp2 iv-v
    out.add(_least_norm_record(system, rng, samples))
    # the main theorem's assumptions, as Theorem thm: linear case derives them
    st = {r.check: r.status for r in out}

    def derived(name, needs, what):
        statuses = [st[n] for n in needs]
        if all(s == PASSED for s in statuses):
            out.add(_rec(name, subj, PASSED, f"{what} follows from {', '.join(needs)} (Theorem thm: linear case; "
                         f"{EVIDENCE})", details={"from": needs}))
        else:  # the theorem's conditions are sufficient, not necessary: nothing is concluded
            missing = [f"{n} ({s})" for n, s in zip(needs, statuses) if s != PASSED]
            out.add(_rec(name, subj, SKIPPED, f"{what} is not established: {', '.join(missing)} did not pass "
                         "(Theorem thm: linear case gives sufficient conditions only)", details={"from": needs}))

    derived("lcs.A1", ["lcs.passivity", "lcs.relation_maxmon", "lcs.rel_int"], "(A1) H(t,·) maximal monotone")
    # the proof of (A2) passes to the limit in z_ℓ ∈ (𝓜 + D)^(-1)(Cx_ℓ + v(t_ℓ)) as t_ℓ → t: it needs
    # v(t_ℓ) → v(t), which boundedness (iv) does not give and v ∈ AC (e: linear case-comp iii) does
    derived("lcs.A2", ["lcs.passivity", "lcs.relation_maxmon", "lcs.rel_int", "lcs.v_bounded", "lcs.v_ac"],
            "(A2) closed graph in (t, x, y)")
    derived("lcs.A3", ["lcs.rel_int", "lcs.v_ac"], "(A3) domains move absolutely continuously")
    derived("lcs.LG", ["lcs.least_norm_growth", "lcs.v_bounded"], "(LG) linear growth of H^0")
    return out


__all__ = ["check_hypotheses", "EVIDENCE"]
