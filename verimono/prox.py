"""Proximal operators as operators: ``F = ∂g`` known through ``prox_{λg}`` and, optionally, ``g`` itself.

``prox_{λg}(x) = argmin_z λ g(z) + |z - x|²/2`` is the resolvent ``J_λ`` of ``F = ∂g`` for a proper,
closed, convex ``g``, so every resolvent law applies.  A resolvent law cannot tell *which* ``g``: the exact
prox of a wrong function (a wrong weight, a formula valid for another norm) passes all of them.  Given
``value = g``, the value laws of :mod:`verimono.checks.prox_laws` can, and ``g`` also gives a membership
test (:meth:`ProxOperator.contains`), so ``yosida_in_graph`` runs instead of being skipped.

Arrays of any shape: with ``shape=(m, n)`` the operator acts on ``R^{m×n}`` with the Frobenius inner
product ``⟨X, Y⟩ = Σ X_ij Y_ij``.  It is presented to the laws as an operator on ``R^{mn}`` through a
flattening adapter (row-major ``reshape``, an isometry of the Frobenius norm onto the Euclidean norm), so
every law and tolerance is the one of ``R^{mn}``; the user's ``prox`` and ``value`` always receive arrays
of ``shape``.  A ``prox`` returning a tuple (``(p, info)``) is rejected with :class:`ProxOutputError`
unless ``unwrap=`` says which element is the point — never unwrapped silently.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from ._subgradients import (CONTAINS_POINTS, ProxOutputError, checked_value, contains_points,  # noqa: F401 - re-exported
                      subgradient_contains)
from .errors import InvalidProblem
from .operators import Operator

def _arity(fn: Callable, with_t: int) -> bool:
    """Whether ``fn`` takes the time argument as its ``with_t``-th positional argument: that many positional
    parameters, the last without a default or named ``t``/``time`` (a parameter with another default, such
    as ``lambda x, lam, f=f: ...``, is not the time; nor is ``*args``, as in decorated library methods)."""
    import inspect

    try:
        params = list(inspect.signature(fn).parameters.values())
    except (TypeError, ValueError):
        return False
    pos = [p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    if len(pos) < with_t:
        return False
    third = pos[with_t - 1]
    return third.default is inspect.Parameter.empty or third.name in ("t", "time")


class ProxOperator(Operator):
    """``F(t, ·) = ∂g(t, ·)`` given by ``prox(X, lam[, t])`` (and ``value(X[, t]) = g(t, X)``) on arrays of
    ``shape``; presented to the laws as an operator on ``R^{prod(shape)}`` (row-major flattening)."""

    def __init__(self, prox: Callable, *, value: Callable | None = None, shape: Any = None,
                 dim: int | None = None, name: str | None = None, unwrap: int | Callable | None = None) -> None:
        if not callable(prox):
            raise InvalidProblem("prox must be callable as prox(x, lam) or prox(x, lam, t)")
        if value is not None and not callable(value):
            raise InvalidProblem("value must be callable as value(x) or value(x, t)")
        if shape is None and dim is None:
            raise InvalidProblem("give the shape of the points (shape=(n,) or shape=(m, n)) or dim")
        if shape is None:
            shape = (int(dim),)
        shape = (int(shape),) if np.ndim(shape) == 0 else tuple(int(s) for s in shape)
        if not shape or any(s < 1 for s in shape):
            raise InvalidProblem(f"shape must be a tuple of positive integers, got {shape!r}")
        if dim is not None and int(dim) != math.prod(shape):
            raise InvalidProblem(f"dim={dim} does not match shape={shape}")
        super().__init__(math.prod(shape), name or getattr(prox, "__name__", "prox"))
        self.shape = shape
        self._prox, self._value, self._unwrap = prox, value, unwrap
        self._prox_t = _arity(prox, 3)
        self._value_t = value is not None and _arity(value, 2)

    # -- the adapter ------------------------------------------------------------------------------
    def _shaped(self, x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        if x.shape != (self.dim,):
            raise InvalidProblem(f"{self.name} acts on R^{self.dim} (arrays of shape {self.shape}, flattened); "
                                 f"got a point of shape {x.shape}")
        return x.reshape(self.shape).copy()

    def _point(self, out: Any) -> np.ndarray:
        if self._unwrap is not None:
            out = self._unwrap(out) if callable(self._unwrap) else out[self._unwrap]
        elif isinstance(out, tuple) and not all(np.ndim(o) == 0 for o in out):
            raise ProxOutputError(f"{self.name}: prox returned a tuple of {len(out)} items, not an array of shape "
                                  f"{self.shape}; pass unwrap=0 (or the index or function that picks the point) "
                                  "to operator_from_prox")
        try:
            p = np.asarray(out, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ProxOutputError(f"{self.name}: prox returned {type(out).__name__}, not an array of shape "
                                  f"{self.shape} ({exc})") from None
        if p.shape != self.shape:
            raise ProxOutputError(f"{self.name}: prox returned shape {p.shape} for a point of shape {self.shape}")
        return p.reshape(self.dim)

    # -- the contract ------------------------------------------------------------------------------
    def resolvent(self, x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        if x.ndim == 2:   # a batch of flattened points, one call per row
            return np.array([self.resolvent(r, lam, t) for r in x]).reshape(x.shape)
        X = self._shaped(x)
        out = self._prox(X, lam, t) if self._prox_t else self._prox(X, lam)
        return self._point(out)

    def value(self, x, t=0.0) -> float:
        """``g(t, x)`` (``+inf`` outside ``dom g``) of a flattened point."""
        if self._value is None:
            return super().value(x, t)
        X = self._shaped(x)
        return checked_value(self, self._value(X, t) if self._value_t else self._value(X))

    def contains(self, x, y, t=0.0, tol=None):
        """Evidence for ``y ∈ ∂g(t, x)`` from ``value`` (:func:`subgradient_contains`)."""
        if self._value is None:
            return super().contains(x, y, t, tol)
        return subgradient_contains(self, x, y, t, tol)

    def provides(self, member):
        if member in ("value", "contains"):
            return self._value is not None
        return Operator.provides(self, member)

    def __repr__(self) -> str:
        return f"{self.name}(shape={self.shape})"


def operator_from_prox(prox: Callable, *, value: Callable | None = None, shape: Any = None,
                       name: str | None = None, unwrap: int | Callable | None = None) -> ProxOperator:
    """``F = ∂g`` from ``prox(x, lam) = argmin_z lam·g(z) + |z - x|²/2`` (or ``prox(x, lam, t)`` for a
    time-dependent ``g``), on arrays of ``shape`` (an int ``n`` or a tuple; the Frobenius inner product).

    ``value(x)`` or ``value(x, t)`` is ``g`` (``+inf`` outside its domain): it enables the value laws
    (prox inequality, optimality, Moreau envelope) and the membership test of ``yosida_in_graph``.
    ``unwrap`` picks the point from a prox returning a tuple (an index or a function); without it a tuple
    is a :class:`ProxOutputError`.  The arity of ``prox``/``value`` decides whether ``t`` is passed."""
    if shape is None:
        raise InvalidProblem("operator_from_prox needs shape= (an int n for R^n, or a tuple such as (m, n))")
    return ProxOperator(prox, value=value, shape=shape, name=name, unwrap=unwrap)


__all__ = ["ProxOperator", "ProxOutputError", "operator_from_prox", "subgradient_contains", "contains_points", "CONTAINS_POINTS"]
