"""Evidence — never proof — for the assumptions of the paper's Theorem ``thm:main`` on a problem.

``check_assumptions(problem)`` samples times ``s < t`` in ``[0, T]``, points ``p`` around ``x0`` and step
sizes ``λ``, and uses only the operator's resolvent (plus ``min_norm``/``project_domain`` when provided):
``z = J_λ p ∈ dom F(t,·)`` with ``Y_λ p ∈ F(t, z)`` (Prop. ``prop:maxmon-resolvent-Yosida`` v) gives graph
points without knowing the domain.  One record per assumption:

* ``assumption_A1`` — monotonicity ``⟨z1 - z2, y1 - y2⟩ ≥ 0`` on sampled graph pairs (resolvent pairs and
  ``(z, F^0(z))``).  A violation disproves (A1).
* ``assumption_A2`` — outer semicontinuity from the right of ``t ↦ graph F(t,·)``, through resolvents:
  if ``q = lim J_λ(t+δ) p`` exists as ``δ ↓ 0``, then ``(q, (p - q)/λ)`` is a limit of graph points of
  ``F(t+δ)``, so (A2) puts it in ``graph F(t)`` and single-valuedness of the resolvent gives
  ``q = J_λ(t) p``.  Sampled on ``δ_k = (T - t) 4^{-k}``; the limit is extrapolated from the last
  differences (geometric tail), and a limit whose distance from ``J_λ(t) p`` stays above tolerance after
  subtracting the tail disproves (A2).  (The Minty residual of the graph point ``(J_λ(t+δ)p, Y_λ(t+δ)p)``
  with respect to ``graph F(t)`` is exactly ``√2 |J_λ(t+δ)p - J_λ(t)p|``.)  A sequence that has not
  settled is no evidence either way and is counted.  Between the sample times, the jumps of
  ``t ↦ J_λ(t) p`` are searched adaptively (:mod:`verimono.checks.jumps`, the bisection of ``lcs.v_ac``)
  down to adjacent floats ``a < b``; the jump time is the one with the shorter decimal (``t <= 0.45``
  switches right after ``0.45``), and the right-limit test runs there: a jump whose time carries the left
  value fails (A2), a right-continuous one passes.  (A2) is *not* implied by (A3) for subdifferentials,
  whatever Lemma ``lem:A3ImpliesA2`` says: ``c(t)|x|`` with ``c = 1`` on ``[0, ½]``, 2 after, has a fixed
  domain and fails (A2) at ½ (the proof needs ``g`` right-continuous in ``t``).
* ``assumption_A3`` — ``D(s,t) = max_z dist(z, dom F(t))`` over sampled ``z ∈ dom F(s)`` (``project_domain``);
  the least nondecreasing ``φ̂`` with ``φ̂(t) - φ̂(s) ≥ D(s,t)`` on the sampled times is reported.  A stated
  ``problem.phi`` below a sample disproves it.  With or without a stated φ, a jump of φ̂ disproves (A3)
  (φ must be absolutely continuous): the jumps of the projections ``t ↦ proj_{dom F(t)} p`` are searched
  adaptively as for (A2), and one across which ``D(a, b)`` stays above tolerance (stalled) fails, with
  its time and size.
* ``assumption_LG`` — ``σ̂(t) = max |F^0(t,z)|/(1 + |z|)``; a stated ``problem.sigma`` below a sample is
  disproved; without one, growth of the ratio by more than ``GROWTH_FLAG`` as ``λ`` (and with it ``z``'s
  distance to the boundary of the domain) shrinks 1000-fold is reported as evidence that (LG) fails.
* ``assumption_YB`` — ``D_λ(s) = |Y_λ(s+λ, z)| - |F^0(s, z)|`` (YB) and ``|Y_λ(s+λ, z)| - |Y_λ(s, z)|``
  (YB'); the estimate ``θ̂(t) = ρ t`` with ``ρ = max D/λ``; a stated ``problem.theta`` with
  ``θ(s+λ) - θ(s) < D`` is disproved; ``ρ(λ)`` growing like ``1/λ`` is evidence that (YB) fails (a moving
  domain: ``|Y_λ(s+λ, z)| ≈ dist(z, dom F(s+λ))/λ``).

Status ``passed`` means "no sample contradicts the assumption" (the message and ``details["evidence"]``
say so); ``failed`` means a sample contradicts it (or the stated function) or the growth evidence above.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ..core.errors import OutsideDomain
from ..core.operators import resolvent_rows
from ..core.problem import Problem
from ..records.results import FAILED, PASSED, SKIPPED, UNDECIDED, XFAIL, XFAIL_DECLARED, CheckResult, Report
from .arguments import valid_seed
from .core import Outcome, law, laws_of, run, subject_name
from .subjects import require_problem
from ..core.tolerances import GROWTH_FLAG, RTOL, STALL_RATIO, STALL_WINDOW, quotient_tolerance, tolerance
from .jumps import JUMP_GRID, base_grid, find_jumps, jump_time
from .over_time import Sup, sup_over_time

EVIDENCE = "evidence from samples, not a proof"
#: (A2): right limits t + δ_k, δ_k = (T - t) A2_RATIO^k for k = 0, ..., A2_LEVELS (down to 1.5e-5 (T - t))
A2_LEVELS = 8
A2_RATIO = 0.25
#: (A2): a sequence J_λ(t+δ_k) p whose last two differences shrink by less than this factor has not
#: settled: its limit cannot be extrapolated, so it is no evidence either way
A2_SETTLED = 0.9
#: (A2): the geometric tail is an estimate (the ratio of the differences drifts when the active set
#: changes along the sequence: it fell 0.3% short on the moving box), so it is doubled; a jump leaves an
#: O(1) gap after a constant sequence, so the factor costs no power against real violations
A2_TAIL_SAFETY = 2.0
#: (A2): step sizes λ (relative to T) of the sampled resolvents (the points p already span two scales)
A2_LAMBDAS = (1e-1,)
#: (A2): what a jump whose side cannot be decided is recorded as (see :func:`check_assumption_A2`)
UNDECIDED_SIDE = ("undecided: neither end of the bracket has the shorter decimal; the right-limit test fails at "
                  "a and passes at b for every jump between adjacent floats, whichever side it is on")
#: step sizes λ (relative to T) used to reach points of dom F(t,·) ever closer to its boundary
LAMBDAS = (1.0, 1e-1, 1e-2, 1e-3)


class _Samples:
    def __init__(self, problem: Problem, seed: int, points: int, times: int) -> None:
        rng = np.random.default_rng(seed)
        x0 = problem.x0[0] if problem.batched else problem.x0
        self.problem, self.op, self.T = problem, problem.operator, problem.T
        r = 1.0 + float(np.linalg.norm(x0))
        base = rng.standard_normal((points, problem.dim))
        scales = np.where(np.arange(points) % 2 == 0, 1.0, 3.0)[:, None] * r
        self.points = np.vstack([x0[None, :], x0 + scales * base / np.linalg.norm(base, axis=1, keepdims=True)])
        self.times = np.linspace(0.0, problem.T, times)
        self.lambdas = [lam * problem.T for lam in LAMBDAS]

    def graph(self, t: float, lam: float):
        """``(z, y, p)`` with ``z = J_λ p ∈ dom F(t)``, ``y = Y_λ p ∈ F(t, z)``."""
        J = resolvent_rows(self.op, self.points, lam, t)
        return J, (self.points - J) / lam, self.points


def _min_norm(op, z, t):
    try:
        return np.asarray(op.min_norm(z, t), dtype=float)
    except OutsideDomain:
        return None


def _sampled(name: str, worst: float, counter: dict | None, details: dict, failed: Callable[[dict], str],
             passed: str) -> Outcome:
    """The outcome of a sampled ratio ``worst`` against the bound 1: ``failed(counter)`` is the message when
    a sample exceeds it (or the ratio is not a number), ``passed`` otherwise."""
    out = Outcome(float(worst), counter=dict(counter or {}), details=details, message=passed)
    if out.failed:
        out.counter["message"] = failed(counter) if counter else f"{name}: the sampled ratio is {worst}"
    return out


def _growth(growth: float, evidence: dict, details: dict, failed: str, passed: str) -> Outcome:
    """The evidence-from-growth outcome of (LG) and (YB) without a stated function: a sampled ratio growing
    more than ``GROWTH_FLAG``-fold as ``λ`` shrinks 1000-fold is evidence the bound fails."""
    if growth > GROWTH_FLAG:
        return Outcome(growth, bound=GROWTH_FLAG, counter={**evidence, "message": failed}, details=details)
    return Outcome(None, status=PASSED, details=details, message=passed)


def run_assumption(decl: Any, problem: Problem, *, seed: int = 0, points: int = 12, times: int = 7) -> CheckResult:
    """An assumption's law on ``problem``: its evaluator on the samples of ``seed`` (``points`` points around
    ``x0``, ``times`` times in ``[0, T]``)."""
    require_problem(problem)
    samples = _Samples(problem, seed, points, times)
    return run(decl, subject_name(problem), lambda: decl.evaluate(samples), problem=problem, seed=seed)


@law("assumption_A1", "(A1)", subject="problem", driver=run_assumption)
def check_assumption_A1(S: _Samples) -> Outcome:
    """(A1): monotonicity ``⟨z1 - z2, y1 - y2⟩ ≥ 0`` on sampled graph pairs of ``F(t,·)`` (resolvent pairs
    ``(J_λ p, Y_λ p)`` and ``(z, F^0(z))``).  A violation disproves (A1)."""
    worst, counter, pairs = -np.inf, None, 0
    for t in S.times:
        Z, Y, P = [], [], []
        for lam in S.lambdas:
            z, y, p = S.graph(float(t), lam)
            Z.append(z), Y.append(y), P.append(np.abs(p).max(axis=1) / lam)
        try:   # minimal sections at the sampled domain points
            z = np.vstack(Z)
            f0 = [_min_norm(S.op, zi, float(t)) for zi in z]
            keep = [i for i, v in enumerate(f0) if v is not None]
            Z.append(z[keep]), Y.append(np.array([f0[i] for i in keep]).reshape(-1, S.problem.dim))
            P.append(np.abs(Y[-1]).max(axis=1) if keep else np.zeros(0))
        except NotImplementedError:
            pass
        Z, Y, P = np.vstack(Z), np.vstack(Y), np.concatenate(P)
        i, j = np.triu_indices(len(Z), 1)
        dz, dy = Z[i] - Z[j], Y[i] - Y[j]
        inner = np.sum(dz * dy, axis=1)
        nz, ny = np.linalg.norm(dz, axis=1), np.linalg.norm(dy, axis=1)
        tol = RTOL * (nz * (1.0 + np.maximum(P[i], P[j])) + ny * (1.0 + np.maximum(np.abs(Z[i]).max(1),
                                                                                      np.abs(Z[j]).max(1))))
        ratio = -inner / (tol + 1e-300)
        pairs += len(i)
        m = int(np.argmax(ratio))
        if ratio[m] > worst:
            worst = float(ratio[m])
            counter = {"t": t, "z1": Z[i[m]], "y1": Y[i[m]], "z2": Z[j[m]], "y2": Y[j[m]], "inner": inner[m]}
    return _sampled("assumption_A1", max(worst, 0.0), counter, {"evidence": EVIDENCE, "pairs": pairs},
                    lambda c: f"<z1 - z2, y1 - y2> = {c['inner']:.3g} < 0 for graph points of F(t = {c['t']:.4g})",
                    f"no non-monotone pair among {pairs} sampled graph pairs ({EVIDENCE})")


def _limit_gap(q: np.ndarray, target: np.ndarray) -> tuple[float, float]:
    """``(|q_K - target|, tail)`` for a sequence ``q_0, ..., q_K`` (rows of ``q``): ``tail`` estimates
    ``|q_∞ - q_K|`` by ``A2_TAIL_SAFETY`` times the geometric series with the larger ratio of the last
    three differences (``inf`` when they do not shrink by ``A2_SETTLED``; ``0`` when the sequence is
    constant at its end)."""
    d = np.linalg.norm(np.diff(q[-4:], axis=0), axis=1)     # the last three differences
    if d[-1] == 0.0:
        tail = 0.0
    elif d[-2] == 0.0 or d[-3] == 0.0 or max(d[-1] / d[-2], d[-2] / d[-3]) > A2_SETTLED:
        tail = np.inf
    else:
        r = max(d[-1] / d[-2], d[-2] / d[-3])
        tail = A2_TAIL_SAFETY * float(d[-1]) * r / (1.0 - r)
    return float(np.linalg.norm(q[-1] - target)), tail


def _right_limit(S: _Samples, t: float, lam: float, P: np.ndarray | None = None):
    """``(worst ratio, counterexample, sequences, unsettled)`` of the right-limit test at ``t``: the
    sequences ``J_λ(t + δ_k) p`` against ``J_λ(t) p`` (module docstring)."""
    P = S.points if P is None else P
    deltas = (S.T - t) * A2_RATIO ** np.arange(A2_LEVELS + 1)
    Q = np.stack([resolvent_rows(S.op, P, lam, t + d) for d in deltas], axis=1)   # (P, D, n)
    AT = resolvent_rows(S.op, P, lam, t)
    worst, counter, sequences, unsettled = 0.0, None, 0, 0
    for p, q, at_t in zip(P, Q, AT):
        gap, tail = _limit_gap(q, at_t)
        sequences += 1
        if not np.isfinite(tail):
            unsettled += 1
            continue
        ratio = max(gap - tail, 0.0) / tolerance(p, q[-1], at_t)
        if ratio > worst:
            worst, counter = ratio, {"t": t, "lam": lam, "p": p, "delta": deltas[-1], "limit": q[-1],
                                     "resolvent_at_t": at_t, "gap": gap, "tail": tail}
    return worst, counter, sequences, unsettled


@law("assumption_A2", "(A2)", subject="problem", driver=run_assumption)
def check_assumption_A2(S: _Samples) -> Outcome:
    """(A2): outer semicontinuity from the right of ``t ↦ graph F(t,·)``: a settled right limit
    ``lim J_λ(t+δ) p`` equals ``J_λ(t) p`` at the sampled times and at every jump of ``t ↦ J_λ(t) p`` found
    between them (:func:`verimono.checks.jumps.find_jumps`).

    A jump bracketed by adjacent floats ``a < b`` happens at :func:`~verimono.checks.jumps.jump_time`: if that
    is ``a`` (``J_λ(a) p`` is the left value, the right limit the other one) the right-limit test there
    fails, if ``b`` the jump is right-continuous and (A2) holds there.  When neither end has the shorter
    decimal the jump is **undecided**, never passed: the right-limit test fails at ``a`` and passes at ``b``
    for *every* jump so bracketed (no float lies between them, so ``J_λ(a + δ) p`` is the right value for
    every ``δ > 0`` and ``J_λ(a) p`` the left one), so testing both ends tells nothing; and the two readings
    — switch right after ``a`` ((A2) fails: ``c = 1`` for ``t ≤ τ``) or at ``b`` ((A2) holds: ``c = 1`` for
    ``t < τ``) — are the same function of floats, which is all verimono can evaluate.  The record is then
    ``undecided`` (unless another test failed), with the brackets."""
    T = S.T
    worst, counter, sequences, unsettled = 0.0, None, 0, 0
    for t in S.times[:-1]:
        for lam in (rel * T for rel in A2_LAMBDAS):
            w, c, n, u = _right_limit(S, float(t), lam)
            sequences, unsettled = sequences + n, unsettled + u
            if w > worst:
                worst, counter = w, c
    lam = A2_LAMBDAS[0] * T
    jumps, searched = find_jumps(lambda t: resolvent_rows(S.op, S.points, lam, t), T)
    found, undecided = [], []
    for j in jumps:
        tj = jump_time(j)
        entry = {"bracket": [j.a, j.b], "size": j.size, "t": tj}
        if tj is None:
            entry["side"] = UNDECIDED_SIDE
            undecided.append(entry)
        elif tj >= T:
            entry["side"] = "at T (no right limit)"
        else:
            entry["side"] = "left value at t (jump right after t)" if tj == j.a else "right-continuous"
            w, c, _, _ = _right_limit(S, tj, lam)
            if w > worst:
                worst, counter = w, dict(c, found_by="jump search", jump=j.size, bracket=[j.a, j.b])
        found.append(entry)
    details = {"evidence": EVIDENCE, "sequences": sequences, "unsettled": unsettled, "jumps": found,
               "jump_search": searched, "undecided_jumps": len(undecided)}
    if undecided and not worst > 1.0:
        u = undecided[0]
        return Outcome(None, status=UNDECIDED, details=details,
                       message=f"{len(undecided)} jump(s) of t ↦ J_λ(t) p found whose side cannot be decided: the first "
                               f"between the adjacent floats {u['bracket'][0]!r} and {u['bracket'][1]!r} (size "
                               f"{u['size']:.3g}); (A2) fails there if the switch is right after the first and holds "
                               "if it is at the second, and in floating point both are the same function (the "
                               "right-limit test fails at the first end and passes at the second for every jump so "
                               f"bracketed) — undecided, never a pass; no other test failed ({EVIDENCE})")
    return _sampled(
        "assumption_A2", worst, counter, details,
        lambda c: (f"J_λ(t+δ) p → {np.array2string(c['limit'], precision=4)} as δ ↓ 0 but J_λ(t) p = "
                   f"{np.array2string(c['resolvent_at_t'], precision=4)} (gap {c['gap']:.3g}, tail ≤ "
                   f"{c['tail']:.3g}; t = {c['t']!r}, λ = {c['lam']:.3g}"
                   + (f"; a jump found between sample times, bracket [{c['bracket'][0]!r}, {c['bracket'][1]!r}]"
                      if c.get("found_by") else "")
                   + "): t ↦ graph F(t,·) is not outer semicontinuous from the right"),
        f"every settled right limit lim J_λ(t+δ) p equals J_λ(t) p ({sequences - unsettled} of {sequences} "
        f"sequences settled at the sample times; {len(found)} jump(s) of J_λ found between them, none with the "
        f"left value at its time; {EVIDENCE})")


@law("assumption_A3", "(A3)", subject="problem", driver=run_assumption)
def check_assumption_A3(S: _Samples) -> Outcome:
    """(A3): ``sup_{z ∈ dom F(s)} dist(z, dom F(t)) ≤ φ(t) - φ(s)``: the least nondecreasing ``φ̂`` of the
    sampled domain motion, compared with a stated ``φ``; a jump of the domain fails it (φ must be absolutely
    continuous)."""
    op, ts = S.op, S.times
    n = len(ts)
    D = np.zeros((n, n))
    arg: dict[tuple[int, int], Any] = {}
    for a in range(n):
        Z = np.array([op.project_domain(p, float(ts[a])) for p in S.points])
        for b in range(a + 1, n):
            Q = np.array([op.project_domain(z, float(ts[b])) for z in Z])
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
    sup, c = _phi_sup(S)
    details["sup_search"] = sup.as_dict()
    if sup.value > worst:
        worst, counter = sup.value, c
    return _sampled("assumption_A3", worst, counter, details,
                    lambda c: f"dist(z, dom F(t)) = {c['dist']:.4g} > φ(t) - φ(s) = {c['phi_t'] - c['phi_s']:.4g} "
                              f"for z in dom F(s), s = {c['s']!r}, t = {c['t']!r}"
                              + (" (found by the search over time)" if c.get("found_by") else "")
                              + ": the stated φ is contradicted",
                    f"stated φ bounds every sampled domain motion: at {n} sample times, and on windows of length "
                    f"T/{JUMP_GRID} searched over time ({sup.evaluations} windows; largest ratio {sup.value:.3g} at "
                    f"s = {sup.t:.4g}) ({EVIDENCE})")


def _phi_ratio(dist: float, phi_s: float, phi_t: float) -> float:
    """``dist / (φ(t) − φ(s) + tol)``; at least 2 when ``φ`` decreases (not allowed by (A3))."""
    rhs = phi_t - phi_s
    r = dist / (max(rhs, 0.0) + tolerance(dist, phi_s, phi_t))
    if rhs < -tolerance(phi_s, phi_t):
        r = max(r, 2.0)
    return float(r)


def _phi_sup(S: _Samples) -> tuple[Sup, dict]:
    """The stated φ against the domain motion on every window ``[s, s + w]``, ``w = T/JUMP_GRID``, searched
    over ``s`` (:func:`verimono.checks.over_time.sup_over_time`; families: the sample points)."""
    op, P, T, phi = S.op, S.points, S.T, S.problem.phi
    w = T / JUMP_GRID

    def one(i: int, s: float) -> tuple[float, dict]:
        t = min(s + w, T)
        z = np.asarray(op.project_domain(P[i], s), dtype=float)
        q = np.asarray(op.project_domain(z, t), dtype=float)
        d = float(np.linalg.norm(z - q))
        ps, pt = float(phi(s)), float(phi(t))
        return _phi_ratio(d, ps, pt), {"s": s, "t": t, "z": z, "dist": d, "phi_s": ps, "phi_t": pt}

    def values(s: float, which):
        return np.array([one(i, s)[0] for i in (range(len(P)) if which is None else which)])

    sup = sup_over_time(values, 0.0, T - w, grid=base_grid(T)[:-1])
    _, c = one(sup.family, sup.t)
    return sup, dict(c, found_by="search over time")


def _excess(S: _Samples, a: float, b: float) -> tuple[float, np.ndarray]:
    """``max_z dist(z, dom F(b))`` over the sampled ``z = proj_{dom F(a)} p``, and the maximiser."""
    Z = np.array([S.op.project_domain(p, a) for p in S.points])
    Q = np.array([S.op.project_domain(z, b) for z in Z])
    d = np.linalg.norm(Z - Q, axis=1)
    m = int(np.argmax(d))
    return float(d[m]), Z[m]


def _a3_jump(S: _Samples, details: dict) -> dict | None:
    """A jump of ``φ̂``: :func:`verimono.checks.jumps.find_jumps` on the projections ``t ↦ proj_{dom F(t)} p``
    (continuous when ``dom F`` moves continuously in the Hausdorff distance), then the excess of
    ``dom F(a)`` over ``dom F(b)`` on the final bracket: still above tolerance and stalled (≥ ``STALL_RATIO``
    times its value ``STALL_WINDOW`` bisections earlier) means ``φ(b) − φ(a) ≥ excess`` on ever shorter
    ``[a, b]``: no absolutely continuous φ (a domain that only grows jumps without violating (A3))."""
    jumps, searched = find_jumps(lambda t: np.array([S.op.project_domain(p, t) for p in S.points]), S.T)
    details["jump_search"] = searched
    details["domain_jumps"] = []
    for j in jumps:
        e, z = _excess(S, j.a, j.b)
        a0, b0 = j.brackets[max(len(j.brackets) - 1 - STALL_WINDOW, 0)]
        e0, _ = _excess(S, a0, b0)
        tol = tolerance(z, e)
        details["domain_jumps"].append({"t": j.time, "bracket": [j.a, j.b], "projection_jump": j.size, "excess": e})
        if e > tol and e >= STALL_RATIO * e0:
            tj = jump_time(j)
            return {"t": j.time if tj is None else tj, "bracket": [j.a, j.b], "excess": e, "excess_earlier": e0,
                    "earlier_bracket": [a0, b0], "z": z, "worst": e / tol, "projection_increments": j.increments}
    return None


def _f0_norm(op, z, t, mu):
    """``|F^0(t, z)|``, or the lower estimate ``|Y_μ z|`` when the operator has no ``min_norm``."""
    try:
        v = _min_norm(op, z, t)
        return None if v is None else float(np.linalg.norm(v)), "min_norm"
    except NotImplementedError:
        return float(np.linalg.norm(op.yosida(z, mu, t))), "yosida lower estimate"


@law("assumption_LG", "(LG)", subject="problem", driver=run_assumption)
def check_assumption_LG(S: _Samples) -> Outcome:
    """(LG): ``|F^0(t, z)| ≤ σ(t)(1 + |z|)``: the estimated ``σ̂`` against a stated ``σ``, or, without one,
    growth of the sampled ratio as ``z`` nears the boundary of the domain (evidence that (LG) fails)."""
    op, sigma = S.op, S.problem.sigma
    by_lam = {}
    worst, counter, how = 0.0, None, "min_norm"
    sig_hat = np.zeros(len(S.times))
    for lam in S.lambdas:
        best = 0.0
        for ti, t in enumerate(S.times):
            z_all, _, _ = S.graph(float(t), lam)
            for z in z_all:
                val, how = _f0_norm(op, z, float(t), 1e-6 * S.T)
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
    growth = by_lam[lams[-1]] / max(by_lam[lams[0]], 1e-12) if by_lam[lams[-1]] > 1e-9 else 1.0
    details = {"evidence": EVIDENCE, "times": S.times, "sigma_hat": sig_hat, "sup_ratio_by_lambda": by_lam,
               "growth": growth, "F0": how, "stated": sigma is not None}
    if sigma is not None:
        sup, c = _sigma_sup(S)
        details["sup_search"] = sup.as_dict()
        if sup.value > worst:
            worst, counter = sup.value, c
        return _sampled("assumption_LG", worst, counter, details,
                        lambda c: f"|F^0(t,z)| = {c['F0_norm']:.4g} > σ(t)(1 + |z|) = "
                                  f"{c['sigma_t'] * (1 + np.linalg.norm(c['z'])):.4g} at t = {c['t']!r}"
                                  + (" (found by the search over time)" if c.get("found_by") else "")
                                  + ": the stated σ is contradicted",
                        f"stated σ bounds every sample, at {len(S.times)} sample times and searched over time "
                        f"({sup.evaluations} times; largest ratio {sup.value:.3g} at t = {sup.t:.4g}) ({EVIDENCE})")
    return _growth(growth, {"sup_ratio_by_lambda": by_lam}, details,
                   f"sup |F^0(t,z)|/(1+|z|) grows {growth:.3g}-fold as z approaches the boundary of dom F: evidence "
                   "that (LG) fails",
                   f"estimated σ̂ ≤ {float(np.max(sig_hat)):.4g} ({EVIDENCE}; F^0 by {how})")


def _sigma_sup(S: _Samples) -> tuple[Sup, dict]:
    """The stated σ against ``|F^0(t, z)|/(1 + |z|)`` searched over ``t`` (families: the sampled ``z =
    J_λ(t) p``, one per point ``p`` and step ``λ``)."""
    op, P, sigma, lams = S.op, S.points, S.problem.sigma, S.lambdas
    mu = 1e-6 * S.T

    def ratio(z: np.ndarray, t: float) -> tuple[float, dict | None]:
        val, _ = _f0_norm(op, z, t, mu)
        if val is None:
            return -np.inf, None
        sig = float(sigma(t))
        rhs = sig * (1.0 + float(np.linalg.norm(z)))
        return val / (rhs + tolerance(rhs, val)), {"t": t, "z": z, "F0_norm": val, "sigma_t": sig}

    def values(t: float, which):
        if which is None:
            return np.array([ratio(z, t)[0] for lam in lams for z in resolvent_rows(op, P, lam, t)])
        out = []
        for f in which:
            li, pi = divmod(int(f), len(P))
            out.append(ratio(resolvent_rows(op, P[pi:pi + 1], lams[li], t)[0], t)[0])
        return np.array(out)

    sup = sup_over_time(values, 0.0, S.T)
    li, pi = divmod(sup.family, len(P))
    _, c = ratio(resolvent_rows(op, P[pi:pi + 1], lams[li], sup.t)[0], sup.t)
    return sup, dict(c or {"t": sup.t, "z": P[pi], "F0_norm": np.nan, "sigma_t": np.nan}, lam=lams[li],
                     found_by="search over time")


def _theta_sup(S: _Samples, key: str) -> tuple[Sup, dict]:
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
        v = _min_norm(op, z, s)
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

    sup = sup_over_time(values, 0.0, T - min(lams), bounds=lambda f: (0.0, T - lams[f // nP]))
    _, c = one(sup.family, sup.t)
    return sup, dict(c or {"form": key, "s": sup.t, "lambda": lams[sup.family // nP], "z": P[sup.family % nP],
                           "lhs": np.nan, "rhs": np.nan}, found_by="search over time")


@law("assumption_YB", "(YB)/(YB')", subject="problem", driver=run_assumption)
def check_assumption_YB(S: _Samples) -> Outcome:
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
            Z = resolvent_rows(op, S.points, 0.1 * T, s)  # z ∈ dom F(s)
            for z in Z:
                y_next = float(np.linalg.norm(op.yosida(z, lam, s + lam)))
                y_now = float(np.linalg.norm(op.yosida(z, lam, s)))
                tol = quotient_tolerance(lam, z)
                cands = {"YB'": y_next - y_now}
                if has_f0:
                    try:
                        f0 = _min_norm(op, z, s)
                        if f0 is not None:
                            cands["YB"] = y_next - float(np.linalg.norm(f0))
                    except NotImplementedError:
                        has_f0 = False
                for key, d in cands.items():
                    rates[lam][key] = max(rates[lam][key], d / lam)
                    if theta is not None:
                        rhs = float(theta(s + lam)) - float(theta(s))
                        q = d / (max(rhs, 0.0) + tol) if d > 0 else 0.0
                        if q > worst[key]:
                            worst[key] = q
                            counter[key] = {"form": key, "s": s, "lambda": lam, "z": z, "lhs": d, "rhs": rhs}
    lams = sorted(rates, reverse=True)
    key = "YB" if has_f0 else "YB'"
    small, big = rates[lams[-1]][key], rates[lams[0]][key]
    growth = small / max(big, 1e-12) if small > 1e-9 else 1.0
    rho = max(r[key] for r in rates.values())
    details = {"evidence": EVIDENCE, "rate_by_lambda": rates, "theta_hat_slope": rho, "growth": growth,
               "form": key, "stated": theta is not None}
    if theta is not None:
        sup, c = _theta_sup(S, key)
        details["sup_search"] = sup.as_dict()
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
        return _sampled("assumption_YB", worst[key], counter[key], details,
                        lambda c: f"{c['form']}: |Y_λ(s+λ,z)| exceeds θ(s+λ) - θ(s) + ... by "
                                  f"{c['lhs'] - c['rhs']:.3g} at s = {c['s']!r}, λ = {c['lambda']:.3g}"
                                  + (" (found by the search over time)" if c.get("found_by") else "")
                                  + ": the stated θ is contradicted",
                        f"stated θ bounds every sampled Yosida increment, at {len(S.times)} sample times and "
                        f"searched over s ({sup.evaluations} times; largest ratio {sup.value:.3g} at s = "
                        f"{sup.t:.4g}) ({key}; {EVIDENCE})")
    return _growth(growth, {"rate_by_lambda": rates}, details,
                   f"the Yosida increment per unit time grows {growth:.3g}-fold as λ shrinks 1000-fold (like 1/λ: a "
                   f"moving domain): evidence that ({key}) fails",
                   f"estimated θ̂(t) = {rho:.4g} t ({key}; {EVIDENCE})")


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
