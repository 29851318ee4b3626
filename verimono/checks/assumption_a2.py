"""(A2), outer semicontinuity from the right of ``t ↦ graph F(t,·)``, through resolvents.

If ``q = lim J_λ(t+δ) p`` exists as ``δ ↓ 0``, then ``(q, (p - q)/λ)`` is a limit of graph points of
``F(t+δ)``, so (A2) puts it in ``graph F(t)`` and single-valuedness of the resolvent gives ``q = J_λ(t) p``.
More: *every* cluster point of ``J_λ(t+δ) p`` is such a limit, so under (A2) the sequence converges, to
``J_λ(t) p`` — a right limit that does not settle (``c(t) = 1.5 + 0.5 sin(1/(t − τ))``) contradicts (A2)
as a wrong limit does.  (The Minty residual of the graph point ``(J_λ(t+δ)p, Y_λ(t+δ)p)`` with respect to
``graph F(t)`` is exactly ``√2 |J_λ(t+δ)p - J_λ(t)p|``.)

The right-limit test at ``t`` samples ``δ_k = (T − t) 4^{-k}``, ``k ≤`` :data:`A2_LEVELS`, extrapolates the
limit from the last differences (geometric tail), and fails when its distance from ``J_λ(t) p`` stays
above tolerance after subtracting the tail.  A sequence that has not settled there — its tail above the
tolerance, so that its limit is not pinned down to what is judged — is followed further, down to
``δ ≈ 10^{-13} T`` (:data:`A2_DEEP_LEVELS`): one that settles is judged as above; one whose values over the
last levels are still as far apart as over the first deep ones has **no limit** (failed, with its cluster
points' spread); one still shrinking, or known only to ± a tail above tolerance, leaves the record
**undecided**, never passed (two differences that shrink by chance once gave an oscillation a tail that
covered its gap).

Where it runs: the sample times; every jump of ``t ↦ J_λ(t) p`` (:mod:`verimono.checks.jumps`, bisected to
adjacent floats ``a < b``; the jump time is the end with the shorter decimal — ``t <= 0.45`` switches right
after 0.45 — and a jump whose side cannot be decided is undecided, see :func:`check_assumption_A2`); and the
point where ``t ↦ J_λ(t) p`` varies fastest — the sup over ``t`` of ``|J_λ(t + ε)p − J_λ(t)p|``
(:mod:`verimono.checks.engine.supremum`), then a zoom toward it (:func:`verimono.checks.engine.supremum.zoom`): an
oscillation like ``sin(1/(t − τ))`` is fastest near ``τ``, where the right limit fails to settle.
(A2) is *not* implied by (A3) for subdifferentials, whatever Lemma ``lem:A3ImpliesA2`` says: ``c(t)|x|`` with
``c = 1`` on ``[0, ½]``, 2 after, has a fixed domain and fails (A2) at ½ (the proof needs ``g``
right-continuous in ``t``).
"""

from __future__ import annotations

import numpy as np

from ..core.errors import UnverifiedSolution
from ..core.operators import resolvent_rows
from ..core.tolerances import tolerance
from ..records.results import UNDECIDED
from ..core.operator_protocol import accepts_times
from .assumption_samples import A2_LAMBDAS, EVIDENCE, on_times, run_assumption, sampled
from .core import Outcome, law
from .jumps import jump_time
from .engine.supremum import zoom
from .engine.times import search_time, searched_t

#: (A2): right limits t + δ_k, δ_k = (T - t) A2_RATIO^k for k = 0, ..., A2_LEVELS (down to 1.5e-5 (T - t))
A2_LEVELS = 8
A2_RATIO = 0.25
#: (A2): an unsettled sequence is followed down to δ = (T − t) 4^-A2_DEEP_LEVELS (about 2e-13 (T − t))
A2_DEEP_LEVELS = 21
#: (A2): the window of deep levels whose spread is compared (the last ones against the first deep ones)
A2_WINDOW = 6
#: (A2): a sequence J_λ(t+δ_k) p whose last two differences shrink by less than this factor has not
#: settled: its limit cannot be extrapolated
A2_SETTLED = 0.9
#: (A2): the spread of the last deep window at least this fraction of the first's: the values do not
#: approach each other over ~13 levels (a factor 7e7 in δ) — no limit (a Hölder-p function's spread falls
#: by 4^(-13p): to this fraction only for p < 0.03)
A2_NO_LIMIT = 0.5
#: (A2): the geometric tail is an estimate (the ratio of the differences drifts when the active set
#: changes along the sequence: it fell 0.3% short on the moving box), so it is doubled; a jump leaves an
#: O(1) gap after a constant sequence, so the factor costs no power against real violations
A2_TAIL_SAFETY = 2.0
#: (A2): the step of the speed |J_λ(t + ε)p − J_λ(t)p| searched for the fastest variation, relative to T
A2_SPEED_STEP = 1e-12
#: (A2): the right limit is tested at the points the zoom toward the fastest variation centred on last
A2_ZOOM_TESTS = 24
#: (A2): the zoom toward the fastest variation: probes per level, the bracket's shrink per level (slower
#: than halving: a probe whose phase hides the oscillation's envelope ``ε/|t − τ|²`` then loses no ground
#: for good), and the levels at most (from ``T/100``, 100 levels of 0.7 reach ``10^-17 T``)
A2_ZOOM_PROBES = 9
A2_ZOOM_SHRINK = 0.7
A2_ZOOM_LEVELS = 100
#: (A2): what a jump whose side cannot be decided is recorded as (see :func:`check_assumption_A2`)
UNDECIDED_SIDE = ("undecided: neither end of the bracket has the shorter decimal; the right-limit test fails at "
                  "a and passes at b for every jump between adjacent floats, whichever side it is on")


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


def _spread(q: np.ndarray) -> float:
    """The diameter of a set of points (rows)."""
    return float(max(np.linalg.norm(q[i] - q[j]) for i in range(len(q)) for j in range(i + 1, len(q))))


def _deep(S, p: np.ndarray, lam: float, t: float) -> tuple[np.ndarray, np.ndarray] | None:
    """``(δ, J_λ(t + δ) p)`` on the deep levels ``A2_LEVELS < k ≤ A2_DEEP_LEVELS`` that verimono's own solver
    verifies (a level it cannot verify is no evidence either way and is left out: the Example's LCP is all
    but infeasible near ``v = 10^-8``); ``None`` unless the last four levels, where the tail is read, are
    verified, and :data:`A2_WINDOW` levels in all, whose spread is read."""
    dd = (S.T - t) * A2_RATIO ** np.arange(A2_LEVELS + 1, A2_DEEP_LEVELS + 1)
    dd = dd[t + dd > t]
    if accepts_times(S.op) and len(dd) >= A2_WINDOW:    # every level in one call, each as its own call gives it
        try:
            return dd, on_times(S.op, p[None, :], lam, t + dd)[:, 0]
        except UnverifiedSolution:      # a level verimono cannot verify: the levels one by one, as below
            pass
    kept, values = [], []
    for k, d in enumerate(dd):
        try:
            values.append(np.asarray(S.op.resolvent(p.copy(), lam, t + d), dtype=float))
            kept.append(k)
        except UnverifiedSolution:
            if k >= len(dd) - 4:        # the tail is read from the last four levels (_limit_gap)
                return None
    if len(kept) < A2_WINDOW:
        return None
    return dd[kept], np.array(values)


def right_limit(S, t: float, lam: float, P: np.ndarray | None = None):
    """``(worst ratio, counterexample, sequences, unsettled, no_limit)`` of the right-limit test at ``t``
    (module docstring): ``unsettled`` sequences still shrinking at the deepest level, ``no_limit`` the
    counterexample of one whose values do not approach each other (``None`` if none).  A sequence that has
    not settled, or whose limit looks wrong, at the first :data:`A2_LEVELS` levels is followed to the deep
    ones before it is judged (a point ``10^-6`` from the kink of ``t|x|`` moves only once ``λδ < 10^-6``)."""
    P = S.near if P is None else P
    deltas = (S.T - t) * A2_RATIO ** np.arange(A2_LEVELS + 1)
    if accepts_times(S.op):     # every level in one call, each row as its own call gives it
        Q = on_times(S.op, P, lam, t + deltas).transpose(1, 0, 2)
    else:
        Q = np.stack([resolvent_rows(S.op, P, lam, t + d) for d in deltas], axis=1)   # (P, D, n)
    AT = resolvent_rows(S.op, P, lam, t)
    worst, counter, sequences, unsettled, no_limit = 0.0, None, 0, 0, None
    for p, q, at_t in zip(P, Q, AT):
        gap, tail = _limit_gap(q, at_t)
        sequences += 1
        delta = float(deltas[-1])
        tol = tolerance(p, q[-1], at_t)
        window_start = None
        # a tail above tolerance leaves the limit open by more than what is judged: follow the sequence down
        if not tail <= tol or gap - tail > tol:
            deep = _deep(S, p, lam, t)
            if deep is not None:
                dd, D = deep
                q = np.vstack([q, D])
                delta, window_start = float(dd[-1]), float(dd[-A2_WINDOW])
                gap, tail = _limit_gap(q, at_t)
                tol = tolerance(p, q[-1], at_t)
                s_last = _spread(q[-A2_WINDOW:])
                if not tail <= tol and s_last <= tol:   # settled within tolerance (its round-off at the end)
                    tail = s_last
        if not np.isfinite(tail):
            first, last = q[A2_LEVELS:A2_LEVELS + A2_WINDOW], q[-A2_WINDOW:]
            if window_start is None:        # no deep levels (verimono's own solver could not verify them)
                unsettled += 1
                continue
            s_first, s_last = _spread(first), _spread(last)
            if s_last > 4 * tol and s_last >= A2_NO_LIMIT * s_first:
                ratio = s_last / (4 * tol)
                if no_limit is None or ratio > no_limit["ratio"]:
                    no_limit = {"t": t, "lam": lam, "p": p, "spread": s_last, "spread_first_deep": s_first,
                                "deltas": [window_start, delta],
                                "resolvent_at_t": at_t, "last": q[-1], "ratio": ratio}
            else:
                unsettled += 1
            continue
        if tail > tol and not gap - tail > tol:     # converging, but its limit known only to ± tail > tolerance
            unsettled += 1
            continue
        ratio = max(gap - tail, 0.0) / tol
        if ratio > worst:
            worst, counter = ratio, {"t": t, "lam": lam, "p": p, "delta": delta, "limit": q[-1],
                                     "resolvent_at_t": at_t, "gap": gap, "tail": tail}
    return worst, counter, sequences, unsettled, no_limit


def _fastest(S, lam: float) -> tuple[list[float], int, dict]:
    """Where ``t ↦ J_λ(t) p`` varies fastest: the sup over ``t`` of ``|J_λ(t + ε)p − J_λ(t)p|`` (relative to
    ``1 + |p|``; families: the points; ``ε = A2_SPEED_STEP·T``), then a zoom toward it whose step shrinks
    with the bracket (``ε = 10^-4 w²``, at least 8 ulps of ``T``): near an oscillation like
    ``sin(1/(t − τ))`` the speed is ``≈ ε/|t − τ|²`` while ``ε ≪ |t − τ|²``, so each level moves toward ``τ``.
    Returns the points the zoom centred on (last first), the family, and what was searched."""
    T, P = S.T, S.near
    size = 1.0 + np.linalg.norm(P, axis=1)
    floor = 8 * np.finfo(float).eps * T

    def speed(t: float, rows, eps: float) -> np.ndarray:
        t2 = min(t + eps, T)
        d = resolvent_rows(S.op, P[rows], lam, t2) - resolvent_rows(S.op, P[rows], lam, t)
        return np.linalg.norm(d, axis=1) / size[rows]

    def values(t, which):
        return speed(t, list(range(len(P))) if which is None else list(which), A2_SPEED_STEP * T)

    def many(ts: np.ndarray, which) -> np.ndarray:
        """``values(t, which)`` at every time of ``ts``: the subject's calls as :func:`speed` makes them (all times
        in one call when the operator takes a time per row), the norms over all times at once (a time whose resolvent verimono's own solver cannot verify is NaN: the
        engine evaluates it again with ``values``)."""
        rows, eps = list(which), A2_SPEED_STEP * T
        if accepts_times(S.op):     # every time in one call, each row as a separate call gives it
            D = on_times(S.op, P[rows], lam, np.minimum(ts + eps, T)) - on_times(S.op, P[rows], lam, ts)
            return np.linalg.norm(D, axis=2) / size[rows]
        D = np.full((len(ts), len(rows), P.shape[1]), np.nan)
        for k, t in enumerate(ts.tolist()):
            try:
                D[k] = resolvent_rows(S.op, P[rows], lam, min(t + eps, T)) - resolvent_rows(S.op, P[rows], lam, t)
            except UnverifiedSolution:
                pass
        return np.linalg.norm(D, axis=2) / size[rows]

    values.many = many      # type: ignore[attr-defined]
    many.bound = np.inf     # type: ignore[attr-defined]  # a speed, no bound: every finite value is the law's
    sup = search_time(values, 0.0, T, design=S.design(), seed=S.seed)
    f = sup.family

    def probe(t: float, w: float) -> float:
        return float(speed(t, [f], max(1e-4 * w * w, floor))[0])

    if accepts_times(S.op):     # a zoom level's probes in one call each side, as :func:`speed` computes each
        def probes(ts: np.ndarray, w: float) -> np.ndarray:
            eps, rows = max(1e-4 * w * w, floor), [f]
            D = on_times(S.op, P[rows], lam, np.minimum(ts + eps, T)) - on_times(S.op, P[rows], lam, ts)
            return (np.linalg.norm(D, axis=2) / size[rows])[:, 0]
        probe.many = probes     # type: ignore[attr-defined]
    z = zoom(probe, 0.0, T, sup.at,
             2 * sup.searched.resolution, scaled=True, probes=A2_ZOOM_PROBES, shrink=A2_ZOOM_SHRINK,
             levels=A2_ZOOM_LEVELS)
    return z.points[::-1], f, {"speed_search": sup.as_dict(), "searched_t": searched_t(sup),
                               "zoom": {"at": z.at, "levels": len(z.widths), "evaluations": z.evaluations}}


@law("assumption_A2", "(A2)", subject="problem", driver=run_assumption, over=("t", "points"))
def check_assumption_A2(S) -> Outcome:
    """(A2): outer semicontinuity from the right of ``t ↦ graph F(t,·)``: every right limit
    ``lim J_λ(t+δ) p`` exists and equals ``J_λ(t) p`` at the sampled times, at every jump of ``t ↦ J_λ(t) p``
    found between them (:func:`verimono.checks.jumps.find_jumps`) and where it varies fastest (module
    docstring).

    A jump bracketed by adjacent floats ``a < b`` happens at :func:`~verimono.checks.jumps.jump_time`: if that
    is ``a`` (``J_λ(a) p`` is the left value, the right limit the other one) the right-limit test there
    fails, if ``b`` the jump is right-continuous and (A2) holds there.  When neither end has the shorter
    decimal the jump is **undecided**, never passed: the right-limit test fails at ``a`` and passes at ``b``
    for *every* jump so bracketed (no float lies between them, so ``J_λ(a + δ) p`` is the right value for
    every ``δ > 0`` and ``J_λ(a) p`` the left one), so testing both ends tells nothing; and the two readings
    — switch right after ``a`` ((A2) fails: ``c = 1`` for ``t ≤ τ``) or at ``b`` ((A2) holds: ``c = 1`` for
    ``t < τ``) — are the same function of floats, which is all verimono can evaluate.  The record is then
    ``undecided`` (unless another test failed), with the brackets.  So it is when a right limit has not
    settled at the deepest level and nothing failed."""
    T = S.T
    worst, counter, sequences, unsettled, no_limit = 0.0, None, 0, 0, None

    def test(t: float, lam: float, **found) -> None:
        nonlocal worst, counter, sequences, unsettled, no_limit
        w, c, n, u, nl = right_limit(S, t, lam)
        sequences, unsettled = sequences + n, unsettled + u
        if w > worst:
            worst, counter = w, dict(c, **found)
        if nl is not None and (no_limit is None or nl["ratio"] > no_limit["ratio"]):
            no_limit = dict(nl, **found)

    for t in S.times[:-1]:
        for lam in (rel * T for rel in A2_LAMBDAS):
            test(float(t), lam)
    lam = A2_LAMBDAS[0] * T
    jumps, searched = S.jumps()
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
            test(tj, lam, found_by="jump search", jump=j.size, bracket=[j.a, j.b])
        found.append(entry)
    zoomed, fam, fast = _fastest(S, lam)
    t_fast = zoomed[0] if zoomed else T
    zoom_witness = False
    # the zoom's last distinct points: the nearest to what it chased (a zoom that stalled repeats its centre)
    for k, t in enumerate(list(dict.fromkeys(zoomed))[:A2_ZOOM_TESTS]):
        if t < T:
            w, c, n, u, nl = right_limit(S, t, lam, S.near[fam:fam + 1])
            sequences, unsettled = sequences + n, unsettled + u
            how = {"found_by": "the search for the fastest variation of t ↦ J_λ(t) p", "zoom_level_from_end": k}
            if w > worst:
                worst, counter = w, dict(c, **how)
            if nl is not None and not zoom_witness:     # the nearest to the singularity the zoom chased
                no_limit, zoom_witness = dict(nl, **how), True
    details = {"evidence": EVIDENCE, "sequences": sequences, "unsettled": unsettled, "jumps": found,
               "jump_search": searched, "undecided_jumps": len(undecided), "fastest": fast,
               "searched": {"t": fast["searched_t"], "x_range": S.x_range(), "lambda": [lam, lam]}}
    if no_limit is not None and not worst > no_limit["ratio"]:
        c = no_limit
        return Outcome(c["ratio"], details=details, counter={**c, "message": (
            f"J_λ(t+δ) p has no limit as δ ↓ 0 at t = {c['t']!r} (λ = {c['lam']:.3g}): its values for δ in "
            f"[{c['deltas'][1]:.2g}, {c['deltas'][0]:.2g}] are still {c['spread']:.3g} apart, as far as for the first "
            f"deep levels ({c['spread_first_deep']:.3g}); (A2) forces every cluster point to equal J_λ(t) p = "
            f"{np.array2string(np.asarray(c['resolvent_at_t']), precision=4)}: t ↦ graph F(t,·) is not outer "
            f"semicontinuous from the right ({EVIDENCE})")})
    if (undecided or unsettled) and not worst > 1.0:
        if undecided:
            u = undecided[0]
            why = (f"{len(undecided)} jump(s) of t ↦ J_λ(t) p found whose side cannot be decided: the first "
                   f"between the adjacent floats {u['bracket'][0]!r} and {u['bracket'][1]!r} (size "
                   f"{u['size']:.3g}); (A2) fails there if the switch is right after the first and holds "
                   "if it is at the second, and in floating point both are the same function (the "
                   "right-limit test fails at the first end and passes at the second for every jump so "
                   "bracketed)")
        else:
            why = (f"{unsettled} of {sequences} right-limit sequences J_λ(t+δ) p have not settled down to δ = "
                   f"(T − t)·4^-{A2_DEEP_LEVELS}: their limit, which (A2) needs to equal J_λ(t) p, cannot be "
                   "extrapolated")
        return Outcome(None, status=UNDECIDED, details=details,
                       message=f"{why} — undecided, never a pass; no other test failed ({EVIDENCE})")
    return sampled(
        "assumption_A2", worst, counter, details,
        lambda c: (f"J_λ(t+δ) p → {np.array2string(c['limit'], precision=4)} as δ ↓ 0 but J_λ(t) p = "
                   f"{np.array2string(c['resolvent_at_t'], precision=4)} (gap {c['gap']:.3g}, tail ≤ "
                   f"{c['tail']:.3g}; t = {c['t']!r}, λ = {c['lam']:.3g}"
                   + (f"; a jump found between sample times, bracket [{c['bracket'][0]!r}, {c['bracket'][1]!r}]"
                      if c.get("bracket") else "")
                   + (f"; found by {c['found_by']}" if c.get("found_by") and not c.get("bracket") else "")
                   + "): t ↦ graph F(t,·) is not outer semicontinuous from the right"),
        f"every right limit lim J_λ(t+δ) p exists and equals J_λ(t) p ({sequences} sequences: at the sample "
        f"times, at {len(found)} jump(s) of J_λ found between them, none with the left value at its time, and "
        f"at t = {t_fast:.6g}, where J_λ varies fastest; searched {fast['speed_search']['searched']['points']} "
        f"times to resolution {fast['speed_search']['searched']['resolution']:.3g}; {EVIDENCE})")


__all__ = ["check_assumption_A2", "right_limit", "UNDECIDED_SIDE", "A2_LEVELS", "A2_RATIO", "A2_DEEP_LEVELS",
           "A2_SETTLED", "A2_TAIL_SAFETY", "A2_NO_LIMIT"]
