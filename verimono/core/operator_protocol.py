"""The operator protocol: a maximal monotone ``F(t, ·)`` known through its resolvent, and an operator from yours.

An :class:`Operator` is known through its resolvent ``J_λ = (I + λF(t,·))^{-1}``, which for a maximal
monotone ``F`` is single-valued, defined everywhere and firmly nonexpansive (the paper's Proposition
``prop:maxmon-resolvent-Yosida``, items i–ii), its Yosida approximation ``Y_λ = (I - J_λ)/λ``, its
minimal section ``F^0(t, x) = proj(0, F(t, x))``, the projection onto ``cl dom F(t,·)`` and a membership
test ``y ∈ F(t, x)``.  Members an operator cannot provide raise :class:`NotImplementedError`; checks that
need them are then counted as skipped, never silently passed.  :func:`operator_from_resolvent` wraps a
user's resolvent (and whichever members they have) as an :class:`Operator`; the closed-form catalog is
:mod:`verimono.core.operators`.
"""

from __future__ import annotations

import inspect
import math
from typing import Any, Callable

import numpy as np

from .arrays import Boundary, array_kind, as_float64, batch_chunks, given_as_is, take_prefetched
from ._subgradients import checked_value, subgradient_contains
from ._rows import per_row_steps, steps_of
from ._validate import check_lam, real_array
from .errors import InvalidProblem
from .tolerances import tolerance


class Operator:
    """Base class of maximal monotone operators ``F(t, ·): R^n ⇉ R^n``.

    Subclasses implement :meth:`resolvent` and whichever of :meth:`min_norm`, :meth:`project_domain`
    and :meth:`contains` they can; :meth:`yosida` is provided here.
    """

    #: True when ``F(t,·)`` does not depend on ``t``.
    static: bool = False
    #: True when ``dom F(t,·) = R^n`` for every ``t`` (so (A3) holds with ``φ ≡ 0``).
    full_domain: bool = False
    #: the magnitude of the data the members compute with (``|c| + r`` for the ball of radius ``r`` centred at ``c``),
    #: when it exceeds the points they are given: the laws then judge them at that scale, since correct code rounds
    #: at it (:mod:`verimono.core.tolerances`, "the operator's own scale").  ``None``: not stated (a law that fails
    #: only within the rounding of the scale inferred from the domain is undecided: verimono.checks.engine.data_scale)
    data_scale: float | None = None

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
        """Yosida approximation ``Y_λ x = (x - J_λ x)/λ``, an element of ``F(t, J_λ x)``.  ``lam`` of shape ``(B,)``
        beside ``x`` of shape ``(B, n)``: row ``i`` at ``λ_i`` (one call when :meth:`_accepts_steps`, else per row)."""
        if type(lam) is np.ndarray and lam.ndim == 1:
            x = real_array(x)
            ls = steps_of(lam, x, f"{self.name}.yosida")
            if not self._accepts_steps():
                return per_row_steps(self.yosida, x, ls, t)
            return (x - self.resolvent(x, ls, t)) / ls[:, None]
        lam = check_lam(lam, f"{self.name}.yosida")
        x = real_array(x)
        return (x - self.resolvent(x, lam, t)) / lam

    def min_norm(self, x: np.ndarray, t: float = 0.0) -> np.ndarray:
        """Minimal section ``F^0(t, x)``, the least-norm element of ``F(t, x)`` (``x ∈ dom F(t,·)``)."""
        raise NotImplementedError(f"{self.name} does not provide its minimal section")

    def project_domain(self, x: np.ndarray, t: float = 0.0) -> np.ndarray:
        """Projection of ``x`` onto ``cl dom F(t,·)``."""
        raise NotImplementedError(f"{self.name} does not provide a projection onto its domain")

    def contains(self, x: np.ndarray, y: np.ndarray, t: float = 0.0, tol: float | None = None) -> bool:
        """Whether ``y ∈ F(t, x)`` up to ``tol`` (default: :func:`verimono.core.tolerances.tolerance`): some
        ``(x', y') ∈ graph F(t,·)`` lies within ``tol`` of ``(x, y)`` in each coordinate."""
        raise NotImplementedError(f"{self.name} does not provide a membership test")

    def value(self, x: np.ndarray, t: float = 0.0) -> float:
        """``g(t, x)`` when ``F(t,·) = ∂g(t,·)`` is a subdifferential and ``g`` is known (``+inf`` outside
        ``dom g``); enables the value laws of :mod:`verimono.checks.prox_laws`."""
        raise NotImplementedError(f"{self.name} does not provide the function value g")

    def growth(self, t: float = 0.0) -> float:
        """``σ(t)`` of (LG) known from the operator itself: ``|F^0(t, x)| ≤ σ(t)(1 + |x|)`` on ``dom F(t,·)``."""
        raise NotImplementedError(f"{self.name} does not state the growth σ of (LG)")

    def provides(self, member: str) -> bool:
        """Whether this operator provides ``member`` (``"min_norm"``, ``"project_domain"``, ``"contains"``, ``"value"``):
        the laws that need a member it lacks are skipped before they run, with that reason."""
        own = getattr(type(self), member, None)
        return own is not None and own is not getattr(Operator, member, None)

    # -- conveniences --------------------------------------------------------------------------
    def in_domain(self, x: np.ndarray, t: float = 0.0, tol: float | None = None) -> bool:
        """Whether ``x ∈ cl dom F(t,·)`` up to ``tol`` (through :meth:`project_domain`)."""
        x = np.asarray(x, dtype=float)
        p = self.project_domain(x, t)
        tol = tolerance(x) if tol is None else tol
        return bool(np.max(np.abs(p - x), initial=0.0) <= tol)

    # -- performance hook (private) ----------------------------------------------------------------
    def _accepts_batches(self) -> bool:
        """Whether :meth:`resolvent` maps a batch ``(B, n)`` row by row, bit-identically to ``B`` separate
        calls (the catalog's own resolvents do; a user's, or a subclass override, is not assumed to)."""
        return False

    def _accepts_times(self) -> bool:
        """Whether :meth:`resolvent`, :meth:`yosida`, :meth:`min_norm` and :meth:`project_domain` take ``t`` of
        shape ``(B,)`` beside ``x`` of shape ``(B, n)`` — row ``i`` at time ``t[i]`` — bit-identically to ``B``
        separate calls (the catalog's own members do; a user's operator, or a subclass override, is not assumed
        to: the assumption laws then call it once per time).  ``min_norm`` raises :class:`OutsideDomain` when
        any row is outside the domain at its time."""
        return False

    def _accepts_steps(self) -> bool:
        """Whether :meth:`resolvent` and :meth:`yosida` take ``lam`` of shape ``(B,)`` beside ``x`` of shape ``(B, n)``
        — row ``i`` at step size ``λ_i`` (and, with ``t`` of shape ``(B,)`` too, at time ``t_i`` when
        :meth:`_accepts_times` says so) — bit-identically to ``B`` separate calls with a float ``λ`` (the catalog's
        own members do; a user's operator, or a subclass override, or a member replaced on the object is not
        assumed to: the operator laws then call it once per step size)."""
        return False

    def _kernel(self, x0: np.ndarray) -> Callable | None:
        """A fast ``step(x, lam, t) = J_λ x`` for float arrays shaped like ``x0``, or ``None``.

        Used by :func:`verimono.solve` in its per-step loop; must return exactly what :meth:`resolvent`
        returns.  ``None`` (the default) means "use :meth:`resolvent`".
        """
        return None

    def __repr__(self) -> str:
        return f"{self.name}(dim={self.dim})"


def resolvent_kernel(op: "Operator", x0: np.ndarray) -> Callable:
    """The fastest ``step(x, lam, t) = J_λ x`` of ``op`` for points shaped like ``x0``.

    The operator's private kernel when it has one and its :meth:`~Operator.resolvent` is not
    overridden by a subclass or on the object itself (a resolvent wrapped by a test or a user's
    instrumentation is the one called), else the bound :meth:`~Operator.resolvent`.
    """
    if "resolvent" in getattr(op, "__dict__", {}):
        return op.resolvent
    kern = getattr(op, "_kernel", None)
    step = kern(np.asarray(x0, dtype=float)) if kern is not None else None
    return op.resolvent if step is None else step


def resolvent_rows(op: "Operator", X: np.ndarray, lam: float, t: float = 0.0) -> np.ndarray:
    """``J_λ`` of every row of ``X`` ``(B, n)``: one vectorized call when the operator's resolvent maps
    batches row by row (the catalog's), else one call per row — the same values either way.  ``t`` of shape
    ``(B,)``: row ``i`` at ``t[i]``, in one call when the operator declares it takes a time per row
    (:meth:`Operator._accepts_times`), else one call per row."""
    X = np.asarray(X, dtype=float)
    if type(t) is np.ndarray and t.ndim == 1:
        if accepts_times(op):
            return np.asarray(op.resolvent(X, lam, t), dtype=float)
        return np.array([np.asarray(op.resolvent(x, lam, tt), dtype=float)
                         for x, tt in zip(X, t.tolist())]).reshape(X.shape)
    if op._accepts_batches():
        return np.asarray(op.resolvent(X, lam, t), dtype=float)
    return np.array([np.asarray(op.resolvent(x, lam, t), dtype=float) for x in X]).reshape(X.shape)


def accepts_times(op: Any) -> bool:
    """Whether ``op`` declares that its members take a time per row (:meth:`Operator._accepts_times`); an
    object that does not say does not (never found out by calling it and catching what it raises)."""
    says = getattr(op, "_accepts_times", None)
    return bool(says()) if callable(says) else False


def accepts_steps(op: Any) -> bool:
    """Whether ``op`` declares that its ``resolvent`` and ``yosida`` take a step size per row
    (:meth:`Operator._accepts_steps`); an object that does not say does not (never found out by calling it)."""
    says = getattr(op, "_accepts_steps", None)
    return bool(says()) if callable(says) else False


def provides(op: Any, member: str) -> bool:
    """``op.provides(member)`` for operators that say, else whether ``op`` has the member at all."""
    says = getattr(op, "provides", None)
    return bool(says(member)) if callable(says) else callable(getattr(op, member, None))


class _FromResolvent(Operator):
    def __init__(self, resolvent, dim, min_norm, project_domain, contains, name, value=None, io=None,
                 batched=False):
        super().__init__(dim, name or getattr(resolvent, "__name__", "user operator"))
        self._resolvent = resolvent
        self._value = value
        self._value_t = value is not None and _accepts(value, 2)
        self._min_norm = min_norm
        self._project_domain = project_domain
        self._contains = contains
        self._contains_takes_tol = contains is not None and _accepts(contains, 4)
        self._io = io if io is not None else Boundary(None)
        #: the resolvent maps a batch: points (B, n), steps (B,), times (B,)
        self.batched = bool(batched)
        #: resolvent values of a batch evaluated ahead of the laws (verimono.checks.engine.batches)
        self._prefetched: dict | None = None

    @property
    def array(self) -> str:
        """The array library the resolvent computes with (declared or detected)."""
        return self._io.name

    def _out(self, value, what):
        """A member's output as float64 (its precision observed, :mod:`verimono.core.arrays`)."""
        if type(value) is np.ndarray and value.dtype == np.float64 and not self._io.detect:
            return value
        try:
            return self._io.returned(value)
        except (TypeError, ValueError):
            return real_array(value, what)      # the typed error for complex or non-numeric values

    def _in(self, x):
        """A point as the user's members are given it (from any array library, in their array type; inside
        :func:`verimono.core.arrays.as_given`, a NumPy subject's NumPy input as it is)."""
        if not (type(x) is np.ndarray and x.dtype == np.float64) and not given_as_is(x, self._io.name):
            try:
                x = as_float64(x)
            except (TypeError, ValueError):
                x = real_array(x)
        return self._io.given(x)

    def resolvent(self, x, lam, t=0.0):
        lam = check_lam(lam, f"{self.name}.resolvent")
        if self.batched:
            hit = take_prefetched(self._prefetched, x, lam, t)
            if hit is not None:
                return hit
            x = as_float64(x)
            if x.ndim == 1:
                return self.resolvent_batch(x[None], np.array([lam]), np.array([float(t)]))[0]
            return self.resolvent_batch(x, np.full(x.shape[0], lam), np.full(x.shape[0], float(t)))
        return self._out(self._resolvent(self._in(x), lam, t), f"the resolvent of {self.name}")

    def resolvent_batch(self, X, lams, ts, pad=True):
        """``J_{λ_i}(X_i)`` at ``t_i`` for the rows of ``X`` ``(B, n)``: batched calls of a ``batched``
        resolvent (chunks padded to powers of two; ``pad=False``: as they are), else one call per row."""
        X = as_float64(X)
        lams, ts = np.asarray(lams, dtype=float), np.asarray(ts, dtype=float)
        if not self.batched:
            return np.array([self.resolvent(r, lam, t) for r, lam, t in zip(X, lams, ts)]).reshape(X.shape)
        out = np.empty_like(X)
        for lo, rows, pick in batch_chunks(X.shape[0], pad):
            P = self._out(self._resolvent(self._io.given(X[pick]), self._io.given(lams[pick]), self._io.given(ts[pick])),
                          f"the batched resolvent of {self.name}")
            if P.shape != (pick.size, self.dim):
                raise InvalidProblem(f"the batched resolvent of {self.name} returned shape {P.shape} for a batch of "
                                     f"shape {(pick.size, self.dim)}")
            out[lo:lo + rows] = P[:rows]
        return out

    def provides(self, member):
        if member == "contains" and self._value is not None:
            return True   # the value-based membership evidence (verimono.core.prox.subgradient_contains)
        return getattr(self, f"_{member}", None) is not None

    def value(self, x, t=0.0):
        if self._value is None:
            return super().value(x, t)
        x = self._in(x)
        return checked_value(self, self._io.scalar(self._value(x, t) if self._value_t else self._value(x)))

    def min_norm(self, x, t=0.0):
        if self._min_norm is None:
            return super().min_norm(x, t)
        return self._out(self._min_norm(self._in(x), t), f"min_norm of {self.name}")

    def project_domain(self, x, t=0.0):
        if self._project_domain is None:
            return super().project_domain(x, t)
        return self._out(self._project_domain(self._in(x), t), f"project_domain of {self.name}")

    def contains(self, x, y, t=0.0, tol=None):
        if self._contains is None and self._value is not None:
            return subgradient_contains(self, x, y, t, tol)
        if self._contains is None:
            return super().contains(x, y, t, tol)
        x, y = self._in(x), self._in(y)
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
                            contains: Callable | None = None, name: str | None = None,
                            value: Callable | None = None, array: Any = None, dtype: Any = None,
                            device: Any = None, batched: bool = False, data_scale: float | None = None) -> Operator:
    """Wrap a user's ``resolvent(x, lam, t)`` as an :class:`Operator`.

    Optional callables: ``min_norm(x, t)``, ``project_domain(x, t)``, ``contains(x, y, t[, tol])``,
    ``value(x[, t])`` — the function ``g`` when ``F = ∂g`` (enables the value laws, and, without
    ``contains``, the membership evidence of :func:`verimono.core.prox.subgradient_contains`).
    Members not given raise :class:`NotImplementedError`, so checks needing them are skipped.

    ``array``/``dtype``/``device``: the array library the members compute with and the precision of their
    inputs (:func:`verimono.operator_from_prox` says how; ``None``: detected from the first resolvent value).
    Their outputs are converted to NumPy float64 with their precision recorded, so a float32 resolvent is
    judged at float32 precision.  ``batched=True``: ``resolvent(X, lams, ts)`` maps points ``(B, n)`` with
    steps and times ``(B,)`` at once, and the search evaluates its draws and sweep a batch at a time.
    ``data_scale``: the magnitude of the data the members compute with, when larger than the points they are given
    (:attr:`Operator.data_scale`: the projection onto a ball centred at ``c`` of radius ``r`` rounds at ``|c| + r``).
    """
    if not callable(resolvent):
        raise InvalidProblem("resolvent must be callable as resolvent(x, lam, t)")
    if value is not None and not callable(value):
        raise InvalidProblem("value must be callable as value(x) or value(x, t)")
    io = Boundary(array_kind(array, dtype=dtype, device=device))
    return with_data_scale(_FromResolvent(resolvent, dim, min_norm, project_domain, contains, name, value, io, batched),
                           data_scale)


def _finite_scale(value: Any) -> float | None:
    """``value`` as a data scale: a finite float ``≥ 0`` (not a bool), else ``None``."""
    if value is None or isinstance(value, bool):
        return None
    try:
        s = float(value)
    except (TypeError, ValueError, OverflowError):     # 10**400: no float
        return None
    return s if math.isfinite(s) and s >= 0.0 else None


def stated_data_scale(op: Any) -> float | None:
    """The operator's stated :attr:`Operator.data_scale` (``None``: not stated, or not a finite number ≥ 0)."""
    return _finite_scale(getattr(op, "data_scale", None))


def with_data_scale(op: Operator, data_scale: float | None) -> Operator:
    """``op`` with its stated :attr:`Operator.data_scale` (``None``: left unstated); a scale that is not a finite
    number ``≥ 0`` is an :class:`InvalidProblem`."""
    if data_scale is not None:
        s = _finite_scale(data_scale)
        if s is None:
            raise InvalidProblem(f"data_scale must be a finite number ≥ 0 (the magnitude of the operator's data), "
                                 f"got {data_scale!r}")
        op.data_scale = s
    return op
