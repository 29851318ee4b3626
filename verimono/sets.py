"""Closed convex sets ``S(t)`` that may move with time, with exact projections.

Each set has ``.dim``, ``.project(x, t=0.0)`` (the Euclidean projection, for ``x`` of shape ``(n,)`` or
``(B, n)``) and ``.contains(x, t=0.0, tol=None)``.  Every parameter is a constant or a callable of ``t``;
a set with callable parameters is a moving set, the normal cone of which gives the sweeping process.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._params import as_param
from .errors import InvalidProblem
from .tolerances import tolerance


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
        """Whether ``x ∈ S(t)`` up to ``tol`` (default scaled to ``|x|``)."""
        x = np.asarray(x, dtype=float)
        tol = tolerance(x) if tol is None else tol
        return bool(np.max(np.abs(self.project(x, t) - x), initial=0.0) <= tol)

    def __repr__(self) -> str:
        return f"{self.name}(dim={self.dim})"


def _all_static(*params) -> bool:
    return all(p.constant for p in params)


class Ball(ConvexSet):
    """Closed Euclidean ball ``{x : |x - center(t)| ≤ radius(t)}``."""

    def __init__(self, center: Any, radius: Any, name: str | None = None) -> None:
        self._c = as_param(center, "center")
        self._r = as_param(radius, "radius")
        c0 = np.atleast_1d(self._c(0.0))
        super().__init__(c0.shape[0], name or "Ball")
        if np.any(self._r(0.0) < 0):
            raise InvalidProblem(f"radius must be nonnegative, got {self._r(0.0)}")
        self.static = _all_static(self._c, self._r)

    def center(self, t: float = 0.0) -> np.ndarray:
        return self._c(t)

    def radius(self, t: float = 0.0) -> float:
        return float(self._r(t))

    def project(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        c = self._c(t)
        d = x - c
        nrm = np.sqrt(np.sum(d * d, axis=-1, keepdims=True))
        r = self._r(t)
        with np.errstate(divide="ignore", invalid="ignore"):
            scale = np.where(nrm > r, r / nrm, 1.0)
        return c + scale * d


class Box(ConvexSet):
    """Axis-aligned box ``{x : lower(t) ≤ x ≤ upper(t)}`` (bounds may be ±inf)."""

    def __init__(self, lower: Any, upper: Any, name: str | None = None) -> None:
        self._lo = as_param(lower, "lower") if callable(lower) else _bound(lower, "lower")
        self._hi = as_param(upper, "upper") if callable(upper) else _bound(upper, "upper")
        lo, hi = np.atleast_1d(self._lo(0.0)), np.atleast_1d(self._hi(0.0))
        lo, hi = np.broadcast_arrays(lo, hi)
        super().__init__(lo.shape[0], name or "Box")
        if np.any(lo > hi):
            raise InvalidProblem(f"Box is empty: lower {lo} exceeds upper {hi}")
        self.static = _all_static(self._lo, self._hi)

    def lower(self, t: float = 0.0) -> np.ndarray:
        return self._lo(t)

    def upper(self, t: float = 0.0) -> np.ndarray:
        return self._hi(t)

    def project(self, x, t=0.0):
        return np.minimum(np.maximum(np.asarray(x, dtype=float), self._lo(t)), self._hi(t))


def _bound(value, name):
    """Bounds may be infinite (unlike other parameters)."""
    arr = np.array(value, dtype=float)
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

    def project(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        a, b = self._a(t), self._b(t)
        excess = np.maximum(x @ a - b, 0.0) / (a @ a)
        return x - np.multiply.outer(excess, a) if x.ndim > 1 else x - excess * a


class Polyhedron(ConvexSet):
    """``{x : G(t)x ≤ h(t), A(t)x = b(t)}``, projected by a KKT-verified QP (:mod:`verimono.qp`).

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
        G, h, A, b = self.data(t)
        tol = tolerance(x, h) if tol is None else tol
        ok = np.all(x @ G.T <= h + tol)
        if A is not None:
            ok = ok and np.all(np.abs(x @ A.T - b) <= tol)
        return bool(ok)

    def project(self, x, t=0.0):
        from .qp import solve_qp

        x = np.asarray(x, dtype=float)
        G, h, A, b = self.data(t)
        if x.ndim > 1:
            return np.stack([self.project(xi, t) for xi in x])
        if np.all(G @ x <= h) and (A is None or np.all(A @ x == b)):
            return x.copy()
        return solve_qp(np.eye(self.dim), -x, G, h, A, b)


class Translated(ConvexSet):
    """``S + c(t)``: a set translated by a moving vector (``c`` constant or callable)."""

    def __init__(self, S: ConvexSet, shift: Any, name: str | None = None) -> None:
        super().__init__(S.dim, name or f"Translated({S.name})")
        self.S = S
        self._c = as_param(shift, "shift")
        self.static = S.static and self._c.constant

    def shift(self, t: float = 0.0) -> np.ndarray:
        return self._c(t)

    def project(self, x, t=0.0):
        c = self._c(t)
        return self.S.project(np.asarray(x, dtype=float) - c, t) + c


__all__ = ["ConvexSet", "Ball", "Box", "HalfSpace", "Polyhedron", "Translated"]
