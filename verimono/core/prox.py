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

Array libraries and precision (:mod:`verimono.core.arrays`): a prox that computes with JAX, PyTorch, CuPy or an
array-API namespace receives its own array type — declared (``array="jax"``, ``array="torch"``, a
namespace module; ``dtype=`` for another precision than the library's default) or detected from what it
returns on its first call — and its outputs are converted to NumPy float64 for the laws, their precision
reported: a float32 prox is judged at float32 precision (:mod:`verimono.core.tolerances`).  ``step=`` says how
the step is passed (positionally, as a keyword such as ``scaling``, or not at all for a projection), and
``batched=True`` declares a prox that maps a batch ``(B, *shape)`` with steps ``(B,)`` at once (vmapped,
vectorised): the search then evaluates its NumPy draws and its sweep a batch at a time.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from ._subgradients import (CONTAINS_POINTS, ProxOutputError, checked_value, contains_points,  # noqa: F401 - re-exported
                      subgradient_contains)
from .arrays import Boundary, array_kind, as_float64, batch_chunks, given_as_is, take_prefetched
from .errors import InvalidProblem
from .operators import Operator
from .operator_protocol import with_data_scale

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


def _time_keyword(fn: Callable) -> str | None:
    """The name of ``fn``'s time parameter (``t`` or ``time``) when it has one."""
    import inspect

    try:
        params = inspect.signature(fn).parameters
    except (TypeError, ValueError):
        return None
    return next((n for n in ("t", "time") if n in params), None)


class ProxOperator(Operator):
    """``F(t, ·) = ∂g(t, ·)`` given by ``prox(X, lam[, t])`` (and ``value(X[, t]) = g(t, X)``) on arrays of
    ``shape``; presented to the laws as an operator on ``R^{prod(shape)}`` (row-major flattening)."""

    def __init__(self, prox: Callable, *, value: Callable | None = None, shape: Any = None,
                 dim: int | None = None, name: str | None = None, unwrap: int | Callable | None = None,
                 array: Any = None, dtype: Any = None, device: Any = None, batched: bool = False,
                 step: str | bool | None = None) -> None:
        if not callable(prox):
            raise InvalidProblem("prox must be callable as prox(x, lam) or prox(x, lam, t)")
        if value is not None and not callable(value):
            raise InvalidProblem("value must be callable as value(x) or value(x, t)")
        if shape is None and dim is None:
            raise InvalidProblem("give the shape of the points (shape=(n,) or shape=(m, n)) or dim")
        if shape is None:
            shape = (int(dim),)
        given = shape
        try:
            parts = [shape] if np.ndim(shape) == 0 else list(shape)
            shape = tuple(int(s) for s in parts)
        except (TypeError, ValueError, OverflowError):
            raise InvalidProblem(f"shape must be a positive integer or a tuple of them, got {given!r}") from None
        if not shape or any(s < 1 for s in shape) or any(isinstance(p, bool) or p != s for p, s in zip(parts, shape)):
            raise InvalidProblem(f"shape must be a positive integer or a tuple of them, got {given!r}")
        if dim is not None and int(dim) != math.prod(shape):
            raise InvalidProblem(f"dim={dim} does not match shape={shape}")
        super().__init__(math.prod(shape), name or getattr(prox, "__name__", "prox"))
        if step is not None and step is not False and not (isinstance(step, str) and step.isidentifier()):
            raise InvalidProblem(f"step must be None (prox(x, lam)), a keyword name such as 'scaling' "
                                 f"(prox(x, scaling=lam)) or False (prox(x): a projection), got {step!r}")
        self.shape = shape
        self._prox, self._value, self._unwrap = prox, value, unwrap
        self._step = step
        if step is None:
            self._prox_t = _arity(prox, 3)
        elif step is False:
            self._prox_t = _arity(prox, 2)
        else:
            self._prox_t = _time_keyword(prox)
        self._value_t = value is not None and _arity(value, 2)
        self._io = Boundary(array_kind(array, dtype=dtype, device=device))
        #: the prox maps a batch (B, *shape) with steps (B,) (and times (B,)) at once
        self.batched = bool(batched)
        #: prox values of a batch evaluated ahead of the laws (verimono.checks.engine.batches)
        self._prefetched: dict | None = None

    @property
    def array(self) -> str:
        """The array library the prox computes with (declared or detected; ``"numpy"`` until detected)."""
        return self._io.name

    # -- the adapter ------------------------------------------------------------------------------
    def _shaped(self, x: np.ndarray) -> np.ndarray:
        if given_as_is(x, self._io.name) and x.shape == (self.dim,):   # an input form of the laws, as it is
            return x.reshape(self.shape)
        x = as_float64(x)
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
            p = self._io.returned(out)
        except (TypeError, ValueError) as exc:
            raise ProxOutputError(f"{self.name}: prox returned {type(out).__name__}, not an array of shape "
                                  f"{self.shape} ({exc})") from None
        if p.shape != self.shape:
            raise ProxOutputError(f"{self.name}: prox returned shape {p.shape} for a point of shape {self.shape}")
        return p.reshape(self.dim)

    def _call(self, X: Any, lam: Any, t: Any) -> Any:
        """The user's prox on ``X`` (already in its array type) with the step and time as it takes them."""
        args, kw = [X], {}
        if self._step is None:
            args.append(lam)
        elif self._step is not False:
            kw[self._step] = lam
        if self._prox_t:
            if isinstance(self._prox_t, str):
                kw[self._prox_t] = t
            else:
                args.append(t)
        return self._prox(*args, **kw)

    # -- the contract ------------------------------------------------------------------------------
    def resolvent(self, x, lam, t=0.0):
        x = x if given_as_is(x, self._io.name) else as_float64(x)
        if x.ndim == 2:   # a batch of flattened points: one call per row, or one batched call
            if self.batched:
                return self.resolvent_batch(x, np.full(x.shape[0], float(lam)), np.full(x.shape[0], float(t)))
            return np.array([self.resolvent(r, lam, t) for r in x]).reshape(x.shape)
        if self.batched:
            hit = take_prefetched(self._prefetched, x, lam, t)
            if hit is not None:
                return hit
            return self.resolvent_batch(x[None], np.array([float(lam)]), np.array([float(t)]))[0]
        X = self._io.given(self._shaped(x))
        return self._point(self._call(X, lam, t))

    def resolvent_batch(self, X: np.ndarray, lams: np.ndarray, ts: np.ndarray, pad: bool = True) -> np.ndarray:
        """``J_{λ_i}(X_i)`` at ``t_i`` for the rows of ``X`` ``(B, dim)`` in batched calls of the prox (chunks
        of at most :data:`verimono.core.arrays.MAX_BATCH` rows padded to a power of two, so that a jitted prox
        compiles for a few shapes; ``pad=False``: as they are, which the checks use to meet every batch size); a
        prox not declared ``batched`` is called row by row."""
        X = as_float64(X)
        lams, ts = np.asarray(lams, dtype=float), np.asarray(ts, dtype=float)
        if X.ndim != 2 or X.shape[1] != self.dim or lams.shape != (X.shape[0],) or ts.shape != (X.shape[0],):
            raise InvalidProblem(f"{self.name}: a batch is points (B, {self.dim}) with steps and times (B,); got "
                                 f"{X.shape}, {lams.shape}, {ts.shape}")
        if not self.batched:
            return np.array([self.resolvent(r, lam, t) for r, lam, t in zip(X, lams, ts)]).reshape(X.shape)
        out = np.empty_like(X)
        for lo, rows, pick in batch_chunks(X.shape[0], pad):
            Xb = self._io.given(X[pick].reshape((pick.size,) + self.shape))
            res = self._call(Xb, self._io.given(lams[pick]), self._io.given(ts[pick]) if self._prox_t else None)
            if self._unwrap is not None:
                res = self._unwrap(res) if callable(self._unwrap) else res[self._unwrap]
            elif isinstance(res, tuple):
                raise ProxOutputError(f"{self.name}: the batched prox returned a tuple of {len(res)} items, not "
                                      f"an array of shape {(pick.size,) + self.shape}; pass unwrap=0")
            try:
                P = self._io.returned(res)
            except (TypeError, ValueError) as exc:
                raise ProxOutputError(f"{self.name}: the batched prox returned {type(res).__name__}, not an "
                                      f"array of shape {(pick.size,) + self.shape} ({exc})") from None
            if P.shape != (pick.size,) + self.shape:
                raise ProxOutputError(f"{self.name}: the batched prox returned shape {P.shape} for a batch of "
                                      f"shape {(pick.size,) + self.shape}")
            out[lo:lo + rows] = P[:rows].reshape(rows, self.dim)
        return out

    def value(self, x, t=0.0) -> float:
        """``g(t, x)`` (``+inf`` outside ``dom g``) of a flattened point."""
        if self._value is None:
            return super().value(x, t)
        X = self._io.given(self._shaped(x))
        return checked_value(self, self._io.scalar(self._value(X, t) if self._value_t else self._value(X)))

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
        lib = self._io.name
        return f"{self.name}(shape={self.shape}" + ("" if lib == "numpy" else f", array={lib!r}") + ")"


def operator_from_prox(prox: Callable, *, value: Callable | None = None, shape: Any = None,
                       name: str | None = None, unwrap: int | Callable | None = None, array: Any = None,
                       dtype: Any = None, device: Any = None, batched: bool = False,
                       step: str | bool | None = None, data_scale: float | None = None) -> ProxOperator:
    """``F = ∂g`` from ``prox(x, lam) = argmin_z lam·g(z) + |z - x|²/2`` (or ``prox(x, lam, t)`` for a
    time-dependent ``g``), on arrays of ``shape`` (an int ``n`` or a tuple; the Frobenius inner product).

    ``value(x)`` or ``value(x, t)`` is ``g`` (``+inf`` outside its domain): it enables the value laws
    (prox inequality, optimality, Moreau envelope) and the membership test of ``yosida_in_graph``.
    ``unwrap`` picks the point from a prox returning a tuple (an index or a function); without it a tuple
    is a :class:`ProxOutputError`.  The arity of ``prox``/``value`` decides whether ``t`` is passed.

    ``step``: how ``λ`` is passed — ``None`` positionally (``prox(x, lam)``), a keyword name
    (``step="scaling"``: ``prox(x, scaling=lam)``, as JAX libraries take it; ``t`` then goes as ``t=`` if the
    prox has such a parameter), or ``False`` for a prox that takes no step (``prox(x)``: a projection,
    the prox of an indicator for every ``λ``).

    ``array``: the array library the prox computes with — ``"jax"``, ``"torch"``, ``"cupy"``, ``"numpy"``, or
    an array-API namespace (module or importable name); ``None`` detects it from what the first call
    returns.  ``dtype`` the precision its inputs are converted to (default the library's:
    float32 for JAX without x64 and for PyTorch); ``device`` where (PyTorch, JAX, array-API).  Outputs of
    any library are converted to NumPy float64 for the laws and their precision recorded: a float32 prox
    is judged at float32 precision (:mod:`verimono.core.tolerances`).

    ``batched=True``: ``prox`` maps a batch — points ``(B, *shape)``, steps ``(B,)`` (and times ``(B,)``) —
    to ``(B, *shape)`` (``jax.vmap``, ``torch.vmap`` or vectorised code); the search then evaluates its
    NumPy draws and its sweep a batch at a time (:mod:`verimono.checks.engine.batches`).

    ``data_scale``: the magnitude of the data the prox computes with, when larger than the points it is given
    (:attr:`verimono.Operator.data_scale`)."""
    if shape is None:
        raise InvalidProblem("operator_from_prox needs shape= (an int n for R^n, or a tuple such as (m, n))")
    return with_data_scale(ProxOperator(prox, value=value, shape=shape, name=name, unwrap=unwrap, array=array,
                                        dtype=dtype, device=device, batched=batched, step=step), data_scale)


__all__ = ["ProxOperator", "ProxOutputError", "operator_from_prox", "subgradient_contains", "contains_points", "CONTAINS_POINTS"]
