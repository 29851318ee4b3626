"""The one place where verimono's numerical tolerances are stated, with their reasons.

Every identity the checks test (nonexpansiveness, the resolvent identity, ``Y_λ x ∈ F(J_λ x)``, ...)
holds exactly in exact arithmetic.  Computed in float64 by closed forms, by factorised linear solves or
by QP solves whose KKT residual verimono verifies to ``QP_RTOL``, each side carries a relative error of a
few ulps up to ``QP_RTOL`` times the magnitude of the data.  ``RTOL = 1e-8`` leaves about two orders of
magnitude of headroom over the verified QP accuracy, and is still 10^4 times smaller than any
violation a genuinely wrong resolvent produces on inputs of unit size.

A comparison ``a <= b`` is accepted when ``a <= b + tolerance(scale)``, where ``scale`` is the size of
the inputs involved (``max |x|``, ``|λ| |y|``, ...): absolute tolerances would be wrong for inputs of
size 1e6 and meaningless for inputs of size 1e-6.

**Precision.**  Everything above is the judgement of a subject computing in float64.  A subject computing
in float32 or half precision rounds ``~ 2^29`` resp. ``2^42`` times more coarsely; judged at ``RTOL`` its
rounding alone breaks the exact identities (a correct float32 projection fails ``resolvent_identity`` with
``lhs 2.11e-05 > slack 1.89e-05``).  The relative tolerance is therefore a function of the precision the
subject computes in (:func:`rtol_for`), chosen to keep float64's balance between the two risks:

* *headroom over the subject's rounding* — correct code must pass: ``RTOL`` is ``4.5·10^7`` float64 ulps
  (``RTOL/EPS``), 7.65 decades above float64's unit roundoff;
* *distance to real violations* — wrong code must fail: a genuinely wrong resolvent violates the laws by
  ``10^-2 … 1`` relative (a lost factor 2 in ``λ``, the wrong set, a forgotten input term), which is
  ``10^6 … 10^8`` times ``RTOL``, 8 decades below violations of unit size.

float64 places its tolerance in the geometric middle of that range (``RTOL ≈ 0.67·sqrt(EPS)``: 7.65 decades
of headroom, 8 decades of distance).  Every other precision is put at the same place, ``rtol(p) =
RTOL·sqrt(eps(p)/EPS)`` (:data:`RTOL_BY_PRECISION`): float32 ``2.3e-4`` (3.3 decades = 1950 ulps of
headroom, 3.6 decades below unit violations, so a violation of ``10^-2`` is still 43 times its slack),
float16 ``2.1e-2`` and bfloat16 ``5.9e-2`` (1.3 resp. 0.9 decades either side: half precision can only
tell violations of about 10% and more from rounding — a limit of the arithmetic, not of the harness).
A smaller float32 tolerance (``1e-5``, 84 ulps) would leave correct float32 code, whose errors grow with
the conditioning of the law's arithmetic, little headroom over its rounding; a larger one (``10^-3``) would
sit within 10 times of the ``10^-3``-sized violations of the zoo's stepper that leaves the domain.
Measured (``docs/prox-libraries.md``): judged at float64's ``RTOL``, correct float32 proxes of jaxopt and
ProxTorch fail up to 10 laws by 1.2–5.6 times their slack; at float32's they pass, and the float32
versions of the zoo's broken operators and steppers are all still caught (``tests/core/test_precision.py``).

The precision of a subject is what it computes in, detected from what it returns (the dtype of its outputs)
and from what it is given (the dtype its declared array library converts inputs to), the coarser deciding:
every conversion of a subject's output to float64 for the arithmetic of the laws reports the dtype it
dropped (:func:`observe`) to the precision under which the law is judged (:func:`judged_precision`, opened
for every law by :func:`verimono.checks.core.run`, which states it in the record), and :func:`tolerance`
uses that precision's ``rtol``.  Outside a judged evaluation,
and for a float64 subject, ``tolerance`` is exactly the float64 one.
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import math
from typing import Any, Iterator

import numpy as np

from ._small import abs_max, row_abs_max

#: relative tolerance of exact identities computed in floating point (see module docstring)
RTOL = 1e-8
#: relative KKT residual below which a QP/LCP solution from a back-end is accepted
QP_RTOL = 1e-10
#: machine epsilon of float64
EPS = float(np.finfo(float).eps)


# -- precision: the tolerance of a subject computing in float32 or half precision ---------------------

#: unit roundoff (machine epsilon) of the floating-point precisions a subject may compute in, by dtype name
EPS_BY_PRECISION = {"float64": 2.0 ** -52, "float32": 2.0 ** -23, "float16": 2.0 ** -10, "bfloat16": 2.0 ** -7}
#: the relative tolerance a subject computing in each precision is judged at (module docstring):
#: ``RTOL·sqrt(eps/EPS)``, the place of float64's ``RTOL`` between rounding and unit-sized violations
RTOL_BY_PRECISION = {p: RTOL * math.sqrt(e / EPS_BY_PRECISION["float64"]) for p, e in EPS_BY_PRECISION.items()}
RTOL_BY_PRECISION["float64"] = RTOL
#: two calls of a subject at the same input agree bit for bit in any precision when it is deterministic;
#: reductions summed in a varying order (threads, GPUs) differ by a few ulps of its precision.  The
#: single-valuedness law allows this many ulps (never less than the float64 tolerance ``RTOL``, so float64
#: subjects are judged as before): 4 float32 ulps are ``4.8e-7``, where a random perturbation of 1e-6
#: — a float32 solver with a random start — stays visible
REPEAT_ULPS = 4


def precision_name(dtype: Any) -> str | None:
    """The precision of ``dtype`` (a NumPy, JAX, PyTorch or array-API dtype, or its name) as a key of
    :data:`EPS_BY_PRECISION`: complex types by their real part; ``None`` for integers, booleans and what is
    not a floating-point type (exact, or nothing a subject computes in)."""
    if dtype is None:
        return None
    name = getattr(dtype, "name", None)
    if not isinstance(name, str):
        name = str(dtype)
    name = name.rsplit(".", 1)[-1]                 # "torch.float32" -> "float32"
    name = {"complex128": "float64", "complex64": "float32"}.get(name, name)
    if name in EPS_BY_PRECISION:
        return name
    try:                                           # other floating types NumPy (or ml_dtypes) knows
        eps = float(np.finfo(dtype).eps)
    except (TypeError, ValueError):
        return None
    return min(EPS_BY_PRECISION, key=lambda p: abs(math.log(EPS_BY_PRECISION[p] / eps)))


def coarser(*precisions: str | None) -> str:
    """The coarsest of ``precisions`` (``None`` entries ignored; float64 when there is none)."""
    out = "float64"
    for p in precisions:
        if p is not None and EPS_BY_PRECISION[p] > EPS_BY_PRECISION[out]:
            out = p
    return out


def rtol_for(precision: str | None) -> float:
    """The relative tolerance of a subject computing in ``precision`` (:data:`RTOL_BY_PRECISION`)."""
    return RTOL_BY_PRECISION[precision or "float64"]


@dataclasses.dataclass
class Precision:
    """The precision a law judges its subject at: the coarsest one observed (float64 until a coarser dtype
    is seen), with its ``rtol`` and ``eps``."""

    name: str = "float64"

    def observe(self, precision: str | None) -> None:
        self.name = coarser(self.name, precision)

    @property
    def rtol(self) -> float:
        return RTOL_BY_PRECISION[self.name]

    @property
    def eps(self) -> float:
        return EPS_BY_PRECISION[self.name]

    def details(self) -> dict[str, Any]:
        """What a record states about the precision it was judged at."""
        return {"dtype": self.name, "rtol": self.rtol}

    def note(self) -> str:
        """A suffix for messages: empty for float64, else the precision and its tolerance."""
        return "" if self.name == "float64" else f" (judged at {self.name} precision: rtol {self.rtol:.2g})"


_JUDGED: contextvars.ContextVar[Precision | None] = contextvars.ContextVar("verimono_precision", default=None)


@contextlib.contextmanager
def judged_precision(initial: str | None = None) -> Iterator[Precision]:
    """Judge what runs inside at the precision the subject is observed to compute in (starting from
    ``initial``, float64 by default); yields the :class:`Precision`, which coarsens as :func:`observe` is
    told of coarser dtypes.  Nested, the inner judgement reports to the outer one as well."""
    outer = _JUDGED.get()
    p = Precision(coarser(initial))
    token = _JUDGED.set(p)
    try:
        yield p
    finally:
        _JUDGED.reset(token)
        if outer is not None:
            outer.observe(p.name)


def observe(dtype: Any) -> None:
    """Report that a subject returned (or was given) values of ``dtype``: the judgement in progress, if
    any, coarsens to it.  Called by every conversion of a subject's values to float64."""
    p = _JUDGED.get()
    if p is not None:
        name = precision_name(dtype)
        if name is not None and name != "float64":
            p.observe(name)


#: the largest finite number of each precision: points a subject is given stay below it by a margin
LARGEST_BY_PRECISION = {"float64": 1.7976931348623157e308, "float32": 3.4028235e38, "float16": 65504.0,
                        "bfloat16": 3.3895314e38}


#: the step sizes ``λ`` every law is searched over, per precision.  From below: every decade ``10^k`` above
#: ``sqrt(tiny)``, so that ``λ|y|`` and ``|x|/λ`` stay representable for the laws' points.  From above: up to
#: ``λ = RTOL/eps`` (float64 ``4.5·10^7``, float32 ``1.9·10^3``): a correct resolvent of a linear part ``A``,
#: computed by a backward-stable solve of ``(I + λA)``, carries a relative error up to ``eps·cond(I + λA) ≈
#: eps·λ|A|`` — within the laws' relative tolerance ``RTOL`` only while ``λ|A| ≤ RTOL/eps`` (measured: a dense
#: solve with a 2-dimensional kernel in ``R^40`` broke firm nonexpansiveness at ``λ = 4·10^18`` by round-off
#: alone).  Beyond it a violation cannot be told from the subject's legitimate rounding at its precision.
#: float64 ``[10^-153, 10^7]``, float32 ``[10^-18, 10^3]``
#: (never narrower than ``[10^-4, 10]``, the steps the samples are drawn from)
STEP_RANGE_BY_PRECISION = {
    p: (min(1e-4, 10.0 ** math.ceil(math.log10(math.sqrt(float(tiny))))),
        max(10.0, 10.0 ** math.floor(math.log10(RTOL_BY_PRECISION[p] / EPS_BY_PRECISION[p]))))
    for p, tiny in (("float64", np.finfo(np.float64).tiny), ("float32", np.finfo(np.float32).tiny),
                    ("float16", np.finfo(np.float16).tiny), ("bfloat16", np.finfo(np.float32).tiny))}


def current_step_range() -> tuple[float, float]:
    """The step sizes ``λ`` searched at the precision under judgement (:data:`STEP_RANGE_BY_PRECISION`)."""
    p = _JUDGED.get()
    return STEP_RANGE_BY_PRECISION["float64" if p is None else p.name]


def current_largest() -> float:
    """The largest finite number of the precision under judgement (float64's outside any)."""
    p = _JUDGED.get()
    return LARGEST_BY_PRECISION["float64" if p is None else p.name]


def current_precision() -> Precision:
    """The precision under judgement (float64 outside any)."""
    p = _JUDGED.get()
    return Precision() if p is None else p


def current_rtol() -> float:
    """The relative tolerance of the precision under judgement (``RTOL`` outside any)."""
    p = _JUDGED.get()
    return RTOL if p is None else p.rtol


def current_eps() -> float:
    """The unit roundoff of the precision under judgement (``EPS`` outside any)."""
    p = _JUDGED.get()
    return EPS if p is None else p.eps


# -- the operator's own scale: the magnitude of the data it computes with --------------------------------
# A correct subject rounds at the magnitude of what it computes with, not only of what it was given: the
# projection onto a ball of radius 1e6 centred at 1e6·e_1 forms x − c (|x − c| ≈ 1e6) for a point x of size 0.006
# near the origin, and returns c + r(x − c)/|x − c|, a cancellation that leaves an error of eps·1e6 (float32: 0.06)
# in a result of size 0.006.  Judged at the magnitude of the points alone (rtol·(1 + 0.006)) that correct code
# fails the exact identities by 12.9 times their slack (float32), 10^3 times in float64 at 1e12.  The points a law
# touched say nothing of the operator's data, so the data's magnitude ``S`` enters the one rule as one more
# scale: ``tolerance = rtol·(1 + max(|inputs|, S))``.  ``S`` is the operator's ``data_scale`` when it states one
# (``verimono.operator_from_resolvent(..., data_scale=S)``, or the attribute on any operator); else 0, and a law
# that fails is judged once more at the scale inferred from the operator's domain (verimono.checks.engine.data_scale):
# a violation within the rounding of that scale is *undecided*, never failed nor passed, and the record says so.

_DATA_SCALE: contextvars.ContextVar[float] = contextvars.ContextVar("verimono_data_scale", default=0.0)


@contextlib.contextmanager
def judged_at_scale(scale: float | None) -> Iterator[float]:
    """Judge what runs inside with the operator's own scale ``scale`` (``None`` or 0: the inputs' magnitudes
    alone) as one more magnitude of every :func:`tolerance`; yields the scale in force."""
    s = 0.0 if scale is None else float(scale)
    if not (math.isfinite(s) and s >= 0.0):
        raise ValueError(f"an operator's data scale is a finite number ≥ 0, got {scale!r}")
    token = _DATA_SCALE.set(s)
    try:
        yield s
    finally:
        _DATA_SCALE.reset(token)


def current_data_scale() -> float:
    """The operator's own scale under judgement (0 outside :func:`judged_at_scale`)."""
    return _DATA_SCALE.get()


def tolerance(*scales: float, rtol: float | None = None) -> float:
    """Tolerance for a comparison between quantities of size ``max(scales)``: ``rtol * (1 + max)``, with
    ``rtol`` the precision's under judgement (``RTOL`` for float64 and outside any judgement); the operator's own
    scale under judgement (:func:`judged_at_scale`) is one more of the ``scales``."""
    if rtol is None:
        rtol = current_rtol()
    m = _DATA_SCALE.get()
    for s in scales:
        if type(s) is np.ndarray:          # the common case, without np.max's dispatch (a law calls this per step)
            if s.dtype.kind == "f" and s.size > 4096:    # no |s| copy of a large array: max(max, -min), the same number
                a = float(max(s.max(), -s.min()))
            else:
                a = abs_max(s) if s.size else 0.0       # NumPy's number (core._small)
        elif type(s) is float:             # a weight c(t): abs is np.abs of one double, without its dispatch
            a = abs(s)
        else:
            a = float(np.max(np.abs(s))) if np.size(s) else 0.0
        if a > m:
            m = a
    return rtol * (1.0 + m)


def row_tolerances(*rows: np.ndarray, rtol: float | None = None) -> np.ndarray:
    """:func:`tolerance` of row ``k`` of every array at once: ``rtol * (1 + max_j |rows_j[k]|∞)`` for each ``k``
    (arrays of shape ``(K, n)``, or ``(K,)`` for scalars per row): what a law computes per step, in one pass (the
    operator's own scale under judgement one more magnitude, as in :func:`tolerance`)."""
    if rtol is None:
        rtol = current_rtol()
    m = None
    for r in rows:
        r = np.asarray(r, dtype=float)
        r = r.reshape(r.shape[0], -1)
        a = row_abs_max(r)       # each row's largest |entry| (0 for no entry), column by column when short
        m = a if m is None else np.maximum(m, a)
    if m is None:
        raise ValueError("row_tolerances needs at least one array")
    s = _DATA_SCALE.get()
    if s:
        m = np.maximum(m, s)
    return rtol * (1.0 + m)

#: relative LCP residual below which a back-end's candidate is refined by one active-set (principal
#: pivot) solve.  The refinement turns a nearly right answer into a round-off-exact one; it is not a
#: solver, so a candidate further off than this (a back-end reporting "solved" on garbage) is never
#: rescued by it and is rejected by the residual check instead.
POLISH_RTOL = 1e-6

#: largest condition number of a principal submatrix ``M_II`` whose factorisation the LCS stepping kernel
#: (:mod:`verimono.lcs.kernel`) caches as an affine map of the state: the map's entries then carry a relative
#: error ``≤ cond·EPS = RTOL/1000``, a thousandth of the margin ``RTOL`` its sign checks demand, so a candidate that
#: passes them is strictly complementary in exact arithmetic too (worse-conditioned patterns are solved
#: step by step by the verified solver instead)
ACTIVE_SET_COND = 1e-3 * RTOL / EPS

# -- trajectory laws and assumption evidence (verimono.checks.trajectory_laws / .assumptions) ----------


def quotient_tolerance(h: float, *scales: float, rtol: float | None = None) -> float:
    """Tolerance for a difference quotient ``(a - b)/h`` of quantities of size ``max(scales)``.

    Each of ``a``, ``b`` carries a relative error ``rtol``; dividing by the step ``h`` divides nothing
    away, so the quotient carries ``rtol (1 + max scale) / h``.  Used for the scheme's selections
    ``(x_k - x_{k+1})/h_{k+1} ∈ F(t_{k+1}, x_{k+1})`` and for Yosida values ``(x - J_λ x)/λ``.
    """
    return tolerance(*scales, rtol=rtol) / float(h)


#: the most steps a convergence study's run takes (the catalog's: K ≤ 1e4): its rounding floor
ROUNDOFF_STEPS = 10_000


def roundoff_floor(scale: float, precision: str | None = None) -> float:
    """The error below which a ``K``-step run (``K ≤ ROUNDOFF_STEPS``) in ``precision`` may show nothing but
    rounding, for states of size ``scale``: errors below it are not fitted by a convergence study.

    float64: the worst case, ``K·eps·scale`` (``2.2e-12``) — far below every discretisation error studied,
    so the pessimism costs nothing.  Coarser precisions: the worst case would swallow ordinary
    discretisation errors (``1.2e-3`` in float32, where the catalog's studies reach ``3e-6``), so the floor
    is the typical accumulation of independent roundings, ``sqrt(K)·eps·scale`` (float32: ``1.2e-5``; the
    catalog's float32 runs of exact schemes stay below ``5e-8``).  The operator's own scale under judgement
    (:func:`judged_at_scale`) is one more magnitude of ``scale``: each step rounds at it."""
    p = precision or "float64"
    k = ROUNDOFF_STEPS if p == "float64" else math.sqrt(ROUNDOFF_STEPS)
    return k * EPS_BY_PRECISION[p] * max(float(scale), _DATA_SCALE.get())   # the operator's own scale: one more


def repeat_tolerance(*scales: float) -> float:
    """Tolerance of two calls of a subject at the same input (single-valuedness): ``REPEAT_ULPS`` ulps of
    the precision under judgement times ``1 + max(scales)``, never less than the float64 :func:`tolerance`
    (``RTOL``): repeatability, unlike an identity, does not degrade with the precision's rounding."""
    t = tolerance(*scales, rtol=RTOL)
    return max(t, REPEAT_ULPS * current_eps() * (t / RTOL))


#: ``unique_limit`` assumes no rate (the paper gives none; ``c = 0.1 t^{-0.9}`` converges like ``h^{0.1}``):
#: the distance of a refinement sequence to its limit is estimated from its own last differences as a
#: geometric tail ``c r/(1 - r)`` (exact for errors ``C h^p`` on 4-fold refinements), times this factor
#: because the error constant still varies from level to level where the solution has a kink (the nodes
#: fall differently around it): the tail was 2.26 times too small at the extinction time of x' ∈ −∂(2|x|)
#: from 1/32 (random partition, K = 2560), and 1.3–2.4 times on the moving half-space at t = π/2 (seeds
#: 1–6).  A stepper whose partitions converge to different limits keeps an O(1) distance while its tails
#: shrink at its own rate: mean_step stays caught by a factor 2.15 (x' = c/x) to 2.6 (t|x|, n = 3)
LIMIT_TAIL_SAFETY = 4.0
#: the ratio of successive differences used in that tail is at least this (order 1 on 4-fold refinements):
#: the implicit Euler scheme is first order, and a faster fall between the coarse default levels (K = 10, 40:
#: meshes 0.63 on the moving half-space, ratios 0.02–0.08) is pre-asymptotic — extrapolating it
#: underestimated the tails 4-fold there (a false alarm on random-partition seeds 1 and 2).  A rate floor,
#: not a rate assumption: slower sequences keep their own, larger ratio
LIMIT_RATIO_FLOOR = 0.25
#: further 4-fold refinements (up to 64 times the finest of the default levels) granted to a problem whose
#: own time scale is finer than the default meshes (while some kind's differences still grow, or a distance
#: lies before the tails' first cells) before the unique-limit law is judged: a generated
#: sweeping process in a ball of radius 0.002 driven by a unit input is pre-asymptotic until |Δ| < 0.002
LIMIT_EXTRA_LEVELS = 3
#: a sampled ratio (``|F^0(t,x)|/(1+|x|)``, a Yosida increment per unit time) that grows by more than
#: this factor while the sampling parameter ``λ`` shrinks 1000-fold is reported as evidence that the
#: bound (LG) / (YB) fails; bounded quantities change by O(1) over that range
GROWTH_FLAG = 10.0

# -- the λ → 0 limits of prop:maxmon-resolvent-Yosida (items iii and vi) --------------------------------
# A limit cannot be observed in finitely many evaluations.  The operator-law checks halve λ from the
# sampled step down to the floor where the resolvent's own error bound 2·tolerance(x)/λ reaches
# (1 + |F^0(x)|)/LIMIT_FLOOR: below it Y_λ x = (x - J_λ x)/λ is dominated by rounding.  The gap
# |F^0(x)| - |Y_λ x| must fall within tolerance on the way, or still be shrinking at the floor: a gap that
# stays above STALL_RATIO times its value STALL_WINDOW halvings (a factor 2^8 in λ) earlier has stalled.
# A correct operator whose gap behaves like λ^p drops below that ratio for any p > 0.006.
#: the sweep stops where the rounding bound on |Y_λ x| is (1 + |F^0(x)|)/LIMIT_FLOOR
LIMIT_FLOOR = 16.0
#: a gap still above this fraction of its value STALL_WINDOW halvings earlier has stalled
STALL_RATIO = 0.99
#: number of halvings of λ over which stalling is judged
STALL_WINDOW = 8

#: relative accuracy of an interior-point SDP solution (KYP search in :mod:`verimono.lcs.passivity`).  Such
#: solvers stop at about 1e-8 relative duality gap; the LMI is then re-checked by an eigenvalue computation
#: against this looser tolerance, scaled to the size of the KYP matrix.
SDP_RTOL = 1e-6

#: a scheme claiming order p (``scheme="any"``) passes ``in_domain`` when the largest distance of its
#: iterates to ``cl dom F(t_k)`` at the finest level is at most this factor times the prediction
#: ``max_j D(K_j) (K_j/K_m)^p`` from the coarser levels: the constant of ``C h^p`` is unknown and drifts
#: by O(h) between levels; a distance that does not vanish (a constant offset) exceeds any fixed factor
DOMAIN_ORDER_SLACK = 2.0

#: ``pseudo_distance_hausdorff``: a sampled lower bound of ``dis(N_C1, N_C2) = d_H(C1, C2)`` must come within
#: this factor of ``d_H`` on the catalog pairs (:mod:`verimono.checks.pseudo_distance`).  With the boundary
#: points of both sets and projected-ascent steps towards their farthest points among the samples, the
#: bound misses ``d_H`` only by the ascent's last step and by ``1/(1 + |y|)`` with ``|y| ≈ 1e6``: measured
#: 0.99927 … 0.9999998 of ``d_H`` (seeds 0–19, 32 directions); an estimator half as large fails by 2
PSEUDO_DISTANCE_FACTOR = 1.01
