"""An operator's members as the laws evaluate them: every returned value checked to be a finite point of
the input's shape and converted to NumPy float64 for the laws' arithmetic — from any array library, its
precision reported to the judgement in progress (:func:`verimono.core.arrays.as_float64`), so that a float32
subject is judged at float32 precision — norms computed without underflow, points shortened for
counterexamples."""

from __future__ import annotations

import math
import zlib
from typing import Any

import numpy as np

from ..core.arrays import as_float64
from ..core._small import abs_max, all_finite
from ..core.errors import NotApplicable, OutsideDomain
from ..core.tolerances import current_data_scale, current_eps, tolerance
from .engine.samples import NUMPY_DIM


class _BadOutput(Exception):
    """An operator member returned something that is not a finite point of the right shape."""


def point(value: Any, like: np.ndarray, member: str) -> np.ndarray:
    """``value`` as a float64 array of ``like``'s shape with finite entries (its precision observed);
    ``_BadOutput`` otherwise."""
    y = as_float64(value)
    if y.shape != like.shape:
        raise _BadOutput(f"{member} returned shape {y.shape} for a point of shape {like.shape}")
    if not all_finite(y):      # np.isfinite(y).all() (core._small: Python floats at R^1-R^8)
        raise _BadOutput(f"{member} returned non-finite values {y}")
    return y


def resolvent(op: Any, x: np.ndarray, lam: float, t: float) -> np.ndarray:
    """``J_λ x`` (on a copy of ``x``: an operator that modifies its input cannot corrupt the sample)."""
    return point(op.resolvent(x.copy(), lam, t), x, "resolvent")


def min_norm(op: Any, x: np.ndarray, t: float) -> np.ndarray:
    """``F^0(t, x)``; a point the operator rejects (:class:`OutsideDomain`) that lies within round-off of the
    closure of its domain is no sample of the law (:func:`within_roundoff_of_domain`)."""
    try:
        return point(op.min_norm(x.copy(), t), x, "min_norm")
    except OutsideDomain:
        if within_roundoff_of_domain(op, x, t):
            raise NotApplicable(_ROUNDOFF_BOUNDARY) from None
        raise


#: why a sample at such a point is inconclusive
_ROUNDOFF_BOUNDARY = ("the point lies outside dom F(t,·) by round-off only (within the tolerance of its closure: "
                      "the boundary of an open domain, reached by rounding a resolvent's value)")


def within_roundoff_of_domain(op: Any, x: np.ndarray, t: float) -> bool:
    """Whether ``x`` lies within the tolerance of its size of ``cl dom F(t,·)`` — judged by the operator's
    ``project_domain`` (``False`` without one: nothing then excuses a point outside the domain).

    A resolvent's value ``J_λx ∈ dom F`` may land, once rounded, on the boundary of an *open* domain
    (``J_λx = s + 10^-20`` for the log barrier of ``(s, ∞)`` rounds to ``s`` for tiny ``λ``): the members
    that need ``x ∈ dom F`` then reject it although nothing is wrong.  Such a sample cannot test the law at
    the precision the subject computes in, so it is inconclusive; a point farther out is the resolvent's fault
    and stays a failure."""
    project = getattr(op, "project_domain", None)
    if project is None:
        return False
    try:
        p = as_float64(project(x.copy(), t))
    except Exception:      # noqa: BLE001 - no projection here: nothing excuses the point
        return False
    return p.shape == x.shape and bool(np.all(np.isfinite(p))) and norm(p - x) <= tolerance(x)


def value(op: Any, z: Any, t: float) -> float:
    """``g(t, z)`` of an operator ``F = ∂g`` that states ``g``."""
    v = op.value(np.array(z, dtype=float), t)
    if type(v) is not float:
        v = as_float64(v)
    return float(v)


#: multiples of the round-off ``eps·(1 + |x|)`` within which a point rejected by the value function is looked
#: for a neighbour it accepts (:func:`outside_by_roundoff_of_dom_g`)
ROUNDOFF_ULPS = (1.0, 4.0, 16.0)


def outside_by_roundoff_of_dom_g(op: Any, p: np.ndarray, t: float, scale: float,
                                 normal: np.ndarray | None = None) -> bool:
    """Whether ``g(p) = +inf`` only by round-off: ``g`` is finite at a point within ``k·eps·(1 + scale)`` of ``p``
    (``k`` in :data:`ROUNDOFF_ULPS`, ``eps`` the unit round-off of the precision under judgement), along
    ``±normal`` (the outer normal ``x − p`` of a projection), ``±p`` or spare directions
    (:func:`_spare_directions`), or at a point the resolvent proposes within that reach (thin domains, below).

    A resolvent exact to its precision leaves its set by up to ``eps·|x|`` (a float32 projection from
    ``|x| = 10^6`` by ~0.1), and a strict indicator (``+inf`` at every point outside) rejects that point: not
    a violation of the law but of nothing (section "Judged at the subject's precision" of docs/precision.md).
    A point farther out stays the resolvent's fault."""
    base = current_eps() * (1.0 + max(float(scale), current_data_scale()))   # the operator's own scale (tolerances.py)
    reach = ROUNDOFF_ULPS[-1] * base
    dirs = []
    for v in (normal, p):
        if v is None:
            continue
        m = norm(v)
        if m > 0.0 and math.isfinite(m):
            dirs += [-np.asarray(v, dtype=float) / m, np.asarray(v, dtype=float) / m]
    dirs += _spare_directions(p)
    if _finite_near(op, p, t, base, dirs):
        return True
    # a thin domain (an affine set, the simplex's hyperplane: g finite only within round-off of it) is met by no
    # probe along a few directions; the subject's own resolvent proposes its nearest point, J_μ p, which the
    # value function then judges (J is only asked for a candidate: a wrong J proposes a point g rejects, or one
    # farther than the reach).  Its round-off is eps·|p|, not eps·|x|: from p far smaller than the x it came from,
    # J_μ p lands within the equalities' round-off
    for mu in _PROPOSAL_STEPS:
        try:
            q = resolvent(op, p, mu, t)
        except Exception:   # noqa: BLE001 - no proposal: nothing excused
            continue
        if _finite_near(op, q, t, current_eps() * (1.0 + norm(q)), dirs, at_p=True, centre=p, reach=reach):
            return True
    return False


#: coordinates probed, besides the normal, ``p`` and :data:`SPARE_RANDOM` seeded directions
SPARE_COORDINATES = 4
SPARE_RANDOM = 2


def _spare_directions(p: np.ndarray) -> list[np.ndarray]:
    """``±e_i`` (the first :data:`SPARE_COORDINATES`) and ``±`` seeded unit directions (deterministic in ``p``).

    The normal ``x − p`` is no direction when the resolvent returned ``x`` itself: a point on a half-space's
    boundary whose projection moves it by less than an ulp of ``x`` is its own correctly rounded projection,
    outside by one rounding of ``a·x`` (float64 PyTorch, ``|x| = 37``: ``a·p − b = 9.4e-16``), and ``±p`` may be
    nearly tangent to the set; any direction with an inward component gets in within the reach."""
    n = p.size
    out = []
    for i in range(min(n, SPARE_COORDINATES)):
        e = np.zeros(n)
        e.flat[i] = 1.0
        out += [e, -e]
    rng = np.random.default_rng(zlib.crc32(np.ascontiguousarray(p, dtype=float).tobytes()))
    for _ in range(SPARE_RANDOM):
        v = rng.standard_normal(n)
        v /= norm(v)
        out += [v, -v]
    return [d.reshape(p.shape) for d in out]


#: the steps ``μ`` at which the subject's resolvent proposes a point of ``dom g`` near a rejected ``p``: any ``μ``
#: for an indicator (``J_μ`` is the projection), a small one for another ``g`` (``J_μ p → proj_{cl dom g} p``)
_PROPOSAL_STEPS = (1.0, 1e-6)


def _finite_near(op: Any, p: np.ndarray, t: float, base: float, dirs: list[np.ndarray], at_p: bool = False,
                 centre: np.ndarray | None = None, reach: float = math.inf) -> bool:
    """``g`` finite at ``p + k·base·d`` (``k`` in :data:`ROUNDOFF_ULPS`, ``d`` in ``dirs``), or at ``p`` itself
    when ``at_p``, among the points within ``reach`` of ``centre``."""
    points = ([p] if at_p else []) + [p + k * base * d for k in ROUNDOFF_ULPS for d in dirs]
    for z in points:
        if centre is not None and not norm(z - centre) <= reach:
            continue
        try:
            if math.isfinite(value(op, z, t)):
                return True
        except Exception:   # noqa: BLE001 - a neighbour the value function cannot judge excuses nothing
            continue
    return False


#: above this many entries :func:`norm` scales its vector only when ``|v|_inf`` leaves ``SAFE_SQUARES``
UNSCALED_N = 1 << 14
#: ``|v|_inf`` within which ``Σ v_i²`` neither overflows nor loses more than ``eps`` of itself to underflow, for any n
#: below 2^100: each square ``<= 2^800 n``, and a square that underflows is ``< 2^-1074 < eps·2^-800``
SAFE_SQUARES = (2.0 ** -400, 2.0 ** 400)


def norm(v: Any) -> float:
    """Euclidean norm without underflow: sampled points may differ by 1e-250, whose square is 0.

    ``|v|_inf · |v / |v|_inf|``, the scaled sum of squares; above :data:`UNSCALED_N` entries (2^14, the
    coordinates above which :mod:`verimono.execution.profiles` caps the search as well) ``sqrt(v·v)`` when
    ``|v|_inf`` lies in :data:`SAFE_SQUARES`, where scaling changes nothing but the rounding (a few ulps):
    the division was a third of a law's norm at n = 10^6.  At or below it the numbers are the scaled ones."""
    v = np.asarray(v, dtype=float)
    if v.size > 4096:       # max(max v, -min v): the same maximum without an n-sized |v| (a law calls this per point)
        m = float(max(v.max(), -v.min()))
    else:
        m = abs_max(v) if v.size else 0.0       # np.abs(v).max(initial=0.0)'s number (core._small)
    if m == 0.0 or not math.isfinite(m):
        return 0.0
    if v.size > UNSCALED_N and SAFE_SQUARES[0] < m < SAFE_SQUARES[1]:
        return float(np.linalg.norm(v))
    # np.linalg.norm(v / m) of a float64 array is sqrt(w·w) of w = (v / m).ravel(order="K"): the same dot and the
    # same correctly rounded square root, without its dispatch (a law calls this per point, ~40,000 times a stage)
    w = (v / m).ravel(order="K")
    return m * math.sqrt(w.dot(w))


def listed(a: np.ndarray) -> Any:
    """A point for a counterexample: its coordinates, or for ``n > NUMPY_DIM`` a summary (the sample's
    recipe replays it; a million coordinates per record would swamp the report)."""
    if a.size <= NUMPY_DIM:
        return a.tolist()
    if a.dtype.kind == "f" and a.size > 4096:   # max(max a, -min a) + 0.0: the same number (and +0 for ±0), no |a| copy
        m = float(max(a.max(), -a.min())) + 0.0
    else:
        m = float(np.max(np.abs(a)))
    return f"<{a.size} values, |.|_inf = {m:.6g}>"


__all__ = ["point", "resolvent", "min_norm", "within_roundoff_of_domain", "outside_by_roundoff_of_dom_g",
           "ROUNDOFF_ULPS", "value", "norm", "listed"]
