"""Operator laws: the paper's Proposition ``prop:maxmon-resolvent-Yosida`` (items i–vi), monotonicity and the
minimal section, each one decorated evaluator ``check_<law>(op, s) -> Outcome``.

Every law is an inequality ``lhs ≤ rhs`` that holds exactly for a maximal monotone ``F(t,·)``; in
floating point it is accepted when ``lhs ≤ rhs + slack``, with ``slack`` built from
:func:`verimono.core.tolerances.tolerance` of the magnitudes involved (divided by ``λ`` where a Yosida value
``(x - J_λ x)/λ`` amplifies the resolvent's error), at the relative tolerance of the precision the operator
computes in (float64: ``RTOL = 1e-8``; float32: ``2.3e-4``; :data:`verimono.core.tolerances.RTOL_BY_PRECISION`),
which the search detects from what the operator returns and records (``details["dtype"]``, ``["rtol"]``).  The recorded ratio of a sample is
``lhs / (rhs + slack)`` and every check's bound is 1: ratios near 1 mean "tight" (e.g.
``|J_λx - J_λy|² / ⟨J_λx - J_λy, x - y⟩`` for firm nonexpansiveness), and for laws with ``rhs = 0``
(identities, membership) the ratio counts violations in units of the stated tolerance.

A sample is ``(x1, x2, λ, μ, ν, t)`` (:class:`verimono.checks.engine.samples.Sample`).  Points known to lie in
``dom F(t,·)`` are produced as ``x = J_ν x1``, which comes with the graph element ``y0 = Y_ν x1 ∈ F(t, x)``
(item v) — so the minimal-section laws need no knowledge of the domain.

The decorator (:func:`verimono.checks.engine.search.operator_law`) makes each the public
``check_<law>(op, *, seed=None, examples=None, horizon=1.0, sample=None) -> CheckResult``: the search of
:mod:`verimono.checks.engine.search` for a sample that breaks it.  A law needing a member the operator does not
provide is skipped before it runs; the value laws of ``prox_{λg}`` are in :mod:`verimono.checks.prox_laws`.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.errors import NotApplicable, OutsideDomain, VerimonoError
from ..core.tolerances import (LIMIT_FLOOR, REPEAT_ULPS, RTOL, STALL_RATIO, STALL_WINDOW, current_eps, repeat_tolerance,
                               row_tolerances, tolerance)
from .core import Member, Outcome, ratio
from .members import (_ROUNDOFF_BOUNDARY, listed, min_norm, norm, outside_by_roundoff_of_dom_g, point, resolvent,
                      within_roundoff_of_domain)
from .engine.batches import (rounding, rounding_bound, row_contains, row_dots, row_member, row_norms, row_ratios, row_resolvents,
                             vectorised)
from .engine.forms import DECLARED, DESCRIBED, INTEGER, InForm
from .engine.samples import Sample
from .engine.search import YOSIDA_SLACK, operator_law

#: tolerance multiples tried when grading a failed membership test ``y ∈ F(t, x)``
GRADES = tuple(10.0 ** k for k in range(0, 13, 2))
_MIN_NORM, _CONTAINS, _PROJECT = Member("min_norm"), Member("contains"), Member("project_domain")


def _graded_membership(op, x: np.ndarray, y: np.ndarray, t: float, tol: float, scale: float | None = None,
                       normal: np.ndarray | None = None) -> float:
    """Smallest tried multiple ``g`` of ``tol`` with ``y ∈ F(t, x)`` up to ``g·tol`` (``inf`` if none; no sample —
    :class:`NotApplicable` — when ``x`` lies outside the domain by round-off only: of ``dom F`` judged by
    ``min_norm`` and ``project_domain``, or of ``dom g`` by ``value`` at points within ``eps·(1 + scale)``)."""
    for g in GRADES:
        if op.contains(x.copy(), y.copy(), t, g * tol):
            return g
    if _outside_by_roundoff(op, x, t):
        raise NotApplicable(f"y ∈ F(t, x) not decidable at x: {_ROUNDOFF_BOUNDARY}")
    if getattr(op, "value", None) is not None and scale is not None and _g_infinite(op, x, t) \
            and outside_by_roundoff_of_dom_g(op, x, t, scale, normal):
        raise NotApplicable("y ∈ ∂g(t, x) not decidable at x: g(x) = inf there only by round-off (g is finite "
                            "within a few eps·|x| of x)")
    return math.inf


def _g_infinite(op, x: np.ndarray, t: float) -> bool:
    try:
        return not math.isfinite(op.value(np.array(x, dtype=float), t))
    except Exception:      # noqa: BLE001 - the law judges the value function's exceptions elsewhere
        return False


def _outside_by_roundoff(op, x: np.ndarray, t: float) -> bool:
    """``x ∉ dom F(t,·)`` (its minimal section rejects it) but within round-off of the domain's closure."""
    if getattr(op, "min_norm", None) is None:
        return False
    try:
        op.min_norm(x.copy(), t)
    except OutsideDomain:
        return within_roundoff_of_domain(op, x, t)
    except Exception:      # noqa: BLE001 - any other answer: x is not shown to be outside
        return False
    return False


def _domain_pair(op, s: Sample) -> tuple[np.ndarray, np.ndarray, float]:
    """``x = J_ν x1 ∈ dom F(t,·)`` with ``y0 = Y_ν x1 ∈ F(t, x)`` and the tolerance of ``x``."""
    x = resolvent(op, s.x1, s.nu, s.t)
    return x, (s.x1 - x) / s.nu, tolerance(s.x1, x)


# -- the laws ---------------------------------------------------------------------------------------

@operator_law("resolvent_single_valued", "prop:maxmon-resolvent-Yosida i–ii")
def check_resolvent_single_valued(op, s):
    """Proposition prop:maxmon-resolvent-Yosida i–ii:
    ``J_λ`` is defined on all of ``R^n`` and single-valued — two calls on the same ``x``
    return the same finite point of shape ``(n,)`` and leave ``x`` unchanged (ratio: |difference|/tol, the
    tolerance of repeated calls: :func:`verimono.core.tolerances.repeat_tolerance`).  A sample in an input form
    (:mod:`verimono.checks.engine.forms`) compares its value with a third call on the same point as a fresh contiguous
    float64 array too (:func:`form_tolerance`): ``J_λ`` is a function of the *values* of ``x``, whatever its layout.
    A value once returned is the caller's: a call at another point ``x2`` must not change it (:func:`_value_kept`:
    an output buffer handed out twice fails, exactly)."""
    x = s.x1.copy()
    a = point(op.resolvent(x, s.lam, s.t), s.x1, "resolvent")
    moved = norm(x - s.x1)
    kept = _value_kept(op, a, s)
    b = resolvent(op, s.x1, s.lam, s.t)
    tau = repeat_tolerance(s.x1, a, b)
    broke = (f" (the call modified its input by {moved:.3g})" if moved else "") + (kept or "")
    out = Outcome.compare(norm(a - b) + (math.inf if moved > 0 or kept else 0.0), 0.0, tau,
                 "|J_λx - J_λx| over two calls" + broke,
                 {"J_first": listed(a), "J_second": listed(b), "input_modified_by": moved})
    if type(op) is InForm and out.worst <= 1.0:
        # J_λ is a function of x's values: the call in this form against the same point as a fresh contiguous array
        c = resolvent(op._op, s.x1, s.lam, s.t)
        tc = form_tolerance(op.form, s.x1, a, c)
        across = Outcome.compare(norm(a - c), 0.0, tc, f"|J_λx (x as {DESCRIBED[op.form]}) - J_λx (x contiguous)|",
                                 {"J_in_form": listed(a), "J_contiguous": listed(c), "form": op.form})
        if not across.worst <= out.worst:
            return across
    return out


def _value_kept(op, a: np.ndarray, s: Sample) -> str | None:
    """``None`` when ``a`` (``J_λx1`` as the subject returned it) keeps its values over a call ``J_λx2`` at another
    point, else what changed.  A resolvent writing every value into one preallocated buffer and returning that buffer
    hands the caller an array the next call overwrites: ``j1 = J(x1); j2 = J(x2)`` leaves ``j1 == j2`` (the stepper's
    law ``trajectory_immutable`` names the same fault of a stepper).  Exact: a returned array that changes in any bit
    has changed.  A subject returning another dtype (float32: converted, a copy) shows it too: the conversion watches
    the array it converted and the copy takes the values the subject later wrote into it
    (:meth:`verimono.core.arrays.Boundary._watch`)."""
    if np.array_equal(s.x1, s.x2):
        return None
    before = a.copy()
    try:
        op.resolvent(s.x2.copy(), s.lam, s.t)
    except Exception:        # noqa: BLE001 - the call at x2 is the other laws' to judge; only a's values are this one's
        return None
    if np.array_equal(a, before, equal_nan=True):
        return None
    return (f" (the value J_λx1 returned changed when J_λ was called at x2, by up to "
            f"{float(np.max(np.abs(a - before))):.3g}: one output buffer handed out twice)")


#: the input forms that change the dtype the subject receives (the others change only the memory layout)
_DTYPE_FORMS = (INTEGER, DECLARED)


def form_tolerance(form: str, *scales) -> float:
    """The tolerance of ``J_λx`` in ``form`` against ``J_λx`` of the same point as a fresh contiguous float64 array
    (``resolvent_single_valued``).  A layout (a strided view, an offset slice, a read-only array) changes no value,
    only memory: the two calls agree as two calls at one input do (:func:`repeat_tolerance`, not bit for bit: NumPy
    reduces a strided or unaligned array in another order, a few ulps).  A dtype change (integer-valued points as
    int64, the subject's declared dtype) hands the subject its values in another type, which it may compute in
    (int64 promoted to float64 by one expression and kept by another): within the tolerance of the precision under
    judgement (:func:`tolerance`; float32: ``2.3e-4``), and never below the repeat tolerance."""
    t = repeat_tolerance(*scales)
    return max(t, tolerance(*scales)) if form in _DTYPE_FORMS else t


@operator_law("resolvent_nonexpansive", "prop:maxmon-resolvent-Yosida ii")
def check_resolvent_nonexpansive(op, s):
    """Proposition prop:maxmon-resolvent-Yosida ii:
    ``|J_λx1 - J_λx2| ≤ |x1 - x2|`` (ratio ``|ΔJ| / (|Δx| + slack)``)."""
    a, b = resolvent(op, s.x1, s.lam, s.t), resolvent(op, s.x2, s.lam, s.t)
    tau = tolerance(s.x1, s.x2, a, b)
    return Outcome.compare(norm(a - b), norm(s.x1 - s.x2), 4 * tau, "|J_λx1 - J_λx2| ≤ |x1 - x2|",
                 {"J1": listed(a), "J2": listed(b)})


@operator_law("resolvent_firmly_nonexpansive", "prop:maxmon-resolvent-Yosida ii (A1)")
def check_resolvent_firmly_nonexpansive(op, s):
    """Proposition prop:maxmon-resolvent-Yosida ii (A1):
    item ii sharpened, equivalent to monotonicity of ``F``:
    ``|J_λx1 - J_λx2|² ≤ ⟨J_λx1 - J_λx2, x1 - x2⟩`` (ratio ``|ΔJ|² / (⟨ΔJ, Δx⟩ + slack)``)."""
    a, b = resolvent(op, s.x1, s.lam, s.t), resolvent(op, s.x2, s.lam, s.t)
    dJ, dx = a - b, s.x1 - s.x2
    tau = tolerance(s.x1, s.x2, a, b)
    return Outcome.compare(float(dJ @ dJ), float(dJ @ dx), 4 * tau * (norm(dJ) + norm(dx) + tau),
                 "|J_λx1 - J_λx2|² ≤ ⟨J_λx1 - J_λx2, x1 - x2⟩", {"J1": listed(a), "J2": listed(b)})


@operator_law("resolvent_in_domain", "range J_λ = dom F", _PROJECT)
def check_resolvent_in_domain(op, s):
    """range J_λ = dom F:
    ``J_λx ∈ dom F(t,·)`` (``x = J_λx + λy`` with ``y ∈ F(t, J_λx)``): the projection onto
    ``cl dom F(t,·)`` leaves ``J_λx`` in place (needs ``project_domain``; ratio: distance/tol)."""
    a = resolvent(op, s.x1, s.lam, s.t)
    p = point(op.project_domain(a.copy(), s.t), a, "project_domain")
    return Outcome.compare(norm(p - a), 0.0, 2 * tolerance(s.x1, a), "dist(J_λx, cl dom F(t,·)) = 0",
                 {"J": listed(a), "proj_dom_J": listed(p)})


@operator_law("resolvent_identity", "resolvent identity")
def check_resolvent_identity(op, s):
    """The resolvent identity ``J_λx = J_μ((μ/λ)x + (1 - μ/λ)J_λx)`` for all ``λ, μ > 0`` (it holds because
    ``x - J_λx ∈ λF(J_λx)``); catches resolvents with a wrong or stale step size (ratio: |difference|/tol)."""
    a = resolvent(op, s.x1, s.lam, s.t)
    r = s.mu / s.lam
    z = r * s.x1 + (1.0 - r) * a
    b = resolvent(op, z, s.mu, s.t)
    tau = tolerance(s.x1, a, z)
    return Outcome.compare(norm(a - b), 0.0, tau * (4.0 + abs(1.0 - r)),
                 "J_λx = J_μ((μ/λ)x + (1 - μ/λ)J_λx)", {"J_lam": listed(a), "J_mu_of_z": listed(b), "z": listed(z)})


@operator_law("resolvent_limit", "prop:maxmon-resolvent-Yosida iii")
def check_resolvent_limit(op, s):
    """Proposition prop:maxmon-resolvent-Yosida iii, quantitatively:
    for ``x ∈ dom F`` and ``y ∈ F(x)``, ``|J_λx - x| ≤ λ|y|`` (nonexpansiveness
    at ``J_λ(x + λy) = x``), hence ``J_λx → x`` as ``λ → 0``.  Tested at ``x = J_νx1``, ``y = Y_νx1`` over
    ``λ, λ/4, …, λ/4^5`` (ratio ``|J_λx - x| / (λ|y| + slack)``)."""
    x, y0, tau = _domain_pair(op, s)
    ny, worst = norm(y0), None      # |y| once; the outcome (its points listed) for the worst step only
    for k in range(6):
        lam = s.lam * 4.0 ** (-k)
        d = norm(resolvent(op, x, lam, s.t) - x)
        q = ratio(d, lam * ny, tau * (4.0 + lam / s.nu))
        if worst is None or not q <= worst[0]:
            worst = (q, d, lam)
    _, d, lam = worst
    return Outcome.compare(d, lam * ny, tau * (4.0 + lam / s.nu), "|J_λx - x| ≤ λ|y| for x = J_νx1, y = Y_νx1 ∈ F(x)",
                           {"x": listed(x), "y": listed(y0), "lam_at_worst": lam})


@operator_law("monotone", "(A1)")
def check_monotone(op, s):
    """Assumption (A1): the graph of ``F(t,·)`` is monotone, ``⟨x_a - x_b, y_a - y_b⟩ ≥ 0``, sampled through the
    resolvent: ``(J_λx1, Y_λx1)`` and ``(J_μx2, Y_μx2)`` are graph elements (item v) for different step
    sizes (ratio ``-⟨Δx, Δy⟩ / slack``)."""
    a, b = resolvent(op, s.x1, s.lam, s.t), resolvent(op, s.x2, s.mu, s.t)
    ya, yb = (s.x1 - a) / s.lam, (s.x2 - b) / s.mu
    dx, dy = a - b, ya - yb
    ex = 2 * tolerance(s.x1, s.x2, a, b)
    ey = ex * (1.0 / s.lam + 1.0 / s.mu)
    return Outcome.compare(-float(dx @ dy), 0.0, 2 * (ex * norm(dy) + ey * norm(dx) + ex * ey),
                 "⟨x_a - x_b, y_a - y_b⟩ ≥ 0 for (x_a, y_a) = (J_λx1, Y_λx1), (x_b, y_b) = (J_μx2, Y_μx2)",
                 {"xa": listed(a), "ya": listed(ya), "xb": listed(b), "yb": listed(yb)})


@operator_law("yosida_lipschitz", "prop:maxmon-resolvent-Yosida iv")
def check_yosida_lipschitz(op, s):
    """Proposition prop:maxmon-resolvent-Yosida iv:
    ``Y_λ`` is ``1/λ``-Lipschitz, ``λ|Y_λx1 - Y_λx2| ≤ |x1 - x2|``
    (ratio ``λ|ΔY| / (|Δx| + slack)``)."""
    a, b = resolvent(op, s.x1, s.lam, s.t), resolvent(op, s.x2, s.lam, s.t)
    dY = ((s.x1 - a) - (s.x2 - b)) / s.lam
    return Outcome.compare(s.lam * norm(dY), norm(s.x1 - s.x2), 4 * tolerance(s.x1, s.x2, a, b),
                 "λ|Y_λx1 - Y_λx2| ≤ |x1 - x2|", {"J1": listed(a), "J2": listed(b)})


@operator_law("yosida_monotone", "prop:maxmon-resolvent-Yosida iv")
def check_yosida_monotone(op, s):
    """Proposition prop:maxmon-resolvent-Yosida iv:
    ``Y_λ`` is (maximal) monotone, ``⟨Y_λx1 - Y_λx2, x1 - x2⟩ ≥ 0``
    (ratio ``-⟨ΔY, Δx⟩ / slack``)."""
    a, b = resolvent(op, s.x1, s.lam, s.t), resolvent(op, s.x2, s.lam, s.t)
    dx = s.x1 - s.x2
    dY = (dx - (a - b)) / s.lam
    return Outcome.compare(-float(dY @ dx), 0.0, 4 * tolerance(s.x1, s.x2, a, b) * norm(dx) / s.lam,
                 "⟨Y_λx1 - Y_λx2, x1 - x2⟩ ≥ 0", {"J1": listed(a), "J2": listed(b)})


@operator_law("yosida_in_graph", "prop:maxmon-resolvent-Yosida v", _CONTAINS)
def check_yosida_in_graph(op, s):
    """Proposition prop:maxmon-resolvent-Yosida v:
    ``Y_λx ∈ F(t, J_λx)`` through ``contains`` (ratio: the smallest power-of-100 multiple of the
    tolerance at which membership is accepted; 1 when it is accepted at the tolerance)."""
    a = resolvent(op, s.x1, s.lam, s.t)
    y = (s.x1 - a) / s.lam
    tol = tolerance(s.x1, a, s.lam * y) * (2.0 + 2.0 / s.lam)
    g = _graded_membership(op, a, y, s.t, tol, scale=max(norm(s.x1), norm(a)), normal=s.x1 - a)
    return Outcome.compare(g, 0.0, 1.0, "Y_λx ∈ F(t, J_λx) (ratio: tolerance multiple needed)",
                 {"J": listed(a), "Y": listed(y), "tol": tol})


@operator_law("yosida_nonincreasing", "prop:maxmon-resolvent-Yosida vi")
def check_yosida_nonincreasing(op, s):
    """Proposition prop:maxmon-resolvent-Yosida vi:
    ``λ ↦ |Y_λx|`` is nonincreasing, ``|Y_μx| ≤ |Y_λx|`` for ``λ ≤ μ`` (stated in the paper for
    ``x ∈ dom F``; it holds for every ``x`` since ``Y_μ = (Y_λ)_{μ-λ}``) (ratio ``|Y_μx| / (|Y_λx| + slack)``)."""
    lo, hi = sorted((s.lam, s.mu))
    if hi == lo:
        hi = 2.0 * lo
    a, b = resolvent(op, s.x1, lo, s.t), resolvent(op, s.x1, hi, s.t)
    ylo, yhi = (s.x1 - a) / lo, (s.x1 - b) / hi
    tau = tolerance(s.x1, a, b)
    return Outcome.compare(norm(yhi), norm(ylo), 4 * tau * (1.0 / lo + 1.0 / hi),
                 "|Y_μx| ≤ |Y_λx| for λ ≤ μ", {"lam": lo, "mu": hi, "Y_lam": listed(ylo), "Y_mu": listed(yhi)})


@operator_law("yosida_bounded_by_min_norm", "prop:maxmon-resolvent-Yosida vi", _MIN_NORM)
def check_yosida_bounded_by_min_norm(op, s):
    """Proposition prop:maxmon-resolvent-Yosida vi:
    ``|Y_λx| ≤ |F^0(x)|`` for ``x ∈ dom F`` (at ``x = J_νx1``; needs ``min_norm``)
    (ratio ``|Y_λx| / (|F^0(x)| + slack)``)."""
    x, _, tau = _domain_pair(op, s)
    f0 = min_norm(op, x, s.t)
    a = resolvent(op, x, s.lam, s.t)
    y = (x - a) / s.lam
    return Outcome.compare(norm(y), norm(f0), 4 * tolerance(x, a) / s.lam + 2 * tau / s.lam + tolerance(f0),
                 "|Y_λx| ≤ |F^0(t, x)| for x = J_νx1 ∈ dom F", {"x": listed(x), "Y": listed(y), "F0": listed(f0)})


@operator_law("yosida_limit", "prop:maxmon-resolvent-Yosida vi", _MIN_NORM)
def check_yosida_limit(op, s):
    """Proposition prop:maxmon-resolvent-Yosida vi:
    ``|Y_λx| → |F^0(x)|`` as ``λ → 0`` for ``x ∈ dom F`` (needs ``min_norm``).  ``λ`` is halved
    until the gap ``||F^0(x)| - |Y_λx||`` is within tolerance, or down to the rounding floor where the gap must
    still be shrinking (``tolerances.STALL_RATIO`` over ``STALL_WINDOW`` halvings); a stalled positive gap
    means ``min_norm`` is not the least-norm element or ``J_λ`` has the wrong ``λ``."""
    x, _, tau = _domain_pair(op, s)
    f0 = norm(min_norm(op, x, s.t))
    tx = tolerance(x)
    floor = 2 * LIMIT_FLOOR * tx / (1.0 + f0)
    lam = max(s.lam, floor)
    gaps, lams = [], []
    while True:
        a = resolvent(op, x, lam, s.t)
        y = norm((x - a) / lam)
        gap, slack = abs(f0 - y), tolerance(f0, y) + 2 * tx / lam
        gaps.append(gap)
        lams.append(lam)
        info = {"x": listed(x), "|F0|": f0, "lams": lams, "gaps": gaps}
        if gap <= slack:
            return Outcome.compare(gap, 0.0, slack, "|Y_λx| → |F^0(t, x)| as λ → 0 (gap within tolerance)", info)
        if y <= 2 * tx / lam and _only_within_rounding(op, x, np.zeros_like(x), s.t, 2 * tx):
            return Outcome.compare(0.0, 0.0, slack, "|Y_λx| → 0: x is within rounding, not exactly at, a zero of F(t,·) "
                         "(F^0 is ill-conditioned there; sample inconclusive)", info, inconclusive=True)
        if lam / 2 < floor:
            break
        lam /= 2
    w = min(STALL_WINDOW, len(gaps) - 1)
    if w == 0:   # one λ above the rounding floor: the gap can be neither closed nor seen shrinking
        return Outcome.compare(gaps[-1], gaps[-1], slack, "|Y_λx| → |F^0(t, x)| (no room to halve λ; sample inconclusive)",
                     info, inconclusive=True)
    if _kink_within(op, x, s.t, KINK_PROBE * lams[-1] * (1.0 + f0)):
        return Outcome.compare(0.0, 0.0, slack, f"|Y_λx| → |F^0(t, x)|: F^0 jumps within {KINK_PROBE * lams[-1] * (1.0 + f0):.2g} "
                     "of x, where the gap closes only below the sweep's rounding floor λ = "
                     f"{lams[-1]:.3g} (sample inconclusive)", info, inconclusive=True)
    if _closing_below_floor(gaps, 8 * current_eps() * (1.0 + float(np.max(np.abs(x)))) / lams[-1]):
        return Outcome.compare(0.0, 0.0, slack, "|Y_λx| → |F^0(t, x)|: the gap is still closing, ever faster, at the rounding "
                     "floor (a kink of F closer to x than λ|F^0| resolves; sample inconclusive)", info,
                     inconclusive=True)
    # the gap exceeds the rounding floor: it must at least still be shrinking
    return Outcome.compare(gaps[-1], STALL_RATIO * gaps[-1 - w], tolerance(gaps[-1], gaps[-1 - w]),
                 f"|Y_λx| → |F^0(t, x)|: gap ||F^0| - |Y_λx|| above tolerance {slack:.3g} must still shrink over "
                 f"the last {w} halvings down to λ = {lams[-1]:.3g}", info)


#: a stalled Yosida gap is inconclusive when F^0 jumps within KINK_PROBE·λ_floor·(1 + |F^0|) of x: at distance
#: d from a kink of F the gap closes once λ|F^0| ≲ d (soft thresholding: λc < d), so a kink nearer than
#: that is resolved only below the floor (a 2^-23 offset from a kink of a shifted ∂‖·‖₁, found by a
#: thorough run); the factor 4 covers the constant of that estimate
KINK_PROBE = 4.0
#: the most halvings of λ the vectorised form of yosida_limit makes (from 10^7 to the smallest normal float is
#: ~1045); it stops earlier when fewer than two rows are open (one row's halvings are cheaper in the law's own
#: loop): the rows still open are the evaluator's
YOSIDA_HALVINGS = 1100


def _kink_within(op, x: np.ndarray, t: float, delta: float) -> bool:
    """Whether ``F^0(t, ·)`` jumps (changes by more than half its size) or leaves its domain within ``delta``
    of ``x``, probed along the coordinate axes and the direction of ``F^0(t, x)``."""
    f0 = min_norm(op, x, t)
    n0 = norm(f0)
    dirs = list(np.eye(x.size))
    if n0 > 0:
        dirs.append(f0 / n0)
    for d in dirs:
        for sgn in (1.0, -1.0):
            try:
                g = min_norm(op, x + sgn * delta * d, t)
            except (VerimonoError, ArithmeticError, ValueError):   # OutsideDomain among them
                return True
            if norm(g - f0) > 0.5 * max(n0, norm(g)):
                return True
    return False


def _closing_below_floor(gaps: list[float], noise: float) -> bool:
    """Whether the gaps ``|F^0| - |Y_λx|`` of the last halvings of ``λ`` close ever faster: the last three
    decrements each at least double (far above the rounding ``noise``) and, continued at that rate, close
    the gap within ``STALL_WINDOW`` more halvings.

    At ``x`` at distance ``d`` from a kink of ``F`` the gap only closes once ``λ ≲ d/|F^0|``: for
    ``∂|·|₁`` at ``x = (1, 1e-8)`` it is ``√2 - √(1 + (1e-8/λ)²)``, whose decrements grow 4-fold per halving
    down to ``λ = 1e-8``, below the rounding floor of the sweep.  A gap ``c + aλ^p`` (a wrong ``F^0`` or a
    wrong ``λ``, ``c > 0``) has decrements shrinking by ``2^-p`` per halving, and a constant gap none.  Near a
    kink the decrements are those of ``|Y_λx|`` alone, so such a sample is inconclusive for a wrong ``F^0``
    too: it fails at points away from kinks, which the search reaches first."""
    if len(gaps) < 4:
        return False
    d = [gaps[-4] - gaps[-3], gaps[-3] - gaps[-2], gaps[-2] - gaps[-1]]
    if not (d[0] > noise and d[1] >= 2 * d[0] and d[2] >= 2 * d[1]):
        return False
    r, step, closed = min(d[1] / d[0], d[2] / d[1]), d[2], 0.0
    for _ in range(STALL_WINDOW):
        step *= r
        closed += step
        if closed >= gaps[-1]:
            return True
    return False


@operator_law("min_norm_in_graph", "minimal section F^0 = proj(0, F(x))", _MIN_NORM, _CONTAINS)
def check_min_norm_in_graph(op, s):
    """The minimal section F^0 = proj(0, F(x)) lies in the graph:
    ``F^0(t, x) ∈ F(t, x)`` for ``x = J_νx1 ∈ dom F`` (needs
    ``min_norm`` and ``contains``; ratio as for :func:`check_yosida_in_graph`)."""
    x, _, _ = _domain_pair(op, s)
    f0 = min_norm(op, x, s.t)
    tol = 2 * tolerance(x, f0)
    g = _graded_membership(op, x, f0, s.t, tol)
    return Outcome.compare(g, 0.0, 1.0, "F^0(t, x) ∈ F(t, x) (ratio: tolerance multiple needed)",
                 {"x": listed(x), "F0": listed(f0), "tol": tol})


@operator_law("min_norm_least", "minimal section F^0 = proj(0, F(x))", _MIN_NORM)
def check_min_norm_least(op, s):
    """The minimal section F^0 = proj(0, F(x)) has least norm,
    ``|F^0(t, x)| ≤ |y|`` for every ``y ∈ F(t, x)``: compared with
    ``y = Y_νx1`` at ``x = J_νx1`` (item v; certified by ``contains`` when available)
    (ratio ``|F^0(x)| / (|y| + slack)``)."""
    x, y0, tau = _domain_pair(op, s)
    f0 = min_norm(op, x, s.t)
    info = {"x": listed(x), "y": listed(y0), "F0": listed(f0)}
    try:   # y0 must be certified in F(t, x) where that can be tested (else yosida_in_graph fails)
        if not op.contains(x.copy(), y0.copy(), s.t, tolerance(x, y0) * (2.0 + 2.0 / s.nu)):
            return Outcome.compare(0.0, 0.0, 1.0, "uncertified y0 ∉ F(t, x) (contains rejects it): sample inconclusive", info,
                         inconclusive=True)
    except NotImplementedError:
        pass
    slack = 4 * tau / s.nu + tolerance(f0)
    if norm(f0) > norm(y0) + slack and _only_within_rounding(op, x, y0, s.t, tolerance(x, y0) * (2.0 + 2.0 / s.nu)):
        return Outcome.compare(0.0, 0.0, 1.0, "y0 ∈ F(t, x') only for x' within rounding of x, near a jump of F^0: "
                     "sample inconclusive", info, inconclusive=True)
    return Outcome.compare(norm(f0), norm(y0), slack, "|F^0(t, x)| ≤ |y| for x = J_νx1 and y = Y_νx1 ∈ F(t, x)", info)


def _only_within_rounding(op, x, y, t, tol) -> bool:
    """Whether ``y ∈ F(t, x)`` holds up to ``tol`` but not exactly: ``x`` is within rounding of a point
    where ``F`` jumps (a kink of ``|·|`` reached through rounded shifts, ``x + Φ = 1e-17``), where ``F^0`` is
    ill-conditioned and the λ → 0 limit and least-norm laws cannot be observed.  An exact kink (``x = 0``)
    is not such a point, so a wrong ``F^0`` there is still caught; without ``contains`` nothing is excused."""
    try:
        return bool(op.contains(x.copy(), y.copy(), t, tol)) and not op.contains(x.copy(), y.copy(), t, 0.0)
    except NotImplementedError:
        return False


# -- the members besides the resolvent: each judged against the resolvent's own values -------------------------

_YOSIDA = Member("yosida")


def yosida_tolerance(x: np.ndarray, j: np.ndarray, lam: float) -> float:
    """The slack of a Yosida value ``Y_λx = (x - J_λx)/λ`` computed from a resolvent accurate to its precision's
    tolerance: ``4·tolerance(x, J_λx)/λ`` (the resolvent's error ``RTOL(1 + |x|)``, float64 ``RTOL = 1e-8``, amplified
    by ``1/λ``; the scale of ``yosida_bounded_by_min_norm``'s)."""
    return 4 * tolerance(x, j) / lam


@operator_law("yosida_member", "prop:maxmon-resolvent-Yosida v", _YOSIDA)
def check_yosida_member(op, s):
    """Proposition prop:maxmon-resolvent-Yosida v, the definition of ``Y_λ``:
    an operator's own ``yosida`` member (where it provides one: an override of :meth:`Operator.yosida`) equals
    ``(x - J_λx)/λ`` from its own resolvent, within :func:`yosida_tolerance` plus the member's own rounding
    (ratio ``|Y_member - (x - J_λx)/λ| / slack``).  The laws compute ``Y_λ`` from the resolvent; a caller of
    ``op.yosida`` gets the member."""
    a = resolvent(op, s.x1, s.lam, s.t)
    y = (s.x1 - a) / s.lam
    m = point(op.yosida(s.x1.copy(), s.lam, s.t), s.x1, "yosida")
    return Outcome.compare(norm(m - y), 0.0, yosida_tolerance(s.x1, a, s.lam) + tolerance(y, m),
                           "yosida(x, λ) = (x - J_λx)/λ", {"J": listed(a), "Y_from_J": listed(y), "Y_member": listed(m)})


#: the monotonicity break of the pair ``contains_rejects`` offers, as a multiple of ``(1 + |Y_λx1| + |Y_λx2| + e_Y)``
#: (``e_Y`` the Yosida values' slack): far beyond what any tolerance of the pair, the graph point or ``contains`` covers
CONTAINS_BREAK = 16.0
#: the least ratio (monotonicity break over what the tolerances can explain) at which the offered pair is decidably
#: outside every monotone graph through the sample's graph point; below it (``J_λx1`` within rounding of ``J_λx2``)
#: the sample is inconclusive
CONTAINS_DECIDABLE = 2.0


def _breaking_pair(n: int, x1, x2, u1, u2, lam, tol_c):
    """The pair ``(u1, v)`` of ``contains_rejects``, with ``v = v2 - c(u1 - u2)``, and its ratio: the break
    ``c|Δu|²`` of monotonicity against ``(u2, v2)`` over the largest value of ``-⟨Δx', Δy'⟩`` a pair within reach of
    it can have (``|a||Δu|c + |b||Δu| + |a||b|`` for moves ``|a| ≤ T_x``, ``|b| ≤ T_y``), for arrays of rows or
    one row (``u`` etc. ``(B, n)`` or ``(n,)``)."""
    rows = u1.ndim == 2
    nrm = row_norms if rows else norm
    lam_c = lam[:, None] if rows else lam
    v1, v2 = (x1 - u1) / lam_c, (x2 - u2) / lam_c
    du = u1 - u2
    ndu = nrm(du)
    if not rows and not ndu > 0:
        return v2, 0.0, ndu, math.inf
    tau = row_tolerances(x1, x2, u1, u2) if rows else tolerance(x1, x2, u1, u2)
    ex, ey = 4 * tau, 4 * tau / lam
    with np.errstate(divide="ignore", invalid="ignore"):
        c = CONTAINS_BREAK * (1.0 + nrm(v1) + nrm(v2) + ey) / ndu
        v = v2 - (c[:, None] if rows else c) * du
        nv = nrm(v)
        # contains' reach: tol_c per coordinate, read absolutely (the protocol) or relative to |v| (a subgradient
        # test), plus the rounding of its own arithmetic on (u1, v)
        reach = math.sqrt(n) * tol_c * (1.0 + nv) + (row_tolerances(u1, v) if rows else tolerance(u1, v))
        tx, ty = reach + ex, reach + ey
        q = c * ndu * ndu / (ndu * ty + c * tx * ndu + tx * ty)
    return v, q, ndu, tx


def _contains_spread(op, n: int) -> float:
    """The factor ``contains_rejects`` divides its tolerance by before handing it to ``contains``: ``sqrt(n)``, so the
    per-coordinate ``tol`` (the protocol's reading, :meth:`Operator.contains`) reaches ``2·tolerance`` in the Euclidean
    norm — the size of the pair's own error — instead of ``sqrt(n)`` times it.  Handed ``2·tolerance`` per coordinate,
    a relative reach ``sqrt(n)·tol·(1 + |v|)`` bounds the break's ratio by ``1/(sqrt(n)·tol)`` whatever ``c`` is
    (the move of ``v`` along ``Δu`` cancels the break): at float32 (``rtol`` 2.3e-4) every sample of ``n ≥ 10^3``
    was inconclusive.  The pair stays decidable by the same rule (:func:`_breaking_pair` counts the reach of the
    ``tol`` handed, and ``contains``' own rounding, ``tolerance(u1, v)`` ≤ ``sqrt(n)·tol`` here): a smaller ``tol``
    only makes a correct ``contains`` reject the more surely.  A user's ``contains(x, y, t)`` that takes no
    ``tol`` (``operator_from_resolvent``/``operator_from_prox`` with one) decides at its own tolerance, which the law
    cannot shrink: it keeps the factor 1 (its reach assumed the protocol's default, as before)."""
    if getattr(op, "_contains", None) is not None and not getattr(op, "_contains_takes_tol", True):
        return 1.0
    return math.sqrt(n)


#: the coordinates of ``contains_rejects``: all but ``offset`` (its pairs ``b + s n``, ``b + 1000 s n`` lie on one normal
#: ray of the domain, whose points a projection maps to one ``J_λx1 = J_λx2``: no pair decidable there, 220 evaluations
#: an operator all inconclusive) and ``mu``, ``nu`` (not read)
CONTAINS_OVER = ("points", "form", "direction", "lam", "t", "scale")


#: why a ``contains_rejects`` sample is inconclusive (its evaluator's message, and its vectorised form's)
_CONTAINS_INCONCLUSIVE = "J_λx1 within rounding of J_λx2: no pair decidably outside the graph (sample inconclusive)"


@operator_law("contains_rejects", "(A1)", _CONTAINS, over=CONTAINS_OVER)
def check_contains_rejects(op, s):
    """Assumption (A1) for the membership test ``contains`` itself: it must reject a pair no monotone graph through
    the sample's graph points holds.  With ``(u_i, v_i) = (J_λx_i, Y_λx_i)`` (item v), the pair
    ``(u1, v2 - c(u1 - u2))``, ``c > 0``, has ``⟨u1 - u2, v - v2⟩ = -c|u1 - u2|² < 0``; ``c`` is
    :data:`CONTAINS_BREAK` times the Yosida values' size over ``|u1 - u2|``, so the break exceeds what the tolerances
    of the pair, of the graph point and of ``contains`` can explain (:func:`_breaking_pair`) by the recorded factor.
    ``contains`` saying True there is a violation (ratio: that factor); a sample with ``u1`` within rounding of
    ``u2`` (factor below :data:`CONTAINS_DECIDABLE`) is inconclusive."""
    u1, u2 = resolvent(op, s.x1, s.lam, s.t), resolvent(op, s.x2, s.lam, s.t)
    tol_c = 2 * tolerance(u1, (s.x2 - u2) / s.lam) / _contains_spread(op, s.x1.size)
    v, q, ndu, tx = _breaking_pair(s.x1.size, s.x1, s.x2, u1, u2, s.lam, tol_c)
    info = {"u1": listed(u1), "u2": listed(u2), "v": listed(v), "tol": tol_c, "break_over_tolerances": float(q)}
    if not (ndu > 0 and q >= CONTAINS_DECIDABLE):
        return Outcome.inconclusive_sample(_CONTAINS_INCONCLUSIVE, info)
    accepted = bool(op.contains(u1.copy(), v.copy(), s.t, tol_c))
    return Outcome.compare(q if accepted else 0.0, 0.0, 1.0,
                           "contains(u1, v2 - c(u1 - u2)) is False, (u_i, v_i) = (J_λx_i, Y_λx_i): the pair breaks "
                           "monotonicity with (u2, v2) (ratio: the break over its tolerances, where it was accepted)",
                           info)


@operator_law("project_domain_nearest", "projection onto cl dom F", _PROJECT)
def check_project_domain_nearest(op, s):
    """The projection onto cl dom F: ``project_domain`` is the nearest point of the closed convex set ``cl dom F(t,·)``
    (convex: ``F`` maximal monotone), so for ``P = project_domain(x1)``: ``|x1 - P| ≤ |x1 - J_λx1|`` (``J_λx1 ∈ dom F``, item i), and the
    projection's variational inequality ``⟨x1 - P, q - P⟩ ≤ 0`` at ``q = J_μx2 ∈ dom F`` (ratio: the larger of
    ``|x1 - P| / (|x1 - J_λx1| + slack)`` and ``⟨x1 - P, q - P⟩ / slack``)."""
    p = point(op.project_domain(s.x1.copy(), s.t), s.x1, "project_domain")
    a, q = resolvent(op, s.x1, s.lam, s.t), resolvent(op, s.x2, s.mu, s.t)
    info = {"P": listed(p), "J_lam_x1": listed(a), "q": listed(q)}
    near = Outcome.compare(norm(s.x1 - p), norm(s.x1 - a), 4 * tolerance(s.x1, a, p),
                           "|x - P x| ≤ |x - J_λx| (J_λx ∈ dom F)", info)
    tau = tolerance(s.x1, s.x2, p, q)
    d, e = s.x1 - p, q - p
    vi = Outcome.compare(float(d @ e), 0.0, 4 * tau * (norm(d) + norm(e) + tau),
                         "⟨x - P x, q - P x⟩ ≤ 0 for q = J_μx2 ∈ dom F", info)
    return vi if not vi.worst <= near.worst else near


#: the multiple ``K`` of ``rtol·(1 + |x|)/λ`` in each Yosida law's slack on ``Y_λ`` (their passed records state the smallest
#: λ at which a violation of ``|Y|`` is judgeable: :data:`verimono.checks.engine.search.YOSIDA_SLACK`)
YOSIDA_SLACK.update({"yosida_in_graph": 2.0, "yosida_monotone": 4.0, "yosida_nonincreasing": 4.0,
                     "yosida_bounded_by_min_norm": 6.0, "yosida_limit": 2.0, "yosida_member": 4.0})


# -- the vectorised forms (verimono.checks.engine.batches): the same inequalities over many samples at once ----
# Each returns the ratio of every row of ``r`` (a Rows); the search re-evaluates by the law's own evaluator every
# row not clearly inside the bound, so these only ever pass a sample, and with the laws' own slack.  Each repeats
# its law's elementwise operations in the same order (bit-identical) and states the rounding bound of its sums
# (:func:`verimono.checks.engine.batches.rounding`: the norms relatively, each dot product by ``|a||b|``), so
# that a row is accepted up to that bound from the law's own ratio.

def _pair(op, r, lam2=None):
    """``J_λ x1`` and ``J_{λ2} x2`` (λ2 defaults to λ) of every row."""
    a = row_resolvents(op, r.x1, r.lam, r.t, r.ok)
    b = row_resolvents(op, r.x2, r.lam if lam2 is None else lam2, r.t, r.ok)
    return a, b


@vectorised("resolvent_nonexpansive")
def _rows_resolvent_nonexpansive(op, r):
    a, b = _pair(op, r)
    tau = row_tolerances(r.x1, r.x2, a, b)
    q = row_ratios(row_norms(a - b), row_norms(r.x1 - r.x2), 4 * tau)
    rounding(r, q, np.ones_like(q))
    return q


@vectorised("resolvent_firmly_nonexpansive")
def _rows_resolvent_firmly_nonexpansive(op, r):
    a, b = _pair(op, r)
    dJ, dx = a - b, r.x1 - r.x2
    tau = row_tolerances(r.x1, r.x2, a, b)
    nJ, nx = row_norms(dJ), row_norms(dx)
    rhs, slack = row_dots(dJ, dx), 4 * tau * (nJ + nx + tau)
    q = row_ratios(row_dots(dJ, dJ), rhs, slack)
    rounding(r, q, rhs + slack, nJ * nJ, (1.0 + np.abs(q)) * nJ * nx)
    return q


@vectorised("resolvent_identity")
def _rows_resolvent_identity(op, r):
    a = row_resolvents(op, r.x1, r.lam, r.t, r.ok)
    q = r.mu / r.lam
    z = q[:, None] * r.x1 + (1.0 - q)[:, None] * a
    b = row_resolvents(op, z, r.mu, r.t, r.ok)
    tau = row_tolerances(r.x1, a, z)
    out = row_ratios(row_norms(a - b), np.zeros_like(tau), tau * (4.0 + np.abs(1.0 - q)))
    rounding(r, out, np.ones_like(out))
    return out


@vectorised("monotone")
def _rows_monotone(op, r):
    a, b = _pair(op, r, r.mu)
    ya, yb = (r.x1 - a) / r.lam[:, None], (r.x2 - b) / r.mu[:, None]
    dx, dy = a - b, ya - yb
    ex = 2 * row_tolerances(r.x1, r.x2, a, b)
    ey = ex * (1.0 / r.lam + 1.0 / r.mu)
    ndx, ndy = row_norms(dx), row_norms(dy)
    slack = 2 * (ex * ndy + ey * ndx + ex * ey)
    q = row_ratios(-row_dots(dx, dy), np.zeros_like(ex), slack)
    rounding(r, q, slack, ndx * ndy)
    return q


@vectorised("yosida_lipschitz")
def _rows_yosida_lipschitz(op, r):
    a, b = _pair(op, r)
    dY = ((r.x1 - a) - (r.x2 - b)) / r.lam[:, None]
    q = row_ratios(r.lam * row_norms(dY), row_norms(r.x1 - r.x2), 4 * row_tolerances(r.x1, r.x2, a, b))
    rounding(r, q, np.ones_like(q))
    return q


@vectorised("yosida_monotone")
def _rows_yosida_monotone(op, r):
    a, b = _pair(op, r)
    dx = r.x1 - r.x2
    dY = (dx - (a - b)) / r.lam[:, None]
    tau = row_tolerances(r.x1, r.x2, a, b)
    ndx = row_norms(dx)
    slack = 4 * tau * ndx / r.lam
    q = row_ratios(-row_dots(dY, dx), np.zeros_like(tau), slack)
    rounding(r, q, slack, row_norms(dY) * ndx)
    return q


@vectorised("yosida_nonincreasing")
def _rows_yosida_nonincreasing(op, r):
    lo, hi = np.minimum(r.lam, r.mu), np.maximum(r.lam, r.mu)
    hi = np.where(hi == lo, 2.0 * lo, hi)
    a = row_resolvents(op, r.x1, lo, r.t, r.ok)
    b = row_resolvents(op, r.x1, hi, r.t, r.ok)
    ylo, yhi = (r.x1 - a) / lo[:, None], (r.x1 - b) / hi[:, None]
    tau = row_tolerances(r.x1, a, b)
    q = row_ratios(row_norms(yhi), row_norms(ylo), 4 * tau * (1.0 / lo + 1.0 / hi))
    rounding(r, q, np.ones_like(q))
    return q


@vectorised("resolvent_limit")
def _rows_resolvent_limit(op, r):
    x = row_resolvents(op, r.x1, r.nu, r.t, r.ok)
    y0 = (r.x1 - x) / r.nu[:, None]
    tau, ny = row_tolerances(r.x1, x), row_norms(y0)
    worst = np.full(len(tau), -np.inf)
    for k in range(6):
        lam = r.lam * 4.0 ** (-k)
        d = row_norms(row_resolvents(op, x, lam, r.t, r.ok) - x)
        q = row_ratios(d, lam * ny, tau * (4.0 + lam / r.nu))
        worst = np.where(np.isnan(q) | (q > worst), q, worst)
    rounding(r, worst, np.ones_like(worst))
    return worst


# the laws whose evaluator calls a member besides the resolvent (row_member: one call per block where the operator
# takes a time per row, else per row; row_contains: one call per row) or
# decides by a truth value: a membership accepted at the law's own tolerance is the law's ratio 1 exactly (its
# grade), so it is stated with no rounding bound (the tolerance is the same elementwise arithmetic, bit for bit);
# a membership refused, a member that raised, a limit not closed at the first step: the law's evaluator decides

@vectorised("resolvent_single_valued")
def _rows_resolvent_single_valued(op, r):
    _first_value_kept(op, r)
    # two calls on (copies of) the same rows; row_resolvents marks a row whose call modified its input
    a = row_resolvents(op, r.x1, r.lam, r.t, r.ok)
    b = row_resolvents(op, r.x1, r.lam, r.t, r.ok)
    t = row_tolerances(r.x1, a, b, rtol=RTOL)
    tau = np.maximum(t, REPEAT_ULPS * current_eps() * (t / RTOL))
    q = row_ratios(row_norms(a - b), np.zeros_like(tau), tau)
    rounding(r, q, np.ones_like(q))
    return q


def _first_value_kept(op, r) -> None:
    """The block's first two rows' calls, as :func:`_value_kept` makes them (:func:`row_resolvents` copies a block's
    values into one array, where a buffer handed out twice cannot show): a first value that changed over the second
    call leaves its row to the law's own evaluator, which judges it."""
    rows = np.flatnonzero(r.ok)
    if rows.size < 2:
        return
    i, j = int(rows[0]), int(rows[1])
    try:
        a = op.resolvent(r.x1[i].copy(), float(r.lam[i]), float(r.t[i]))
        if type(a) is not np.ndarray or a.dtype != np.float64:
            return           # converted: a copy, which a later call cannot change
        before = a.copy()
        op.resolvent(r.x1[j].copy(), float(r.lam[j]), float(r.t[j]))
    except Exception:        # noqa: BLE001 - the rows' own calls (and the evaluator) judge what raised
        return
    if not np.array_equal(a, before, equal_nan=True):
        r.ok[i] = False


@vectorised("resolvent_in_domain")
def _rows_resolvent_in_domain(op, r):
    a = row_resolvents(op, r.x1, r.lam, r.t, r.ok)
    p = row_member(op.project_domain, a, r.t, r.ok)
    q = row_ratios(row_norms(p - a), np.zeros(len(r.ok)), 2 * row_tolerances(r.x1, a))
    rounding(r, q, np.ones_like(q))
    return q


def _granted(ok: np.ndarray, inside: np.ndarray) -> np.ndarray:
    """Ratio 1 (the law's grade at its own tolerance) where the membership was accepted; the other rows go to the
    law's evaluator (``ok`` cleared: it grades them)."""
    ok &= inside
    return np.ones(len(ok))


@vectorised("yosida_in_graph")
def _rows_yosida_in_graph(op, r):
    a = row_resolvents(op, r.x1, r.lam, r.t, r.ok)
    y = (r.x1 - a) / r.lam[:, None]
    tol = row_tolerances(r.x1, a, r.lam[:, None] * y) * (2.0 + 2.0 / r.lam)
    q = _granted(r.ok, row_contains(op, a, y, r.t, tol, r.ok))
    r.err = np.zeros(len(q))
    return q


def _rows_domain_pair(op, r):
    """``x = J_ν x1``, ``y0 = Y_ν x1`` and the tolerance of ``x`` of every row (:func:`_domain_pair`)."""
    x = row_resolvents(op, r.x1, r.nu, r.t, r.ok)
    return x, (r.x1 - x) / r.nu[:, None], row_tolerances(r.x1, x)


@vectorised("min_norm_in_graph")
def _rows_min_norm_in_graph(op, r):
    x, _, _ = _rows_domain_pair(op, r)
    f0 = row_member(op.min_norm, x, r.t, r.ok)
    q = _granted(r.ok, row_contains(op, x, f0, r.t, 2 * row_tolerances(x, f0), r.ok))
    r.err = np.zeros(len(q))
    return q


@vectorised("yosida_bounded_by_min_norm")
def _rows_yosida_bounded_by_min_norm(op, r):
    x, _, tau = _rows_domain_pair(op, r)
    f0 = row_member(op.min_norm, x, r.t, r.ok)
    a = row_resolvents(op, x, r.lam, r.t, r.ok)
    y = (x - a) / r.lam[:, None]
    q = row_ratios(row_norms(y), row_norms(f0),
                   4 * row_tolerances(x, a) / r.lam + 2 * tau / r.lam + row_tolerances(f0))
    rounding(r, q, np.ones_like(q))
    return q


@vectorised("min_norm_least")
def _rows_min_norm_least(op, r):
    x, y0, tau = _rows_domain_pair(op, r)
    f0 = row_member(op.min_norm, x, r.t, r.ok)
    # y0 certified in F(t, x) where contains can tell (the law's sample is inconclusive otherwise: its evaluator says so)
    r.ok &= row_contains(op, x, y0, r.t, row_tolerances(x, y0) * (2.0 + 2.0 / r.nu), r.ok, lacking=True)
    q = row_ratios(row_norms(f0), row_norms(y0), 4 * tau / r.nu + row_tolerances(f0))
    rounding(r, q, np.ones_like(q))
    return q


@vectorised("yosida_limit")
def _rows_yosida_limit(op, r):
    # the law's halving of λ from its first λ (λ, or the law's own floor when λ is below it), over every row at once
    # (each halving one row_resolvents pass over the rows still open;
    # λ halved as the law halves it, bit for bit): a row is decided at the first λ where its gap closes clearly (its
    # ratio plus its rounding bound within 1) — the law's ratio there; it is halved again only while its gap is
    # clearly open, |Y_λx| clearly above the law's rounding branch and λ/2 clearly above the floor.  Every other row
    # (a gap within rounding of its slack, near that branch or the floor, never closed: the stall analysis; F^0 0
    # within rounding) is the evaluator's
    x, _, _ = _rows_domain_pair(op, r)
    F0 = row_member(op.min_norm, x, r.t, r.ok)
    f0 = row_norms(F0)
    tx = row_tolerances(x)
    floor = 2 * LIMIT_FLOOR * tx / (1.0 + f0)
    near = 1.0 + 1e-9
    lam = r.lam.copy()      # the law's first λ, bit for bit: λ itself above the floor, else the law's own floor
    for j in np.flatnonzero(r.ok & ~(r.lam > floor * near)).tolist():
        lam[j] = max(float(r.lam[j]), 2 * LIMIT_FLOOR * tolerance(x[j]) / (1.0 + norm(F0[j])))
    n = x.shape[1]
    q, err, live = np.full(len(r.ok), np.inf), np.full(len(r.ok), np.inf), r.ok.copy()
    for _ in range(YOSIDA_HALVINGS):
        i = np.flatnonzero(live)
        if i.size < 2:
            break
        oki = np.ones(i.size, dtype=bool)
        li = lam[i]
        a = row_resolvents(op, x[i], li, r.t[i], oki)
        y = row_norms((x[i] - a) / li[:, None])
        gap, slack = np.abs(f0[i] - y), row_tolerances(f0[i], y) + 2 * tx[i] / li
        qi = row_ratios(gap, np.zeros_like(gap), slack)
        ei = rounding_bound(n, qi, slack, f0[i] + y)
        done = oki & np.isfinite(qi) & np.isfinite(ei) & (qi + ei <= 1.0)
        q[i[done]], err[i[done]] = qi[done], ei[done]
        half = li / 2
        go = oki & ~done & (qi - ei > 1.0) & (y > 2 * tx[i] / li * near) & (half >= floor[i] * near) & (half > 0.0)
        r.ok[i[~(done | go)]] = False
        live[i] = go
        lam[i] = half
    r.ok &= ~live        # rows still open after the most halvings: the evaluator's
    r.err = err
    return q

@vectorised("contains_rejects")
def _rows_contains_rejects(op, r):
    # the law's pair in row arithmetic (its norms in another summation order: the pair and its factor within rounding
    # of the law's); a row decided here is one whose pair contains rejects, the law's ratio 0 exactly, with a factor
    # clearly above CONTAINS_DECIDABLE; a row near that threshold, or accepted (a violation), is the evaluator's
    # A row whose pair the evaluator finds undecidable — |J_λx1 - J_λx2| = 0 (exactly: a norm is 0 only for a zero
    # row, in either order), or a finite factor clearly below CONTAINS_DECIDABLE — is stated inconclusive here, with
    # the evaluator's message, and not evaluated again (about half of the law's samples: tiny or large λ)
    u1, u2 = _pair(op, r)
    tol_c = 2 * row_tolerances(u1, (r.x2 - u2) / r.lam[:, None]) / _contains_spread(op, r.x1.shape[1])
    v, q, ndu, _ = _breaking_pair(r.x1.shape[1], r.x1, r.x2, u1, u2, r.lam, tol_c)
    r.inconclusive = r.ok & ((ndu == 0.0) | (np.isfinite(q) & (q <= CONTAINS_DECIDABLE * (1.0 - 1e-6))))
    r.inconclusive_what = _CONTAINS_INCONCLUSIVE
    r.ok &= (ndu > 0) & np.isfinite(q) & (q >= CONTAINS_DECIDABLE * (1.0 + 1e-6))
    inside = row_contains(op, u1, v, r.t, tol_c, r.ok)
    r.ok &= ~inside
    r.err = np.zeros(len(r.ok))
    return np.zeros(len(r.ok))


@vectorised("project_domain_nearest")
def _rows_project_domain_nearest(op, r):
    p = row_member(op.project_domain, r.x1, r.t, r.ok)
    a, q = _pair(op, r, r.mu)
    n1, na = row_norms(r.x1 - p), row_norms(r.x1 - a)
    q1 = row_ratios(n1, na, 4 * row_tolerances(r.x1, a, p))
    tau = row_tolerances(r.x1, r.x2, p, q)
    d, e = r.x1 - p, q - p
    nd, ne = row_norms(d), row_norms(e)
    slack = 4 * tau * (nd + ne + tau)
    q2 = row_ratios(row_dots(d, e), np.zeros_like(tau), slack)
    n = r.x1.shape[1]
    r.err = np.maximum(rounding_bound(n, q1, np.ones_like(q1)), rounding_bound(n, q2, slack, nd * ne))
    return np.maximum(q1, q2)
