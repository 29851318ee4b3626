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
* ``lcs.v_bounded`` / ``lcs.v_ac`` (items iv, ``e: linear case-comp`` iii): sup and total variation of ``v``
  on nested sample grids;
* ``lcs.least_norm_growth`` (item vi): ``|B z*(η)| ≤ α(1 + |η|)`` with ``z*`` the least-norm multiplier of
  ``(η, D)``, the worst sampled ratio reported (Proposition ``p:lcp2`` v gives it for PSD ``D``);
* ``lcs.A1``, ``lcs.A2``, ``lcs.A3``, ``lcs.LG``: the main theorem's assumptions, passed when the items the
  Section 7 theorem derives them from passed, skipped (not established) otherwise — those items are
  sufficient conditions, so their failure refutes nothing.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linprog

from ..errors import VerimonoError
from ..results import FAILED, PASSED, SKIPPED, CheckResult, Report
from ..tolerances import tolerance
from .lcp import is_psd, solve_lcp
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


def check_hypotheses(system, T: float, *, samples: int = 64, seed: int = 0) -> Report:
    """Evidence for each hypothesis of the Section 7 theorems on ``[0, T]`` (see the module docstring)."""
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
    fine = np.linspace(0.0, T, 4097)
    V = np.array([system.v(float(t)) for t in fine])
    finite = bool(np.all(np.isfinite(V)))
    out.add(_rec("lcs.v_bounded", subj, finite, f"sup |v| = {np.abs(V).max():.4g} on 4097 samples ({EVIDENCE})",
                 worst=float(np.abs(V).max()) if finite else None, details={"evidence": True}))
    tv = [float(np.sum(np.linalg.norm(np.diff(V[::s], axis=0), axis=1))) for s in (4, 2, 1)]
    settled = finite and abs(tv[2] - tv[1]) <= max(0.05 * tv[2], tolerance(tv[2], rtol=1e-6))
    out.add(_rec("lcs.v_ac", subj, settled, f"total variation of v on nested grids {tv} ({EVIDENCE}); "
                 "a jump or unbounded variation keeps growing under refinement", details={"evidence": True}))
    # vi. least-norm growth bound |B z*(η)| ≤ α(1 + |η|)
    if isinstance(rel, BoxRelation) and np.all(np.isfinite(rel.bounds(system.m)[1])):
        bnd = float(np.linalg.norm(B, 2) * np.abs(np.concatenate(rel.bounds(system.m))).max() * np.sqrt(system.m))
        out.add(_rec("lcs.least_norm_growth", subj, True, f"bounded multipliers: |Bz| ≤ {bnd:.4g} (exact)"))
    elif isinstance(rel, BoxRelation) and is_psd(D):
        ratios = []
        for _ in range(samples):
            x = rng.normal(size=system.n) * 3.0
            eta = C @ x + system.v(float(rng.uniform(0, T)))
            try:
                z = solve_lcp(D, eta)
            except VerimonoError:
                continue
            ratios.append(float(np.linalg.norm(B @ z) / (1.0 + np.linalg.norm(eta))))
        out.add(_rec("lcs.least_norm_growth", subj, bool(ratios), f"Proposition p:lcp2 v: worst sampled "
                     f"|B z*(η)|/(1 + |η|) over {len(ratios)} η ∈ dom (𝓟 + D)^(-1) ({EVIDENCE})",
                     worst=max(ratios) if ratios else None, details={"evidence": True}))
    else:
        out.add(_rec("lcs.least_norm_growth", subj, SKIPPED, "needs a box relation with D + Dᵀ ⪰ 0"))
    # the main theorem's assumptions, as Theorem thm: linear case derives them
    st = {r.check: r.status for r in out}

    def derived(name, needs, what):
        statuses = [st[n] for n in needs]
        if all(s == PASSED for s in statuses):
            out.add(_rec(name, subj, PASSED, f"{what} follows from {', '.join(needs)} (Theorem thm: linear case; "
                         f"{EVIDENCE})", details={"from": needs}))
        else:  # the theorem's conditions are sufficient, not necessary: nothing is concluded
            missing = [n for n, s in zip(needs, statuses) if s != PASSED]
            out.add(_rec(name, subj, SKIPPED, f"{what} is not established: {', '.join(missing)} did not pass "
                         "(Theorem thm: linear case gives sufficient conditions only)", details={"from": needs}))

    derived("lcs.A1", ["lcs.passivity", "lcs.relation_maxmon", "lcs.rel_int"], "(A1) H(t,·) maximal monotone")
    derived("lcs.A2", ["lcs.passivity", "lcs.relation_maxmon", "lcs.rel_int", "lcs.v_bounded"],
            "(A2) closed graph in (t, x, y)")
    derived("lcs.A3", ["lcs.rel_int", "lcs.v_ac"], "(A3) domains move absolutely continuously")
    derived("lcs.LG", ["lcs.least_norm_growth", "lcs.v_bounded"], "(LG) linear growth of H^0")
    return out


__all__ = ["check_hypotheses", "EVIDENCE"]
