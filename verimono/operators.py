"""Maximal monotone operators ``F(t, ·)`` and their resolvents.

An :class:`Operator` is known through its resolvent ``J_λ = (I + λF(t,·))^{-1}``, which for a maximal
monotone ``F`` is single-valued, defined everywhere and firmly nonexpansive (the paper's Proposition
``prop:maxmon-resolvent-Yosida``, items i–ii), its Yosida approximation ``Y_λ = (I - J_λ)/λ``, its
minimal section ``F^0(t, x) = proj(0, F(t, x))``, the projection onto ``cl dom F(t,·)`` and a membership
test ``y ∈ F(t, x)``.  Members an operator cannot provide raise :class:`NotImplementedError`; checks that
need them are then counted as skipped, never silently passed.

Every catalog operator accepts points of shape ``(n,)`` or a batch of shape ``(B, n)`` and every
parameter may be a constant or a callable of ``t``.
"""

from __future__ import annotations

import inspect
from typing import Any, Callable

import numpy as np

from ._params import as_param
from .errors import InvalidProblem, NotMonotone, OutsideDomain
from .tolerances import tolerance


class Operator:
    """Base class of maximal monotone operators ``F(t, ·): R^n ⇉ R^n``.

    Subclasses implement :meth:`resolvent` and whichever of :meth:`min_norm`, :meth:`project_domain`
    and :meth:`contains` they can; :meth:`yosida` is provided here.
    """

    #: True when ``F(t,·)`` does not depend on ``t``.
    static: bool = False

    def __init__(self, dim: int, name: str | None = None) -> None:
        if int(dim) != dim or dim < 1:
            raise InvalidProblem(f"operator dimension must be a positive integer, got {dim!r}")
        self.dim = int(dim)
        self.name = name or type(self).__name__

    # -- the contract -------------------------------------------------------------------------
    def resolvent(self, x: np.ndarray, lam: float, t: float = 0.0) -> np.ndarray:
        """``J_λ x = (I + λ F(t,·))^{-1}(x)``."""
        raise NotImplementedError(f"{self.name} does not provide a resolvent")

    def yosida(self, x: np.ndarray, lam: float, t: float = 0.0) -> np.ndarray:
        """Yosida approximation ``Y_λ x = (x - J_λ x)/λ``, an element of ``F(t, J_λ x)``."""
        x = np.asarray(x, dtype=float)
        return (x - self.resolvent(x, lam, t)) / lam

    def min_norm(self, x: np.ndarray, t: float = 0.0) -> np.ndarray:
        """Minimal section ``F^0(t, x)``, the least-norm element of ``F(t, x)`` (``x ∈ dom F(t,·)``)."""
        raise NotImplementedError(f"{self.name} does not provide its minimal section")

    def project_domain(self, x: np.ndarray, t: float = 0.0) -> np.ndarray:
        """Projection of ``x`` onto ``cl dom F(t,·)``."""
        raise NotImplementedError(f"{self.name} does not provide a projection onto its domain")

    def contains(self, x: np.ndarray, y: np.ndarray, t: float = 0.0, tol: float | None = None) -> bool:
        """Whether ``y ∈ F(t, x)`` up to ``tol`` (default: :func:`verimono.tolerances.tolerance`)."""
        raise NotImplementedError(f"{self.name} does not provide a membership test")

    # -- conveniences --------------------------------------------------------------------------
    def in_domain(self, x: np.ndarray, t: float = 0.0, tol: float | None = None) -> bool:
        """Whether ``x ∈ cl dom F(t,·)`` up to ``tol`` (through :meth:`project_domain`)."""
        x = np.asarray(x, dtype=float)
        p = self.project_domain(x, t)
        tol = tolerance(x) if tol is None else tol
        return bool(np.max(np.abs(p - x), initial=0.0) <= tol)

    def __repr__(self) -> str:
        return f"{self.name}(dim={self.dim})"


def _norm(x: np.ndarray) -> np.ndarray:
    """Euclidean norm over the last axis, keeping it (works for (n,) and (B, n))."""
    return np.sqrt(np.sum(x * x, axis=-1, keepdims=True))


def _check_dim(op: Operator, x: np.ndarray) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    if x.shape[-1:] != (op.dim,):
        raise InvalidProblem(f"{op.name} acts on R^{op.dim}; got a point of shape {x.shape}")
    return x


class _FromResolvent(Operator):
    def __init__(self, resolvent, dim, min_norm, project_domain, contains, name):
        super().__init__(dim, name or getattr(resolvent, "__name__", "user operator"))
        self._resolvent = resolvent
        self._min_norm = min_norm
        self._project_domain = project_domain
        self._contains = contains
        self._contains_takes_tol = contains is not None and _accepts(contains, 4)

    def resolvent(self, x, lam, t=0.0):
        return np.asarray(self._resolvent(x, lam, t), dtype=float)

    def min_norm(self, x, t=0.0):
        if self._min_norm is None:
            return super().min_norm(x, t)
        return np.asarray(self._min_norm(x, t), dtype=float)

    def project_domain(self, x, t=0.0):
        if self._project_domain is None:
            return super().project_domain(x, t)
        return np.asarray(self._project_domain(x, t), dtype=float)

    def contains(self, x, y, t=0.0, tol=None):
        if self._contains is None:
            return super().contains(x, y, t, tol)
        if self._contains_takes_tol:
            return bool(self._contains(x, y, t, tol))
        return bool(self._contains(x, y, t))


def _accepts(fn: Callable, n: int) -> bool:
    try:
        params = inspect.signature(fn).parameters.values()
    except (TypeError, ValueError):
        return False
    if any(p.kind is p.VAR_POSITIONAL for p in params):
        return True
    return len([p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]) >= n


def operator_from_resolvent(resolvent: Callable[[np.ndarray, float, float], Any], dim: int, *,
                            min_norm: Callable | None = None, project_domain: Callable | None = None,
                            contains: Callable | None = None, name: str | None = None) -> Operator:
    """Wrap a user's ``resolvent(x, lam, t)`` as an :class:`Operator`.

    Optional callables: ``min_norm(x, t)``, ``project_domain(x, t)``, ``contains(x, y, t[, tol])``.
    Members not given raise :class:`NotImplementedError`, so checks needing them are skipped.
    """
    if not callable(resolvent):
        raise InvalidProblem("resolvent must be callable as resolvent(x, lam, t)")
    return _FromResolvent(resolvent, dim, min_norm, project_domain, contains, name)


class Linear(Operator):
    """``F(t, x) = M(t) x`` with ``M + Mᵀ ⪰ 0`` (``M`` need not be symmetric).

    Monotone because ``⟨M(x-y), x-y⟩ ≥ 0``; continuous and everywhere defined, hence maximal.
    ``J_λ = (I + λM)^{-1}``, well conditioned: ``xᵀ(I + λM)x ≥ |x|²`` gives singular values ≥ 1.
    For a constant ``M`` the inverse is computed once per step size and reused.
    """

    def __init__(self, M: Any, name: str | None = None) -> None:
        self._M = as_param(M, "M")
        M0 = self._M(0.0)
        if M0.ndim != 2 or M0.shape[0] != M0.shape[1]:
            raise InvalidProblem(f"M must be a square matrix, got shape {M0.shape}")
        super().__init__(M0.shape[0], name or "Linear")
        self.static = self._M.constant
        _require_monotone_matrix(M0, "M")
        self._cache_lam: float | None = None
        self._cache_inv: np.ndarray | None = None

    def M(self, t: float = 0.0) -> np.ndarray:
        return self._M(t)

    def _inverse(self, lam: float, t: float) -> np.ndarray:
        if self.static:
            if lam != self._cache_lam:
                self._cache_inv = np.linalg.inv(np.eye(self.dim) + lam * self._M(t)).T.copy()
                self._cache_lam = lam
            return self._cache_inv
        return np.linalg.inv(np.eye(self.dim) + lam * self._M(t)).T

    def resolvent(self, x, lam, t=0.0):
        return np.asarray(x, dtype=float) @ self._inverse(float(lam), t)

    def min_norm(self, x, t=0.0):
        return np.asarray(x, dtype=float) @ self._M(t).T

    def project_domain(self, x, t=0.0):
        return np.array(x, dtype=float)

    def contains(self, x, y, t=0.0, tol=None):
        Mx = self.min_norm(x, t)
        tol = tolerance(Mx, y) if tol is None else tol
        return bool(np.max(np.abs(np.asarray(y) - Mx)) <= tol)


def _require_monotone_matrix(M: np.ndarray, what: str) -> None:
    sym = 0.5 * (M + M.T)
    lmin = float(np.linalg.eigvalsh(sym)[0]) if M.size else 0.0
    if lmin < -tolerance(M):
        raise NotMonotone(f"{what} + {what}ᵀ must be positive semidefinite for a monotone operator; "
                          f"its smallest eigenvalue is {2 * lmin:.3g}")


def _nonnegative(value: np.ndarray, what: str) -> None:
    if np.any(np.asarray(value) < 0):
        raise NotMonotone(f"{what} must be nonnegative for a convex function (got {value}); "
                          "a negative weight makes the operator non-monotone")


class NormSubdifferential(Operator):
    """``F(t, ·) = ∂(c(t)‖·‖₂)``: ``F(t, x) = c x/|x|`` for ``x ≠ 0`` and the ball ``c B`` at 0.

    The paper's example ``g(t, x) = t|x|`` is ``c(t) = t``.  ``J_λ x = max(1 - λc/|x|, 0) x``
    (block soft thresholding), ``F^0(t, 0) = 0``.
    """

    static = False

    def __init__(self, c: Any, dim: int = 1, name: str | None = None) -> None:
        super().__init__(dim, name or "NormSubdifferential")
        self._c = as_param(c, "c")
        self.static = self._c.constant
        _nonnegative(self._c(0.0), "c(0)")

    def c(self, t: float = 0.0) -> float:
        return self._c(t)

    def resolvent(self, x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        nrm = _norm(x)
        with np.errstate(divide="ignore", invalid="ignore"):
            scale = np.maximum(1.0 - lam * self._c(t) / nrm, 0.0)
        return np.where(nrm > 0.0, scale, 0.0) * x

    def min_norm(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        nrm = _norm(x)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(nrm > 0.0, self._c(t) * x / nrm, 0.0)

    def project_domain(self, x, t=0.0):
        return np.array(x, dtype=float)

    def contains(self, x, y, t=0.0, tol=None):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        c = float(self._c(t))
        tol = tolerance(c, y) if tol is None else tol
        if np.linalg.norm(x) > 0.0:
            return bool(np.linalg.norm(y - c * x / np.linalg.norm(x)) <= tol)
        return bool(np.linalg.norm(y) <= c + tol)


class L1Subdifferential(Operator):
    """``F(t, ·) = ∂(Σ_i c_i(t)|x_i|)`` (``c`` a scalar or a vector of weights).

    Componentwise: ``c_i sgn(x_i)`` for ``x_i ≠ 0`` and ``[-c_i, c_i]`` at 0;
    ``J_λ`` is soft thresholding ``sgn(x) max(|x| - λc, 0)``.
    """

    def __init__(self, c: Any, dim: int = 1, name: str | None = None) -> None:
        super().__init__(dim, name or "L1Subdifferential")
        self._c = as_param(c, "c")
        self.static = self._c.constant
        c0 = self._c(0.0)
        if c0.ndim and c0.shape != (dim,):
            raise InvalidProblem(f"c must be a scalar or have shape ({dim},), got {c0.shape}")
        _nonnegative(c0, "c(0)")

    def resolvent(self, x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        return np.sign(x) * np.maximum(np.abs(x) - lam * self._c(t), 0.0)

    def min_norm(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        return np.sign(x) * self._c(t)

    def project_domain(self, x, t=0.0):
        return np.array(x, dtype=float)

    def contains(self, x, y, t=0.0, tol=None):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        c = np.broadcast_to(self._c(t), x.shape)
        tol = tolerance(c, y) if tol is None else tol
        nz = x != 0.0
        ok_nz = np.all(np.abs(y[nz] - c[nz] * np.sign(x[nz])) <= tol)
        ok_z = np.all(np.abs(y[~nz]) <= c[~nz] + tol)
        return bool(ok_nz and ok_z)


class NormalCone(Operator):
    """``F(t, ·) = N_{S(t)}``, the normal cone of a moving closed convex set (the sweeping process).

    ``J_λ = proj_{S(t)}`` for every ``λ`` (the catching-up algorithm), ``dom F(t,·) = S(t)`` and
    ``F^0(t, x) = 0`` on ``S(t)``; ``y ∈ N_S(x)`` iff ``x ∈ S`` and ``proj_S(x + y) = x``.
    """

    def __init__(self, S: Any, name: str | None = None) -> None:
        super().__init__(S.dim, name or f"NormalCone({getattr(S, 'name', type(S).__name__)})")
        self.S = S
        self.static = getattr(S, "static", False)

    def resolvent(self, x, lam, t=0.0):
        return self.S.project(x, t)

    def min_norm(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        if not self.S.contains(x, t):
            raise OutsideDomain(f"x = {x} is not in S(t={t}); N_S(x) is empty there")
        return np.zeros_like(x)

    def project_domain(self, x, t=0.0):
        return self.S.project(x, t)

    def contains(self, x, y, t=0.0, tol=None):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        tol = tolerance(x, y) if tol is None else tol
        if not self.S.contains(x, t, tol):
            return False
        return bool(np.max(np.abs(self.S.project(x + y, t) - x)) <= tol)


class Shifted(Operator):
    """``G(t, x) = F(t, x + Φ(t))`` — the input-shift lemma of Section 6 (label ``l:extinput``).

    With ``Φ(t) = ∫_0^t u``, ``x' ∈ -F(t,x) + u`` has the solution ``x = ξ + Φ`` where
    ``ξ' ∈ -G(t, ξ)``.  ``J^G_λ(x) = J^F_λ(x + Φ) - Φ``, ``G^0(t,x) = F^0(t, x + Φ)``.
    """

    def __init__(self, F: Operator, Phi: Any, name: str | None = None) -> None:
        super().__init__(F.dim, name or f"Shifted({F.name})")
        self.F = F
        self._Phi = as_param(Phi, "Phi")
        self.static = F.static and self._Phi.constant

    def Phi(self, t: float = 0.0) -> np.ndarray:
        return self._Phi(t)

    def resolvent(self, x, lam, t=0.0):
        p = self._Phi(t)
        return self.F.resolvent(np.asarray(x, dtype=float) + p, lam, t) - p

    def min_norm(self, x, t=0.0):
        return self.F.min_norm(np.asarray(x, dtype=float) + self._Phi(t), t)

    def project_domain(self, x, t=0.0):
        p = self._Phi(t)
        return self.F.project_domain(np.asarray(x, dtype=float) + p, t) - p

    def contains(self, x, y, t=0.0, tol=None):
        return self.F.contains(np.asarray(x, dtype=float) + self._Phi(t), y, t, tol)


class LogBarrier(Operator):
    """``F(t, ·) = ∂(-c(t) Σ_i ln x_i)`` on the open orthant ``(0, ∞)^n``: ``F(x) = -c/x``.

    Its domain is open, ``cl dom F = [0, ∞)^n``, and ``|F^0|`` is unbounded near the boundary, so
    (LG) fails there: from ``x0 = 0`` the solution of ``x' = c/x`` is ``sqrt(2ct)`` and the proximal
    scheme converges with order exactly 1/2 (see ``verimono.reference``).
    ``J_λ x = (x + sqrt(x² + 4λc))/2`` componentwise, evaluated without cancellation.
    """

    def __init__(self, c: Any = 1.0, dim: int = 1, name: str | None = None) -> None:
        super().__init__(dim, name or "LogBarrier")
        self._c = as_param(c, "c")
        self.static = self._c.constant
        if np.any(self._c(0.0) <= 0):
            raise InvalidProblem("LogBarrier needs c > 0")

    def resolvent(self, x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        r = np.sqrt(x * x + 4.0 * lam * self._c(t))
        with np.errstate(divide="ignore", invalid="ignore"):
            neg = 2.0 * lam * self._c(t) / (r - x)
        return np.where(x >= 0.0, 0.5 * (x + r), neg)

    def min_norm(self, x, t=0.0):
        x = np.asarray(x, dtype=float)
        if np.any(x <= 0.0):
            raise OutsideDomain(f"LogBarrier is defined on (0, ∞)^n; got x = {x}")
        return -self._c(t) / x

    def project_domain(self, x, t=0.0):
        return np.maximum(np.asarray(x, dtype=float), 0.0)

    def contains(self, x, y, t=0.0, tol=None):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        if np.any(x <= 0.0):
            return False
        expected = -self._c(t) / x
        tol = tolerance(expected, y) if tol is None else tol
        return bool(np.max(np.abs(y - expected)) <= tol)


__all__ = [
    "Operator",
    "operator_from_resolvent",
    "Linear",
    "NormSubdifferential",
    "L1Subdifferential",
    "NormalCone",
    "Shifted",
    "LogBarrier",
]
