"""Evidence — never proof — for the assumptions of the paper's Theorem ``thm:main`` on a problem.

``check_assumptions(problem)`` samples times ``s < t`` in ``[0, T]``, points ``p`` around ``x0``, far from it
and near the kink ``0`` (:mod:`verimono.checks.assumption_samples`), and step sizes ``λ``, and uses only the
operator's resolvent (plus ``min_norm``/``project_domain`` when provided): ``z = J_λ p ∈ dom F(t,·)`` with
``Y_λ p ∈ F(t, z)`` (Prop. ``prop:maxmon-resolvent-Yosida`` v) gives graph points without knowing the domain.
Every "for all t" is searched (:mod:`verimono.checks.engine.supremum`) from the sample times and the times just after
every jump found, and every record says what was searched (``details["searched"]``).  One record per
assumption:

* ``assumption_A1`` (here) — monotonicity ``⟨z1 - z2, y1 - y2⟩ ≥ 0`` on sampled graph pairs (resolvent pairs
  and ``(z, F^0(z))``) at the sample times, and the largest violation over pairs of resolvent graph points
  searched over ``t``.  A violation disproves (A1).
* ``assumption_A2`` — outer semicontinuity from the right (:mod:`verimono.checks.assumption_a2`).
* ``assumption_A3``, ``assumption_LG``, ``assumption_YB`` — the assumptions with a bounding function φ, σ, θ
  (:mod:`verimono.checks.assumption_bounds`).

Status ``passed`` means "no sample contradicts the assumption" (the message and ``details["evidence"]``
say so); ``failed`` means a sample contradicts it (or the stated function) or the growth evidence above.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..core.problem import Problem
from ..core.tolerances import current_data_scale, current_rtol
from ..records.results import FAILED, PASSED, UNDECIDED, XFAIL, XFAIL_DECLARED, CheckResult, Report
from .arguments import valid_seed
from .assumption_a2 import (A2_LEVELS, A2_RATIO, A2_SETTLED, A2_TAIL_SAFETY, UNDECIDED_SIDE,  # noqa: F401
                            check_assumption_A2)
from .assumption_bounds import check_assumption_A3, check_assumption_LG, check_assumption_YB  # noqa: F401
from .assumption_samples import (A2_LAMBDAS, EVIDENCE, LAMBDAS, min_norm_or_none, min_norms,  # noqa: F401
                                 run_assumption, sampled)
from .core import Outcome, law, laws_of, run, subject_name
from .subjects import require_problem
from .engine.times import search_time, searched_t


def _dots(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a_i @ b_i`` of every row, by a stacked matmul: the same bits as the 1-D ``a_i @ b_i`` of the law's
    evaluator of one time (``np.einsum`` and ``np.sum`` reduce in another order)."""
    return (a[:, None, :] @ b[:, :, None])[:, 0, 0]


def _non_monotone(Z: np.ndarray, Y: np.ndarray, P: np.ndarray):
    """``(ratio, inner, i, j)`` of every pair of graph points ``(Z_i, Y_i)``: ``-⟨Z_i − Z_j, Y_i − Y_j⟩`` in
    units of its rounding (``P``: the size of what each ``Y`` was computed from; the operator's own scale under
    judgement is one more magnitude of the ``Z``, as in :func:`verimono.core.tolerances.tolerance`), at the
    precision under judgement."""
    i, j = np.triu_indices(len(Z), 1)
    dz, dy = Z[i] - Z[j], Y[i] - Y[j]
    inner = np.sum(dz * dy, axis=1)
    nz, ny = np.linalg.norm(dz, axis=1), np.linalg.norm(dy, axis=1)
    zs = np.maximum(np.maximum(np.abs(Z[i]).max(1, initial=0.0), np.abs(Z[j]).max(1, initial=0.0)), current_data_scale())
    tol = current_rtol() * (nz * (1.0 + np.maximum(P[i], P[j])) + ny * (1.0 + zs))
    return -inner / (tol + 1e-300), inner, i, j


def _size(P: np.ndarray, lam: float) -> np.ndarray:
    """The size of what ``Y_λ p = (p − J_λ p)/λ`` of each row ``p`` of ``P`` is computed from: ``max(|p|, S)/λ``,
    ``S`` the operator's own scale under judgement (``J_λ p`` rounds at it: :mod:`verimono.core.tolerances`)."""
    return np.maximum(np.abs(P).max(axis=1, initial=0.0), current_data_scale()) / lam


@law("assumption_A1", "(A1)", subject="problem", driver=run_assumption, over=("t", "points", "lam"))
def check_assumption_A1(S) -> Outcome:
    """(A1): monotonicity ``⟨z1 - z2, y1 - y2⟩ ≥ 0`` on sampled graph pairs of ``F(t,·)`` (resolvent pairs
    ``(J_λ p, Y_λ p)`` and ``(z, F^0(z))``) at the sample times, and over the pairs of resolvent graph points
    of each ``λ`` searched over ``t`` (:func:`_a1_sup`).  A violation disproves (A1)."""
    worst, counter, pairs = -np.inf, None, 0
    nn = len(S.near)
    for t in S.times:
        Z, Y, P, N = [], [], [], []
        for lam in S.lambdas:
            J = S.rows(S.points, lam, float(t))
            keep = np.all(np.isfinite(J), axis=1)       # rows verimono could not verify are no evidence
            Z.append(J[keep]), Y.append(((S.points - J) / lam)[keep])
            P.append(_size(S.points[keep], lam))
            N.append(J[:nn][keep[:nn]])
        try:   # minimal sections at the domain points of x0 and the points around it
            z = np.vstack(N)
            f0 = min_norms(S.op, z, float(t))
            keep = [i for i, v in enumerate(f0) if v is not None]
            Z.append(z[keep]), Y.append(np.array([f0[i] for i in keep]).reshape(-1, S.problem.dim))
            P.append(np.abs(Y[-1]).max(axis=1) if keep else np.zeros(0))
        except NotImplementedError:
            pass
        Z, Y, P = np.vstack(Z), np.vstack(Y), np.concatenate(P)
        ratio, inner, i, j = _non_monotone(Z, Y, P)
        pairs += len(i)
        m = int(np.argmax(ratio))
        if ratio[m] > worst:
            worst = float(ratio[m])
            counter = {"t": t, "z1": Z[i[m]], "y1": Y[i[m]], "z2": Z[j[m]], "y2": Y[j[m]], "inner": inner[m]}
    sup, c = _a1_sup(S)
    if sup.value > worst:
        worst, counter = sup.value, c
    details = {"evidence": EVIDENCE, "pairs": pairs, "sup_search": sup.as_dict(),
               "searched": {"t": searched_t(sup), "x_range": S.x_range(),
                            "lambda": [min(S.lambdas), max(S.lambdas)]}}
    return sampled("assumption_A1", max(worst, 0.0), counter, details,
                   lambda c: f"<z1 - z2, y1 - y2> = {c['inner']:.3g} < 0 for graph points of F(t = {c['t']!r})"
                             + (" (found by the search over time)" if c.get("found_by") else ""),
                   f"no non-monotone pair among {pairs} sampled graph pairs at {len(S.times)} sample times, nor "
                   f"among the resolvent graph points searched over t ({sup.searched.points} times, resolution "
                   f"{sup.searched.resolution:.3g}: {sup.searched.outside()}) ({EVIDENCE})")


def _a1_sup(S):
    """The largest non-monotonicity of a pair of graph points ``(J_λ(t) p_a, Y_λ(t) p_a)``,
    ``(J_λ(t) p_b, Y_λ(t) p_b)`` over ``t`` (families: the step ``λ`` and the pair ``a < b``; two resolvents
    per family, all of them in one batch per ``λ`` at the design times)."""
    lams, P = S.lambdas, S.points
    ia, ib = np.triu_indices(len(P), 1)
    per = len(ia)

    def pairs(t: float, li: int, rows: np.ndarray):
        """The ratios of the pairs of ``rows`` (indices into P) at step ``lams[li]`` (``-inf`` for a pair with
        a point whose resolvent verimono could not verify)."""
        lam, p = lams[li], P[rows]
        z = S.rows(p, lam, t)
        y = (p - z) / lam
        ratio, inner, i, j = _non_monotone(z, y, _size(p, lam))
        return z, y, np.where(np.isnan(ratio), -np.inf, ratio), inner, i, j

    def one(t: float, f: int) -> float:
        """The ratio of family ``f`` alone (two resolvents; :func:`_non_monotone`'s formula for one pair)."""
        li, k = divmod(int(f), per)
        lam, p = lams[li], P[[ia[k], ib[k]]]
        z = S.rows(p, lam, t)
        y = (p - z) / lam
        dz, dy = z[0] - z[1], y[0] - y[1]
        inner = float(dz @ dy)
        size = _size(p, lam)
        tol = current_rtol() * (math.sqrt(float(dz @ dz)) * (1.0 + max(size[0], size[1]))
                                + math.sqrt(float(dy @ dy)) * (1.0 + max(float(np.abs(z).max()), current_data_scale())))
        r = -inner / (tol + 1e-300)
        return -math.inf if r != r else r

    def values(t: float, which):
        if which is not None and len(which) <= 2:      # the coverage and the local search: one pair
            return np.array([one(t, f) for f in which])
        # every family: one batched resolvent call per λ
        every = np.concatenate([pairs(t, li, np.arange(len(P)))[2] for li in range(len(lams))])
        return every if which is None else every[np.asarray(list(which), dtype=int)]

    def many(ts: np.ndarray, which) -> np.ndarray:
        """``values(t, which)`` at every time of ``ts`` (``which``: one or two pairs): the subject's calls as
        :func:`one` makes them (all times in one call when the operator takes a time per row), the arithmetic over all times at once (NaN where a row is not finite for a
        reason other than an unverified resolvent: the engine evaluates it again with :func:`one`)."""
        out = np.empty((len(ts), len(which)))
        for k, f in enumerate(which):
            li, kk = divmod(int(f), per)
            lam, p = lams[li], P[[ia[kk], ib[kk]]]
            z = S.rows_at_times(p, lam, ts)         # (times, 2, n): one call when the operator takes a time per row
            y = (p - z) / lam
            dz, dy = z[:, 0] - z[:, 1], y[:, 0] - y[:, 1]
            size = _size(p, lam)
            tol = current_rtol() * (np.sqrt(_dots(dz, dz)) * (1.0 + max(size[0], size[1]))
                                    + np.sqrt(_dots(dy, dy)) * (1.0 + np.maximum(np.abs(z).max(axis=(1, 2)),
                                                                                 current_data_scale())))
            with np.errstate(invalid="ignore"):
                r = -_dots(dz, dy) / (tol + 1e-300)
            unverified = ~np.isfinite(z).all(axis=(1, 2))
            out[:, k] = np.where(np.isnan(r) & unverified, -np.inf, r)
        return out

    values.many = many      # type: ignore[attr-defined]
    sup = search_time(values, 0.0, S.T, design=S.design(), seed=S.seed)
    li, k = divmod(sup.family, per)
    z, y, ratio, inner, _, _ = pairs(sup.t, li, np.array([ia[k], ib[k]]))
    return sup, {"t": sup.t, "lam": lams[li], "z1": z[0], "y1": y[0], "z2": z[1], "y2": y[1],
                 "inner": inner[0], "found_by": "search over time"}


def run_composite(decl: Any, problem: Problem, records: dict[str, CheckResult]) -> CheckResult:
    """A law over the records of the other assumptions of ``problem``."""
    return run(decl, subject_name(problem), lambda: decl.evaluate(problem, records), problem=problem)


@law("assumptions_thm_main", "thm:main: (A1)–(A3) and (LG) or (YB)", subject="problem", driver=run_composite)
def thm_main(problem: Problem, records: dict[str, CheckResult]) -> Outcome:
    """Theorem ``thm:main`` needs (A1)–(A3) and *one of* (LG) or (YB): a composite law over the records of
    the five assumptions.  When exactly one of (LG), (YB) has evidence against it and the other has
    evidence for it, that record becomes an expected failure (``xfail``, saying which alternative holds, the
    declaration in ``details["xfail_declared"]``); this record fails when any remaining assumption record
    failed, and is undecided (never passed) when one is undecided and none failed."""
    lg, yb = records.get("assumption_LG"), records.get("assumption_YB")
    for this, other, name in ((lg, yb, "(YB)"), (yb, lg, "(LG)")):
        if this is not None and other is not None and this.status == FAILED and other.status == PASSED:
            this.status = XFAIL
            this.message = f"the alternative hypothesis {name} has evidence for it; {this.message}"
            this.details = {**this.details,
                            XFAIL_DECLARED: f"thm:main needs (LG) or (YB); {name} has evidence for it"}
    bad = [r.check for r in records.values() if r.status == FAILED]
    open_ = [r.check for r in records.values() if r.status == UNDECIDED]
    if bad:
        return Outcome(None, status=FAILED, details={"evidence": EVIDENCE, "from": sorted(records)},
                       message="evidence against " + ", ".join(bad))
    if open_:     # an undecided assumption is never a pass, nor is a theorem resting on it
        return Outcome(None, status=UNDECIDED, details={"evidence": EVIDENCE, "from": sorted(records)},
                       message="undecided: " + ", ".join(open_) + " (no record contradicts the others)")
    return Outcome(None, status=PASSED, details={"evidence": EVIDENCE, "from": sorted(records)},
                   message="no sample contradicts (A1)–(A3) and (LG) or (YB) — evidence, not proof")


ASSUMPTION_LAWS = ("assumption_A1", "assumption_A2", "assumption_A3", "assumption_LG", "assumption_YB")


def check_assumptions(problem: Problem, *, seed: int = 0, points: int = 12, times: int = 7,
                      composite: bool = True) -> Report:
    """Sampled evidence for (A1), (A2), (A3), (LG) and (YB)/(YB') on ``problem`` (see the module docstring),
    then (``composite=True``) the composite law :func:`thm_main` of Theorem ``thm:main``."""
    require_problem(problem)
    seed = valid_seed(seed)
    report = Report(meta={"subject": subject_name(problem), "seed": seed, "evidence": EVIDENCE})
    laws = laws_of("problem")
    for name in ASSUMPTION_LAWS:
        report.add(laws[name].check(problem, seed=seed, points=points, times=times))
    if composite:
        rec = thm_main(problem, {r.check: r for r in report.results})
        rec.seed = seed
        report.add(rec)
    return report


def problem_checks(problem: Problem | None = None, *, seed: int = 0, points: int = 12, times: int = 7):
    """The battery of a problem, as ``(name, check)`` pairs with ``check(problem) -> CheckResult`` — one
    source for :func:`check_assumptions`'s records in :func:`verimono.testing.parametrize_with_checks`.

    The five assumption laws share their samples and the composite :func:`thm_main` reads their records,
    so the first check run evaluates the whole battery once (per problem) and every check returns its own
    record of it."""
    done: dict[int, dict[str, CheckResult]] = {}

    def records(p: Problem) -> dict[str, CheckResult]:
        if id(p) not in done:
            done[id(p)] = {r.check: r for r in check_assumptions(p, seed=seed, points=points, times=times)}
        return done[id(p)]

    for name in (*ASSUMPTION_LAWS, "assumptions_thm_main"):
        yield name, (lambda p, _name=name: records(p)[_name])


__all__ = ["check_assumptions", "problem_checks", "thm_main", "ASSUMPTION_LAWS", "EVIDENCE", "LAMBDAS", "A2_LEVELS", "A2_RATIO", "A2_SETTLED",
           "A2_TAIL_SAFETY", "A2_LAMBDAS"]
