"""Evidence for the hypotheses of Theorems ``thm: linear case`` and ``e: linear case-comp`` (Section 7), each a
decorated evaluator ``check_<law>(system, T, *, samples, seed) -> Outcome`` on a
:class:`verimono.lcs.LinearRelationSystem` (subject kind ``"system"``); :func:`check_hypotheses` is the
battery.  Records are labelled **evidence, not proof** where they rest on samples (times ``t``, points
``x``) rather than on an exact argument:

* ``lcs.passivity`` (item i): ``Σ(A,B,C,D)`` passive with storage ``½|x|²`` — the eigenvalue test of the KYP
  matrix ``Q(I)``; ``lcs.pass_D_psd`` and ``lcs.pass_kernel`` — Proposition ``p:pass`` i, ii with ``K = I``;
* ``lcs.relation_maxmon`` (item ii): exact for Complementarity/Relay (normal cones of boxes), sampled
  firm nonexpansiveness of the resolvent for an operator relation;
* ``lcs.rel_int`` (item iii / ``e: linear case-comp`` ii): ``im C ∩ ri(im(𝓜 + D) − v(t)) ≠ ∅`` on sampled
  ``t`` by linear programming (:func:`verimono.lcs.hypotheses.rel_int_margin`), then minimised over ``t``
  (:mod:`verimono.checks.over_time`);
* ``lcs.v_bounded`` (item iv): sup of ``|v|`` searched over ``t`` and zoomed into, growth toward a
  singularity detected (:mod:`verimono.checks.engine.supremum`); ``lcs.v_ac`` (``e: linear case-comp`` iii,
  ``v ∈ AC``): no jump — the largest increments of ``v`` must vanish when bisected (the search of
  :mod:`verimono.checks.jumps`) — and a settled total variation; a jump fails with its location;
* ``lcs.least_norm_growth`` (item vi, from Proposition ``p:lcp2`` iv–v for PSD ``D``): the least-norm
  multiplier ``z*`` of sampled unit ``q ∈ Q_D^+`` is homogeneous (``z*(sq) = s z*(q)``) and least-norm;
  ``|z*(q)| ≤ α|q|`` is checked against the explicit ``α = 1/λ_min((D + Dᵀ)/2)`` when that is positive, and
  otherwise ``α`` is only estimated from below by the samples (said so in the record);
* ``lcs.A1``, ``lcs.A2``, ``lcs.A3``, ``lcs.LG``: the main theorem's assumptions, passed when the items the
  Section 7 theorem derives them from passed, skipped (not established, with the items that did not pass
  and their status) otherwise — those items are sufficient conditions, so their failure refutes nothing.
  ``lcs.A2`` rests on ``lcs.v_ac`` too: its proof needs ``v(t_ℓ) → v(t)``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..core.errors import InvalidCheckArgument, VerimonoError
from ..lcs.hypotheses import rel_int_margin, sample_unit_q, shorter_solution
from ..lcs.lcp import is_psd, lcp_alpha, solve_lcp
from ..lcs.passivity import is_passive
from ..lcs.relations import BoxRelation, OperatorRelation
from ..records.results import PASSED, SKIPPED, CheckResult, Report
from ..core.tolerances import EPS, RTOL, STALL_WINDOW, tolerance
from .core import Outcome, law, laws_of, run, subject_name
from .jumps import find_jumps
from .over_time import sup_over_time
from .engine.supremum import Space, maximise, unbounded, zoom

EVIDENCE = "evidence from samples, not a proof"
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


def _horizon(T: Any) -> float:
    if isinstance(T, bool) or not isinstance(T, (int, float, np.integer, np.floating)) \
            or not math.isfinite(float(T)) or T <= 0:
        raise InvalidCheckArgument(f"check_hypotheses needs a finite horizon T > 0, got {T!r}")
    return float(T)


def _samples(samples: Any) -> int:
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
        raise InvalidCheckArgument(f"samples must be a positive integer, got {samples!r}")
    return int(samples)


def run_system_law(decl: Any, system: Any, T: float, *, samples: int = 64, seed: int = 0) -> CheckResult:
    """A Section 7 law on ``system`` over ``[0, T]`` (``samples`` sampled times or points, seeded)."""
    T, samples = _horizon(T), _samples(samples)
    return run(decl, subject_name(system), lambda: decl.evaluate(system, T, samples=samples, seed=seed))


def system_law(name: str, label: str) -> Any:
    return law(name, label, subject="system", driver=run_system_law)


def _verdict(ok: bool, message: str, worst: float | None = None, bound: float | None = 1.0, **kw: Any) -> Outcome:
    """An outcome decided by ``ok`` (the ratio ``worst`` against ``bound`` is reported, not judged)."""
    counter = kw.pop("counter", None) or {}
    return Outcome(worst, bound=bound, status=PASSED if ok else "failed", message=message,
                   counter={**counter, "message": message}, **kw)


# -- item i: passivity ------------------------------------------------------------------------------

@system_law("lcs.passivity", "thm: linear case i")
def check_passivity(system: Any, T: float, *, samples: int, seed: int) -> Outcome:
    """Theorem ``thm: linear case`` i: ``Σ(A, B, C, D)`` passive with storage ``½|x|²`` (``K = I``): the
    eigenvalue test of the KYP matrix ``Q(I)``."""
    p = is_passive(system.A, system.B, system.C, system.D, K=np.eye(system.n))
    return _verdict(p.passive, f"Theorem thm: linear case i (K = I): {p.message}", -p.margin, p.tol)


@system_law("lcs.pass_D_psd", "p:pass i")
def check_pass_d_psd(system: Any, T: float, *, samples: int, seed: int) -> Outcome:
    """Proposition ``p:pass`` i: ``D + Dᵀ ⪰ 0``."""
    p = is_passive(system.A, system.B, system.C, system.D, K=np.eye(system.n))
    return _verdict(p.D_psd, "Proposition p:pass i: D + Dᵀ ⪰ 0",
                    float(-np.linalg.eigvalsh(system.D + system.D.T)[0]), p.tol)


@system_law("lcs.pass_kernel", "p:pass ii")
def check_pass_kernel(system: Any, T: float, *, samples: int, seed: int) -> Outcome:
    """Proposition ``p:pass`` ii: ``(B − Cᵀ) ker(D + Dᵀ) = {0}`` (``K = I``)."""
    p = is_passive(system.A, system.B, system.C, system.D, K=np.eye(system.n))
    return _verdict(p.kernel_ok, "Proposition p:pass ii: (B − Cᵀ) ker(D + Dᵀ) = {0}", p.kernel_residual, p.tol)


# -- item ii: the relation ----------------------------------------------------------------------------

@system_law("lcs.relation_maxmon", "thm: linear case ii")
def check_relation_maxmon(system: Any, T: float, *, samples: int, seed: int) -> Outcome:
    """Theorem ``thm: linear case`` ii: the relation ``𝓜`` is maximal monotone — exact for Complementarity and
    Relay (normal cones of nonempty boxes); for an operator relation, firm nonexpansiveness of its resolvent
    on ``samples`` sampled pairs."""
    rel = system.relation
    if isinstance(rel, BoxRelation):
        return _verdict(True, f"{rel.name}: the normal cone of a nonempty box is maximal monotone (exact)")
    if not isinstance(rel, OperatorRelation):
        return Outcome(None, status=SKIPPED, message=f"a relation of type {type(rel).__name__} is not known here")
    rng = np.random.default_rng(seed)
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
    return _verdict(bad is None, f"resolvent firmly nonexpansive on {samples} sampled pairs ({EVIDENCE})",
                    float(worst), 0.0, counter=bad, details={"evidence": True})


# -- item iii: the relative interior ------------------------------------------------------------------

def _times(system: Any, T: float, samples: int) -> np.ndarray:
    return np.linspace(0.0, T, 17 if system.v_constant else max(17, samples))


@system_law("lcs.rel_int", "thm: linear case iii")
def check_rel_int(system: Any, T: float, *, samples: int, seed: int) -> Outcome:
    """Theorem ``thm: linear case`` iii (``e: linear case-comp`` ii): ``im C ∩ ri(im(𝓜 + D) − v(t)) ≠ ∅``
    for **every** ``t``, by linear programming: for a box relation with ``D + Dᵀ ⪰ 0``, ``im(𝓜 + D)`` is the
    linear image of a polyhedron, and the condition is a positive margin of an LP
    (:func:`verimono.lcs.hypotheses.rel_int_margin`).  The margin is computed at sampled ``t`` and then
    minimised over ``t`` (:func:`verimono.checks.over_time.sup_over_time` on the negated margin, refined to
    adjacent floats: a margin that touches 0 at one time, ``v = |t − 0.4567|``, is 0.0036 at the nearest of
    64 samples)."""
    ts = _times(system, T, samples)
    # the margin is a function of t alone: the search below starts on the same grid, each LP solved once
    known: dict[float, float | None] = {}

    def margin(t: float) -> float | None:
        out = known.get(t)
        if out is None:
            out = known[t] = rel_int_margin(system, t)
        return out

    margins = [margin(float(t)) for t in ts]
    if any(mg is None for mg in margins):
        return Outcome(None, status=SKIPPED, message="im(𝓜 + D) is known as a polyhedron only for box relations "
                                                     "with D + Dᵀ ⪰ 0")
    details = {"evidence": True, "t": ts.tolist(), "margins": margins}
    worst_t, least = float(ts[int(np.argmin(margins))]), float(min(margins))
    if not system.v_constant:
        sup = sup_over_time(lambda t, which: np.array([-margin(float(t))]), 0.0, T, grid=ts,
                            refine=True, seed=seed)
        details["searched"] = {"t": sup.searched.as_dict()}
        details["min_search"] = sup.as_dict()
        if -sup.value < least:
            worst_t, least = sup.t, -sup.value
    how = (f"on {ts.size} sampled t (v is constant)" if system.v_constant else
           f"on {ts.size} sampled t and minimised over t ({details['min_search']['evaluations']} LPs, resolution "
           f"{details['searched']['t']['resolution']:.3g}: a loss on an interval of t narrower than that is outside "
           "what was searched, at one isolated time only if the margin dips toward it over a wider one)")
    return _verdict(least > tolerance(system.C, system.D),
                    f"im C ∩ ri(im(𝓜 + D) − v(t)) ≠ ∅ {how} by linear programming ({EVIDENCE}); smallest margin "
                    f"{least:.3g} at t = {worst_t!r}", -least, 0.0, details=details,
                    counter={"t": worst_t, "margin": least} if least <= tolerance(system.C, system.D) else None)


# -- item iv and e: linear case-comp iii: v ---------------------------------------------------------

def _v_on_grid(system: Any, T: float) -> tuple[np.ndarray, np.ndarray]:
    fine = np.linspace(0.0, T, AC_GRID + 1)
    return fine, np.array([system.v(float(t)) for t in fine])


@system_law("lcs.v_bounded", "thm: linear case iv")
def check_v_bounded(system: Any, T: float, *, samples: int, seed: int) -> Outcome:
    """Theorem ``thm: linear case`` iv: ``v`` bounded on ``[0, T]``.  The sup of ``|v|`` is searched over
    ``t`` (:func:`verimono.checks.engine.supremum.maximise`: the :data:`AC_GRID` grid, a coverage grid, DIRECT and
    Brent), then zoomed into (:func:`verimono.checks.engine.supremum.zoom`, down to adjacent floats): a ``|v|`` still
    growing there (:func:`verimono.checks.engine.supremum.unbounded`: ``v = −1/|t − τ|`` doubles per halving) is
    unbounded and fails, as does a value that is not finite; a narrow spike settles at its height."""
    fine, V = _v_on_grid(system, T)
    if not np.all(np.isfinite(V)):
        i = int(np.flatnonzero(~np.all(np.isfinite(V.reshape(len(fine), -1)), axis=1))[0])
        return _verdict(False, f"v is not finite at t = {fine[i]!r} ({EVIDENCE})", details={"evidence": True},
                        counter={"t": float(fine[i])})
    def size(t: float) -> float:
        try:
            return float(np.max(np.abs(np.asarray(system.v(float(t)), dtype=float)), initial=0.0))
        except ArithmeticError:     # 1/0 at the singularity itself: |v| is infinite there
            return math.inf
    sup = maximise(lambda t, which: np.array([size(t)]), Space("t", 0.0, T), design=fine, seed=seed,
                   kind="time")
    z = zoom(size, 0.0, T, sup.at, 2 * sup.searched.resolution)
    grows = unbounded(z)
    details = {"evidence": True, "sup_search": sup.as_dict(), "zoom": z.as_dict(),
               "searched": {"t": sup.searched.as_dict(), "zoom_to": z.widths[-1] if z.widths else None}}
    top = max(sup.value, z.values[-1] if z.values else sup.value)
    if grows:
        msg = (f"|v| grows without bound toward t ≈ {z.at!r}: {z.values[-1]:.4g} on a bracket of width "
               f"{z.widths[-1]:.2g}, still growing as the bracket halves ({z.values[-1 - STALL_WINDOW]:.4g} "
               f"{STALL_WINDOW} halvings earlier) — v is not bounded ({EVIDENCE})")
        return _verdict(False, msg, top, None, details=details,
                        counter={"t": z.at, "v": z.values[-1], "widths": z.widths[-3:], "values": z.values[-3:]})
    return _verdict(True, f"sup |v| = {top:.4g} (at t = {z.at:.6g}), searched over t ({sup.searched.points} times, "
                          f"resolution {sup.searched.resolution:.3g}) and zoomed into down to width "
                          f"{z.widths[-1] if z.widths else 0:.2g}, where it settles ({EVIDENCE})",
                    top, None, details=details)


@system_law("lcs.v_ac", "e: linear case-comp iii")
def check_v_ac(system: Any, T: float, *, samples: int, seed: int) -> Outcome:
    """Theorem ``e: linear case-comp`` iii, ``v ∈ AC``: continuity and bounded variation of ``v``.

    *Continuity*: the jump search of :mod:`verimono.checks.jumps` on ``v`` (:data:`AC_GRID` intervals,
    :data:`AC_CANDIDATES` candidates of each kind, brackets split down to width ``AC_FLOOR·ε·T``): on a
    continuous ``v`` the increment goes to 0, across a jump of size ``J`` it stays ``≥ J`` and is reported
    with its location.  *Bounded variation*: the grid total variation on the last two dyadic grids settles
    (relative change ≤ ``TV_SETTLE``).  Evidence, not proof (a Cantor-like ``v`` passes both)."""
    fine, V = _v_on_grid(system, T)
    if not np.all(np.isfinite(V)):
        return _verdict(False, "v is not finite on the sample grid", details={"evidence": True})
    levels = [AC_GRID // 8, AC_GRID // 4, AC_GRID // 2, AC_GRID]
    largest = [float(np.linalg.norm(np.diff(V[::AC_GRID // k], axis=0), axis=1).max(initial=0.0)) for k in levels]
    min_width = AC_FLOOR * EPS * T
    jumps, searched = find_jumps(lambda t: np.asarray(system.v(t), float), T, grid=AC_GRID, shifts=0,
                                 candidates=AC_CANDIDATES, extrema=AC_CANDIDATES, min_width=min_width)
    jump = None
    if jumps:
        j = jumps[0]
        jump = {"t": j.time, "bracket": [j.a, j.b], "v_left": np.asarray(j.va).tolist(),
                "v_right": np.asarray(j.vb).tolist(), "jump": j.size, "increments": j.increments}
    tv = [float(np.sum(np.linalg.norm(np.diff(V[::s], axis=0), axis=1))) for s in (4, 2, 1)]
    settled = abs(tv[2] - tv[1]) <= max(TV_SETTLE * tv[2], tolerance(tv[2]))
    details = {"evidence": True, "largest_increment": dict(zip(map(str, levels), largest)), "total_variation": tv,
               "jump_search": searched}
    worst, bound = (jump["jump"], searched["floor"]) if jump is not None else (0.0, searched["floor"])
    if jump is not None:
        msg = (f"v jumps by {jump['jump']:.4g} at t ≈ {jump['t']:.9g}: |v(b) − v(a)| stays {jump['jump']:.4g} on "
               f"brackets [a, b] around it down to width {jump['bracket'][1] - jump['bracket'][0]:.2g} — v is not "
               f"continuous, let alone absolutely continuous ({EVIDENCE})")
    elif not settled:
        msg = f"grid total variation of v still grows under refinement: {tv} (unbounded variation?) ({EVIDENCE})"
        worst, bound = abs(tv[2] - tv[1]) / tv[2], TV_SETTLE
    else:
        msg = (f"largest increment of v on grids of {levels} intervals: {[f'{d:.3g}' for d in largest]}; "
               f"no jump in {searched['bisected']} candidate intervals bisected to width {min_width:.2g}; total "
               f"variation {tv[2]:.6g} settled ({EVIDENCE})")
    return _verdict(jump is None and settled, msg, worst, bound, details=details,
                    counter=jump if jump is not None else (None if settled else {"total_variation": tv}))


# -- item vi: growth of the least-norm multipliers ------------------------------------------------------

@system_law("lcs.least_norm_growth", "thm: linear case vi")
def check_least_norm_growth(system: Any, T: float, *, samples: int, seed: int) -> Outcome:
    """Theorem ``thm: linear case`` vi via Proposition ``p:lcp2`` iv–v.

    Bounded boxes: ``|Bz| ≤ ‖B‖ max|bounds| √m`` exactly.  Complementarity with ``D + Dᵀ ⪰ 0``: on sampled
    unit ``q ∈ Q_D^+`` the least-norm solution ``z*`` of :func:`verimono.lcs.solve_lcp` must be homogeneous,
    ``z*(sq) = s z*(q)`` for ``s`` in :data:`LN_SCALES` (to ``tolerance(z*)``), and least-norm (no shorter
    solution, :func:`verimono.lcs.hypotheses.shorter_solution`); then ``|z*(q)| ≤ α|q|`` is checked against
    the explicit ``α = 1/λ_min((D + Dᵀ)/2)`` (:func:`verimono.lcs.lcp.lcp_alpha`) when that is positive, and
    ``α`` is otherwise estimated from below by the samples."""
    rel, D, B = system.relation, system.D, system.B
    if isinstance(rel, BoxRelation) and np.all(np.isfinite(rel.bounds(system.m)[1])):
        bnd = float(np.linalg.norm(B, 2) * np.abs(np.concatenate(rel.bounds(system.m))).max() * np.sqrt(system.m))
        return _verdict(True, f"bounded multipliers: |Bz| ≤ {bnd:.4g} (exact)")
    if not (isinstance(rel, BoxRelation) and rel.is_lcp and is_psd(D)):
        return Outcome(None, status=SKIPPED, message="needs a bounded box, or complementarity with D + Dᵀ ⪰ 0 "
                                                     "(Proposition p:lcp2)")
    rng = np.random.default_rng(seed)
    alpha, worst, bad, shorter_checked, q_alpha = 0.0, 0.0, None, 0, None
    explicit = lcp_alpha(D)
    for _ in range(samples):
        q = sample_unit_q(D, rng)
        try:
            z = solve_lcp(D, q)
        except VerimonoError as exc:
            bad, worst = {"q": q, "error": f"{type(exc).__name__}: {exc}"}, np.inf
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
        p = shorter_solution(D, q, z)
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
    return _verdict(bad is None, msg, worst, 1.0, counter=bad,
                    details={"evidence": True, "alpha": a_used, "alpha_kind": a_kind, "alpha_sampled": alpha,
                             "B_alpha": bn * a_used, "samples": samples, "least_norm_checked": shorter_checked,
                             "scales": list(LN_SCALES)})


# -- the main theorem's assumptions, as Theorem thm: linear case derives them ------------------------

#: derived assumption → (the items it follows from, what it says)
DERIVED = {
    "lcs.A1": (("lcs.passivity", "lcs.relation_maxmon", "lcs.rel_int"), "(A1) H(t,·) maximal monotone"),
    # the proof of (A2) passes to the limit in z_ℓ ∈ (𝓜 + D)^(-1)(Cx_ℓ + v(t_ℓ)) as t_ℓ → t: it needs
    # v(t_ℓ) → v(t), which boundedness (iv) does not give and v ∈ AC (e: linear case-comp iii) does
    "lcs.A2": (("lcs.passivity", "lcs.relation_maxmon", "lcs.rel_int", "lcs.v_bounded", "lcs.v_ac"),
               "(A2) closed graph in (t, x, y)"),
    "lcs.A3": (("lcs.rel_int", "lcs.v_ac"), "(A3) domains move absolutely continuously"),
    "lcs.LG": (("lcs.least_norm_growth", "lcs.v_bounded"), "(LG) linear growth of H^0"),
}


def run_derived(decl: Any, system: Any, records: dict[str, CheckResult]) -> CheckResult:
    """A derived assumption of ``system`` over the records of the items it follows from."""
    return run(decl, subject_name(system), lambda: decl.evaluate(decl.name, records))


def _derived(name: str, records: dict[str, CheckResult]) -> Outcome:
    """An assumption of Theorem ``thm:main`` as Theorem ``thm: linear case`` derives it from its items
    (:data:`DERIVED`): passed when they all passed, else not established (skipped) — the items are
    sufficient conditions, so their failure refutes nothing."""
    needs, what = DERIVED[name]
    statuses = [records[n].status for n in needs]
    if all(s == PASSED for s in statuses):
        return Outcome(None, status=PASSED, details={"from": list(needs)},
                       message=f"{what} follows from {', '.join(needs)} (Theorem thm: linear case; {EVIDENCE})")
    missing = [f"{n} ({s})" for n, s in zip(needs, statuses) if s != PASSED]
    # the theorem's conditions are sufficient, not necessary: nothing is concluded
    return Outcome(None, status=SKIPPED, details={"from": list(needs)},
                   message=f"{what} is not established: {', '.join(missing)} did not pass (Theorem thm: linear case "
                           "gives sufficient conditions only)")


for _name, (_needs, _what) in DERIVED.items():
    law(_name, "thm: linear case", subject="system", driver=run_derived)(_derived)


def check_hypotheses(system: Any, T: float, *, samples: int = 64, seed: int = 0) -> Report:
    """Evidence for each hypothesis of the Section 7 theorems on ``[0, T]`` (see the module docstring).

    ``T`` must be a finite positive horizon and ``samples`` a positive integer
    (:class:`verimono.InvalidCheckArgument` otherwise: an empty interval is evidence of nothing)."""
    T, samples = _horizon(T), _samples(samples)
    out = Report(meta={"evidence": EVIDENCE})
    laws = laws_of("system", battery=True)
    for name, decl in laws.items():
        if name not in DERIVED:
            out.add(decl.public(system, T, samples=samples, seed=seed))
    done = {r.check: r for r in out}
    for name in DERIVED:
        out.add(laws[name].public(system, done))
    return out


__all__ = ["check_hypotheses", "EVIDENCE", "DERIVED", "AC_GRID", "AC_CANDIDATES", "AC_FLOOR", "TV_SETTLE",
           "LN_SCALES"]
