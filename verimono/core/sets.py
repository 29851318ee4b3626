"""Closed convex sets ``S(t)`` that may move with time, with exact projections.

Each set has ``.dim``, ``.project(x, t=0.0)`` (the Euclidean projection, for ``x`` of shape ``(n,)`` or
``(B, n)``) and ``.contains(x, t=0.0, tol=None)``.  Every parameter is a constant or a callable of ``t``;
a set with callable parameters is a moving set, the normal cone of which gives the sweeping process.

Batches of sets: ``Ball(center, radius)`` with ``center`` of shape ``(B, n)`` and/or ``radius`` of shape
``(B,)``, and ``Box(lower, upper)`` with bounds of shape ``(B, n)``, are ``B`` sets projecting the rows of
a ``(B, n)`` batch of points one each (one vectorized call).

Times per row: a catalog set whose :meth:`ConvexSet._accepts_times` says so takes ``t`` of shape ``(B,)`` beside
``x`` of shape ``(B, n)`` in ``project`` and ``contains`` — row ``i`` at time ``t[i]``, bit-identical to ``B``
separate calls (its moving parameters are called once per time; the arithmetic runs over all rows at once).
``contains`` then answers per row, an array of ``B`` booleans.  The assumption laws' time designs use it
(:mod:`verimono.checks.assumption_samples`); a set that does not declare it is called once per time.

Performance: projections are written without ``np.errstate`` and with inner products by the BLAS
``dot`` of each row (:func:`verimono.core.operators.dot_rows`), so a batch ``(B, n)`` and its rows one by one
give identical bits;
``_kernel`` returns a private fast path for :func:`verimono.solve` (constants prebound, scalar work in
Python floats — the same IEEE operations).
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ._params import as_param
from ._rows import _INF, _TINY, _mn, _mx, _sqrt, dot_rows, per_row, times_of
from ._validate import bad_lam, bad_param, batch_column, finite_point, real_array
from .errors import InvalidProblem
from .qp import solve_qp
from .tolerances import row_tolerances, tolerance


class ConvexSet:
    """Base class: a nonempty closed convex set ``S(t) ⊂ R^n``."""

    static = False

    def __init__(self, dim: int, name: str | None = None) -> None:
        self.dim = int(dim)
        self.name = name or type(self).__name__

    def project(self, x: np.ndarray, t: float = 0.0) -> np.ndarray:
        """Euclidean projection onto ``S(t)``."""
        raise NotImplementedError

    def contains(self, x: np.ndarray, t: float = 0.0, tol: float | None = None) -> bool:
        """Whether ``x ∈ S(t)`` up to ``tol`` (default scaled to ``|x|``).  With ``t`` of shape ``(B,)`` and
        ``x`` of shape ``(B, n)``: whether each row lies in ``S(t[i])`` (default tolerance of each row), an
        array of ``B`` booleans, as ``B`` separate calls answer."""
        x = np.asarray(x, dtype=float)
        ts = times_of(t, x, self.name)
        if ts is not None:
            if not self._accepts_times():
                return np.array([self.contains(xi, ti, tol) for xi, ti in zip(x, ts.tolist())], dtype=bool)
            tol = row_tolerances(x) if tol is None else tol
            return np.max(np.abs(self.project(x, ts) - x), axis=-1, initial=0.0) <= tol
        tol = tolerance(x) if tol is None else tol
        d = np.abs(self.project(x, t) - x)
        # the ndarray's own max (np.max's dispatch is most of a small point's cost): the same reduction
        return bool((d.max(initial=0.0) if type(d) is np.ndarray else np.max(d, initial=0.0)) <= tol)

    def _accepts_batches(self) -> bool:
        """Whether :meth:`project` maps a batch ``(B, n)`` row by row, bit-identically (the catalog sets'
        own projections do; a user's set or override is not assumed to)."""
        return False

    def _accepts_times(self) -> bool:
        """Whether :meth:`project` and :meth:`contains` take ``t`` of shape ``(B,)`` beside ``x`` of shape
        ``(B, n)``, row ``i`` at ``t[i]``, bit-identically to ``B`` separate calls (the catalog sets' own members
        do, unless they are a batch of sets; a user's set or override is not assumed to)."""
        return False

    def _kernel(self, x0: np.ndarray) -> Callable | None:
        """A fast ``step(x, lam, t) = proj_{S(t)} x`` (``lam`` ignored) for float arrays shaped like
        ``x0``, returning exactly what :meth:`project` returns; ``None`` means use :meth:`project`."""
        return None

    def __repr__(self) -> str:
        return f"{self.name}(dim={self.dim})"


def _past_roundoff(excess: np.ndarray, scale: float) -> bool:
    """Whether a moving parameter is beyond its limit by more than round-off (``excess > 0`` where it is past:
    a radius below 0, a lower bound above its upper bound), a NaN included.  Parameters that meet their limit
    at some ``t`` in exact arithmetic (a set shrinking to a point) may cross it there by a few ulps; within
    :func:`verimono.core.tolerances.tolerance` of their finite ``scale`` that is the limit itself."""
    return not np.all(excess <= tolerance(scale))


def _all_static(*params) -> bool:
    return all(p.constant for p in params)


def _own(obj: Any, cls: type) -> bool:
    return type(obj).project is cls.project


def _own_times(obj: Any, cls: type) -> bool:
    """``obj`` uses ``cls``'s own ``project`` and ``contains`` (those that take a time per row): neither overridden
    by a subclass nor replaced on the object itself (a user's wrapper is not assumed to take an array of times)."""
    mine = getattr(obj, "__dict__", {})
    return (type(obj).project is cls.project and type(obj).contains is cls.contains
            and "project" not in mine and "contains" not in mine)


def _at_times(param, ts: np.ndarray) -> np.ndarray:
    """``param`` at every time of ``ts``: a constant as it is, a moving one ``(B, *shape)``, a row per time."""
    return param(0.0) if param.constant else param.at_times(ts)


def _column(p: np.ndarray) -> np.ndarray:
    """A value per row ``(B,)`` as a column ``(B, 1)``; a scalar as it is."""
    return p[:, None] if np.ndim(p) else p


def _fast(param) -> Callable[[float], np.ndarray]:
    """``t -> param(t)``; a constant is bound once."""
    if param.constant:
        v = param(0.0)
        return lambda t: v
    return param


def _scaled_norm(d: np.ndarray) -> np.ndarray:
    """``|d|`` over the last axis (kept) without overflow: ``m·|d/m|`` with ``m = max|d_i|``, for rows whose
    ``d·d`` overflows (``|d| > 1.3e154``; the projection of such a point used to come back as the centre)."""
    m = np.max(np.abs(d), axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        q = d / np.where(m > 0, m, 1.0)
    return m * np.sqrt(np.sum(q * q, axis=-1, keepdims=True))


class Ball(ConvexSet):
    """Closed Euclidean ball ``{x : |x - center(t)| ≤ radius(t)}``."""

    def __init__(self, center: Any, radius: Any, name: str | None = None) -> None:
        self._c = as_param(center, "center")
        self._r = as_param(radius, "radius")
        c0 = np.atleast_1d(self._c(0.0))
        super().__init__(c0.shape[-1], name or "Ball")
        r0 = self._r(0.0)
        if c0.ndim > 2 or r0.ndim > 1:
            raise InvalidProblem(f"Ball takes a center (n,) or (B, n) and a radius () or (B,), got "
                                 f"{c0.shape} and {r0.shape}")
        if np.any(r0 < 0):
            raise InvalidProblem(f"radius must be nonnegative, got {r0}")
        self.static = _all_static(self._c, self._r)

    def center(self, t: float = 0.0) -> np.ndarray:
        return self._c(t)

    def radius(self, t: float = 0.0) -> float:
        r = self._r(t)
        return float(r) if r.ndim == 0 else r

    def _accepts_batches(self):
        return _own(self, Ball)

    def _accepts_times(self):
        return _own_times(self, Ball) and self._c(0.0).ndim <= 1 and self._r(0.0).ndim == 0

    def _radius_at(self, t):
        """``radius(t)``, checked ``≥ 0`` (a nonempty ball) at this ``t`` when it moves; a radius below 0 by
        round-off (:func:`_past_roundoff`) is 0, the ball its centre."""
        r = self._r(t)
        if not self._r.constant and not np.all(r >= 0):
            if _past_roundoff(-r, float(np.max(np.abs(self._c(t)), initial=0.0))):
                raise bad_param(self.name, "radius(t)", r, t, "must be >= 0 (the ball is empty)")
            r = np.maximum(r, 0.0)
        return r

    def project(self, x, t=0.0):
        x = finite_point(x, f"the point projected onto {self.name}")
        ts = times_of(t, x, self.name)
        if ts is not None:
            if not self._accepts_times():
                return per_row(self.project, x, ts)
            return self._project(x, ts, times=True)
        return self._project(x, t)

    def _project(self, x, t, times=False):
        """:meth:`project` of a finite float array (the solve loop checks finiteness per block instead);
        ``times``: ``t`` has a time per row of ``x`` (the same operations on each row)."""
        # points inside are returned unchanged (not as c + (x - c), which may differ in the last bit)
        c = _at_times(self._c, t) if times else self._c(t)
        d = x - c
        with np.errstate(over="ignore"):
            dd = dot_rows(d, d)
        r = None
        if d.ndim == 1 and not times:
            # one point, one ball: the norm and the test in Python floats (the same IEEE operations on the same
            # d·d, hence the same bits), the radius read once as below
            nrm = _sqrt(dd)
            if nrm < _INF:
                r = self._radius_at(t)
                if r.ndim == 0:
                    rf = float(r)
                    if not nrm > rf:
                        return x.copy()
                    return c + d * (rf / nrm)       # nrm > r ≥ 0: the divisor below is nrm
        nrm = np.sqrt(dd)[..., None]
        if np.isinf(nrm).any():          # |d| beyond 1.3e154: d·d overflows; the norm itself does not
            nrm = np.where(np.isinf(nrm), _scaled_norm(d), nrm)
        if times:
            r = _column(self._radius_times(t))
        else:
            r = batch_column(self._radius_at(t) if r is None else r, x, "radius")
        outside = nrm > r
        if not outside.any():  # the common case along a trajectory: nothing to project
            return x.copy()
        # where nrm > r (>= 0) the divisor is nrm; elsewhere it keeps r/divisor <= 1 (no inf*0 warnings)
        return np.where(outside, c + d * (r / _mx(nrm, _mx(r, _TINY))), x)

    def _radius_times(self, ts):
        """``radius`` at every time of ``ts`` (``(B,)``; a constant as it is), each checked as :meth:`_radius_at`
        checks it (a time where it is below 0 goes through :meth:`_radius_at`: its error, or its round-off 0)."""
        if self._r.constant:
            return self._r(0.0)
        r = self._r.at_times(ts)
        if not np.all(r >= 0):
            r = np.array([self._radius_at(t) for t in ts.tolist()], dtype=float)
        return r

    def _kernel(self, x0):
        if not _own(self, Ball):
            return None
        name = self.name
        if x0.ndim != 1 or self._r(0.0).ndim or self._c(0.0).ndim != 1:
            project = self._project

            def batch_step(x, lam, t):
                if not 0.0 < lam < _INF:
                    raise bad_lam(lam, name)
                return project(x, t)
            return batch_step
        if self.static:
            c, r = self._c(0.0), float(self._r(0.0))

            def step(x, lam, t):
                if not 0.0 < lam < _INF:
                    raise bad_lam(lam, name)
                d = x - c
                nrm = _sqrt(d.dot(d))
                if nrm == _INF:
                    nrm = float(_scaled_norm(d)[0])
                if nrm > r:
                    return c + d * (r / nrm)
                return x
            return step
        center = _fast(self._c)
        rfn, radius_at = self._r, self._radius_at

        def step(x, lam, t):
            if not 0.0 < lam < _INF:
                raise bad_lam(lam, name)
            c = center(t)
            d = x - c
            nrm = _sqrt(d.dot(d))
            if nrm == _INF:
                nrm = float(_scaled_norm(d)[0])
            r = float(rfn(t))
            if not r >= 0.0:         # also nan: 0 if it is round-off, else the ball is empty
                r = float(radius_at(t))
            if nrm > r:
                return c + d * (r / nrm)
            return x
        return step


class Box(ConvexSet):
    """Axis-aligned box ``{x : lower(t) ≤ x ≤ upper(t)}`` (bounds may be ±inf)."""

    def __init__(self, lower: Any, upper: Any, name: str | None = None) -> None:
        self._lo = as_param(lower, "lower") if callable(lower) else _bound(lower, "lower")
        self._hi = as_param(upper, "upper") if callable(upper) else _bound(upper, "upper")
        lo, hi = np.atleast_1d(self._lo(0.0)), np.atleast_1d(self._hi(0.0))
        lo, hi = np.broadcast_arrays(lo, hi)
        if lo.ndim > 2:
            raise InvalidProblem(f"Box bounds must have shape (n,) or (B, n), got {lo.shape}")
        super().__init__(lo.shape[-1], name or "Box")
        if np.any(lo > hi):
            raise InvalidProblem(f"Box is empty: lower {lo} exceeds upper {hi}")
        self.static = _all_static(self._lo, self._hi)

    def lower(self, t: float = 0.0) -> np.ndarray:
        return self._lo(t)

    def upper(self, t: float = 0.0) -> np.ndarray:
        return self._hi(t)

    def _accepts_batches(self):
        return _own(self, Box)

    def _accepts_times(self):
        return _own_times(self, Box) and np.ndim(self._lo(0.0)) <= 1 and np.ndim(self._hi(0.0)) <= 1

    def _bounds_at(self, t):
        """``(lower(t), upper(t))``, checked ``lower ≤ upper`` (a nonempty box) at this ``t`` when they move;
        bounds crossed by round-off (:func:`_past_roundoff`) are the point between them."""
        lo, hi = self._lo(t), self._hi(t)
        if not self.static and not (lo <= hi).all():
            lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
            gap = lo - hi
            finite = np.concatenate([np.ravel(lo[np.isfinite(lo)]), np.ravel(hi[np.isfinite(hi)])])
            if _past_roundoff(gap, float(np.abs(finite).max(initial=0.0))):
                raise bad_param(self.name, "lower(t) - upper(t)", gap, t, "must be <= 0 (the box is empty)")
            point = 0.5 * (lo + hi)
            lo, hi = np.where(gap > 0, point, lo), np.where(gap > 0, point, hi)
        return lo, hi

    def project(self, x, t=0.0):
        x = finite_point(x, f"the point projected onto {self.name}")
        ts = times_of(t, x, self.name)
        if ts is not None:
            if not self._accepts_times():
                return per_row(self.project, x, ts)
            lo, hi = self._bounds_times(ts)
            return _mn(_mx(x, lo), hi)
        lo, hi = self._bounds_at(t)
        return _mn(_mx(x, lo), hi)

    def _bounds_times(self, ts):
        """``(lower, upper)`` at every time of ``ts`` (rows ``(B, n)``; constants as they are), checked as
        :meth:`_bounds_at` checks them (a time where they cross goes through it: its error or its midpoint)."""
        lo, hi = _at_times(self._lo, ts), _at_times(self._hi, ts)
        if not self.static and not np.all(lo <= hi):
            pairs = [self._bounds_at(t) for t in ts.tolist()]
            lo = np.array([np.broadcast_to(a, (self.dim,)) for a, _ in pairs], dtype=float)
            hi = np.array([np.broadcast_to(b, (self.dim,)) for _, b in pairs], dtype=float)
        return lo, hi

    def _kernel(self, x0):
        if not _own(self, Box):
            return None
        lo, hi = _fast(self._lo), _fast(self._hi)
        name = self.name
        if self._lo.constant and self._hi.constant:
            lo0, hi0 = lo(0.0), hi(0.0)

            def step(x, lam, t):
                if not 0.0 < lam < _INF:
                    raise bad_lam(lam, name)
                return _mn(_mx(x, lo0), hi0)
        else:
            bounds = self._bounds_at

            def step(x, lam, t):
                if not 0.0 < lam < _INF:
                    raise bad_lam(lam, name)
                lo_t, hi_t = bounds(t)
                return _mn(_mx(x, lo_t), hi_t)
        return step


def _bound(value, name):
    """Bounds may be infinite (unlike other parameters)."""
    arr = np.array(real_array(value, name), dtype=float)
    if np.any(np.isnan(arr)):
        raise InvalidProblem(f"{name} must not be NaN")
    arr.setflags(write=False)

    class _Const:
        constant = True

        def __call__(self, t, _a=arr):
            return _a
    return _Const()


class HalfSpace(ConvexSet):
    """``{x : ⟨normal(t), x⟩ ≤ offset(t)}`` with a nonzero normal."""

    def __init__(self, normal: Any, offset: Any, name: str | None = None) -> None:
        self._a = as_param(normal, "normal")
        self._b = as_param(offset, "offset")
        a0 = np.atleast_1d(self._a(0.0))
        if not np.any(a0):
            raise InvalidProblem("HalfSpace normal must be nonzero")
        super().__init__(a0.shape[0], name or "HalfSpace")
        self.static = _all_static(self._a, self._b)

    def normal(self, t: float = 0.0) -> np.ndarray:
        return self._a(t)

    def offset(self, t: float = 0.0) -> float:
        return float(self._b(t))

    def _accepts_batches(self):
        return _own(self, HalfSpace)

    def _accepts_times(self):
        return _own_times(self, HalfSpace) and np.ndim(self._a(0.0)) == 1 and np.ndim(self._b(0.0)) == 0

    def _normal_at(self, t):
        a = self._a(t)
        if not self._a.constant and not (np.isfinite(a).all() and a.dot(a) > 0.0):
            raise bad_param(self.name, "normal(t)", a, t, "must be finite and nonzero")
        return a

    def project(self, x, t=0.0):
        # inner products row by row (dot_rows, not x @ a): the same summation for a point and a batch row
        x = finite_point(x, f"the point projected onto {self.name}")
        ts = times_of(t, x, self.name)
        if ts is not None:
            if not self._accepts_times():
                return per_row(self.project, x, ts)
            a, b = _at_times(self._a, ts), _column(_at_times(self._b, ts))
            if a.ndim == 1:
                aa = a.dot(a)
            else:      # moving: each row's a(t) checked as _normal_at checks it, aa the BLAS dot of each row
                aa = dot_rows(a, a)
                if not (np.isfinite(a).all() and np.all(aa > 0.0)):
                    for ti in ts.tolist():
                        self._normal_at(ti)
                aa = aa[:, None]
            excess = _mx(dot_rows(x, a)[..., None] - b, 0.0) / aa
            return x - excess * a
        a, b = self._normal_at(t), self._b(t)
        s, aa = dot_rows(x, a), a.dot(a)
        if x.ndim == 1 and a.ndim == 1 and b.ndim == 0:
            # one point, one half-space: the excess in Python floats (the same IEEE operations, hence the same
            # bits) where none of them overflows, divides by 0 or meets a NaN (NumPy's arithmetic below then:
            # its warnings)
            e = float(s) - float(b)
            if -_INF < e < _INF and 0.0 < aa < _INF:
                e = max(e, 0.0) / float(aa)
                if e < _INF:
                    return x - e * a
        excess = _mx(s[..., None] - b, 0.0) / aa
        return x - excess * a

    def _kernel(self, x0):
        if not _own(self, HalfSpace) or x0.ndim != 1 or self._b(0.0).ndim:
            return None
        normal = _fast(self._a)
        name = self.name
        if self._a.constant:
            aa0 = float(self._a(0.0).dot(self._a(0.0)))
            norm2 = lambda a, t: aa0  # noqa: E731
        else:
            def norm2(a, t):
                aa = float(a.dot(a))
                if not 0.0 < aa < _INF:
                    raise bad_param(name, "normal(t)", a, t, "must be finite and nonzero")
                return aa
        if self._b.constant:
            b0 = float(self._b(0.0))
            offset = lambda t: b0  # noqa: E731
        else:
            bfn = self._b
            offset = lambda t: float(bfn(t))  # noqa: E731

        def step(x, lam, t):
            if not 0.0 < lam < _INF:
                raise bad_lam(lam, name)
            a = normal(t)
            return x - (max(float(x.dot(a)) - offset(t), 0.0) / norm2(a, t)) * a
        return step


class Polyhedron(ConvexSet):
    """``{x : G(t)x ≤ h(t), A(t)x = b(t)}``, projected by a KKT-verified QP (:mod:`verimono.core.qp`).

    Emptiness is detected when a projection is attempted (:class:`verimono.InfeasibleStep`).
    """

    def __init__(self, G: Any, h: Any, A: Any = None, b: Any = None, name: str | None = None) -> None:
        self._G, self._h = as_param(G, "G"), as_param(h, "h")
        self._A = None if A is None else as_param(A, "A")
        self._B = None if b is None else as_param(b, "b")
        G0 = np.atleast_2d(self._G(0.0))
        super().__init__(G0.shape[1], name or "Polyhedron")
        if np.atleast_1d(self._h(0.0)).shape != (G0.shape[0],):
            raise InvalidProblem(f"h must have shape ({G0.shape[0]},)")
        if (self._A is None) != (self._B is None):
            raise InvalidProblem("A and b go together")
        params = [self._G, self._h] + ([self._A, self._B] if self._A is not None else [])
        self.static = _all_static(*params)

    def data(self, t: float = 0.0):
        G, h = np.atleast_2d(self._G(t)), np.atleast_1d(self._h(t))
        if self._A is None:
            return G, h, None, None
        return G, h, np.atleast_2d(self._A(t)), np.atleast_1d(self._B(t))

    def contains(self, x, t=0.0, tol=None):
        x = np.asarray(x, dtype=float)
        ts = times_of(t, x, self.name)
        if ts is not None:      # one row at a time (its data at its time): the same as separate calls
            return np.array([self.contains(xi, ti, tol) for xi, ti in zip(x, ts.tolist())], dtype=bool)
        G, h, A, b = self.data(t)
        tol = tolerance(x, h) if tol is None else tol
        ok = np.all(x @ G.T <= h + tol)
        if A is not None:
            ok = ok and np.all(np.abs(x @ A.T - b) <= tol)
        return bool(ok)

    @staticmethod
    def _inside(x, G, h, A, b):
        """Rows of ``x`` (shape (..., n)) lying in the set, by the same arithmetic for a point and a batch."""
        ok = np.all(dot_rows(x[..., None, :], G) <= h, axis=-1)
        if A is not None:
            ok &= np.all(dot_rows(x[..., None, :], A) == b, axis=-1)
        return ok

    def _accepts_batches(self):
        return _own(self, Polyhedron)

    def _accepts_times(self):
        return _own_times(self, Polyhedron)

    def project(self, x, t=0.0):
        """Points inside are returned as they are; the others by a KKT-verified QP each.

        A batch ``(B, n)`` tests membership for all rows at once and solves QPs only for the rows
        outside, each exactly as for the point alone (identical results).
        """
        x = finite_point(x, f"the point projected onto {self.name}")
        ts = times_of(t, x, self.name)
        if ts is not None:      # one row at a time (its data at its time): the same as separate calls
            return per_row(self.project, x, ts)
        G, h, A, b = self.data(t)
        inside = self._inside(x, G, h, A, b)
        if x.ndim == 1:
            if inside:
                return x.copy()
            return solve_qp(np.eye(self.dim), -x, G, h, A, b)
        out = np.array(x, dtype=float)
        flat, ins = out.reshape(-1, self.dim), inside.reshape(-1)
        if not ins.all():
            P = np.eye(self.dim)
            for i in np.flatnonzero(~ins).tolist():
                flat[i] = solve_qp(P, -flat[i], G, h, A, b)
        return out


class Translated(ConvexSet):
    """``S + c(t)``: a set translated by a moving vector (``c`` constant or callable)."""

    def __init__(self, S: ConvexSet, shift: Any, name: str | None = None) -> None:
        super().__init__(S.dim, name or f"Translated({S.name})")
        self.S = S
        self._c = as_param(shift, "shift")
        self.static = S.static and self._c.constant

    def shift(self, t: float = 0.0) -> np.ndarray:
        return self._c(t)

    def _accepts_batches(self):
        return _own(self, Translated) and self.S._accepts_batches()

    def _accepts_times(self):
        return (_own_times(self, Translated) and bool(getattr(self.S, "_accepts_times", lambda: False)())
                and np.ndim(self._c(0.0)) <= 1)

    def project(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        ts = times_of(t, x, self.name)
        if ts is not None:
            if not self._accepts_times():
                return per_row(self.project, x, ts)
            c = _at_times(self._c, ts)
            return self.S.project(x - c, ts) + c
        c = self._c(t)
        return self.S.project(x - c, t) + c

    def _kernel(self, x0):
        if not _own(self, Translated):
            return None
        kern = getattr(self.S, "_kernel", None)
        inner = kern(x0) if kern is not None else None
        if inner is None:
            project, name = self.S.project, self.name

            def inner(x, lam, t):
                if not 0.0 < lam < _INF:
                    raise bad_lam(lam, name)
                return project(x, t)
        shift = _fast(self._c)

        def step(x, lam, t):
            c = shift(t)
            return inner(x - c, lam, t) + c
        return step


__all__ = ["ConvexSet", "Ball", "Box", "HalfSpace", "Polyhedron", "Translated"]
