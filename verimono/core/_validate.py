"""Validation of what the solver core is given: step sizes, points, time-dependent parameters — a typed
:class:`verimono.InvalidProblem` naming what was wrong, never a silent NaN."""

from __future__ import annotations

import numbers

import numpy as np

from ._small import all_finite
from .errors import InvalidProblem

_INF = float("inf")


def bad_lam(lam: object, who: str) -> InvalidProblem:
    """The error for a step size ``λ`` that is not a finite positive number (``J_λ`` is defined for
    ``λ > 0`` only: ``λ = 0`` is the identity, whose Yosida value ``0/0`` is NaN, and ``λ < 0`` inverts a
    non-monotone ``I + λF``)."""
    return InvalidProblem(f"{who}: the step size λ must be a finite number > 0, got {lam!r}")


def check_lam(lam: object, who: str) -> float:
    """``lam`` as a float after checking ``0 < λ < ∞`` (:func:`bad_lam` otherwise)."""
    if isinstance(lam, complex) or isinstance(lam, np.complexfloating):
        raise bad_lam(lam, who)
    try:
        v = float(lam)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise bad_lam(lam, who) from None
    if not 0.0 < v < _INF:
        raise bad_lam(lam, who)
    return v


def real_array(x: object, what: str = "point") -> np.ndarray:
    """``x`` as a float64 array; :class:`InvalidProblem` for complex values (``np.asarray(z, float)`` would
    silently drop the imaginary part) or non-numeric ones.  A float64 array is returned as it is."""
    if type(x) is np.ndarray and x.dtype == np.float64:
        return x
    a = np.asarray(x)
    if a.dtype.kind == "c":
        raise InvalidProblem(f"{what} must be real, got complex values {x!r:.80}")
    try:
        return a.astype(float, copy=False)
    except (TypeError, ValueError) as exc:
        raise InvalidProblem(f"{what} must be numeric: {exc}") from None


def states_shape_error(who: str, shape: tuple, nodes: int, dim: tuple) -> InvalidProblem:
    """The error for a stepper's states of the wrong shape: ``(K + 1,) + x0.shape`` was expected, one state per
    node of the grid of ``nodes = K + 1`` times, ``x_0`` first.  The shapes users return by mistake are named
    with their likely cause: one state too many (a loop ``while t < T: t += h`` whose sum of steps falls short of
    ``T`` by round-off takes one more step, of size ~1e-16: solve_nivp c82f2bc's fixed-step driver), one too
    few (``x_0`` left out, or ``floor(T/h)`` steps), the transpose, the states of a one-dimensional problem as
    a flat array."""
    expected = (nodes,) + tuple(dim)
    shape = tuple(shape)
    msg = f"stepper {who} returned shape {shape}, expected {expected}: one state per node of t_grid, x_0 first"
    if len(shape) == len(expected) and shape[1:] == expected[1:] and shape[0] == nodes + 1:
        why = (f"one state more than the {nodes} nodes — a stepper that steps past the last node (a loop "
               f"'while t < T: t += h' takes one more step of round-off size when its sum of steps falls short "
               f"of T); step over the nodes: for k in range(len(t_grid) - 1)")
    elif len(shape) == len(expected) and shape[1:] == expected[1:] and shape[0] == nodes - 1:
        why = (f"one state fewer than the {nodes} nodes — x_0 left out, or floor(T / h) steps, one short when "
               f"h does not divide T in floating point; step over the nodes: for k in range(len(t_grid) - 1)")
    elif len(expected) == 2 and shape == expected[::-1]:
        why = "the transpose: states are rows (scipy's solve_ivp returns sol.y of shape (n, K + 1): return sol.y.T)"
    elif expected[1:] == (1,) and shape == (nodes,):
        why = "a flat array for a problem of dimension 1: return the states as a column, x[:, None]"
    else:
        return InvalidProblem(msg)
    return InvalidProblem(f"{msg}; {why}")


def finite_point(x: object, what: str) -> np.ndarray:
    """:func:`real_array` and every entry finite (a projection of a NaN point has no meaning)."""
    a = real_array(x, what)
    if not all_finite(a):
        raise InvalidProblem(f"{what} must be finite, got {np.array2string(a, threshold=8)}")
    return a


def bad_param(owner: str, what: str, value: object, t: float, need: str, cls: type = InvalidProblem) -> Exception:
    """The error for a time-dependent parameter invalid at time ``t`` (the failing ``t`` in the message)."""
    v = np.array2string(np.asarray(value), threshold=8) if not isinstance(value, float) else f"{value:g}"
    return cls(f"{owner}: {what} = {v} at t = {t!r}: {need}")


def batch_column(p: np.ndarray, x: np.ndarray, what: str) -> np.ndarray:
    """A per-operator scalar parameter ``p`` shaped to broadcast against the rows of ``x``.

    A scalar is returned as is; a batch ``(B,)`` — one value per operator of a batch — applies row by row
    and needs points of shape ``(B, n)``: anything else would broadcast silently (``(B,)`` against a
    point ``(n,)`` with ``B = n`` mixes operators and coordinates), so it is an :class:`InvalidProblem`.
    """
    if p.ndim == 0:
        return p
    if x.ndim != 2 or x.shape[0] != p.shape[0]:
        raise InvalidProblem(f"{what} is a batch of {p.shape[0]} values (one per operator): it applies to "
                             f"points of shape ({p.shape[0]}, n), got a point of shape {x.shape}")
    return p[:, None]


def _real(value: object) -> bool:
    """A real number: a Python or NumPy int or float, not a bool (``True`` is not a step size)."""
    return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))


def step_range_of(step_range: object, cls: type = InvalidProblem) -> tuple[float, float]:
    """``step_range = (h_min, h_max)`` (either order) as two finite step sizes ``> 0``, sorted; ``cls``
    otherwise.  Whether it holds two grids of a problem's ``[0, T]`` depends on ``T``: that is decided per
    problem (:func:`verimono.core.grid_design.cells_range`)."""
    try:
        a, b = step_range  # type: ignore[misc]
    except (TypeError, ValueError):
        raise cls(f"step_range must be two step sizes (h_min, h_max), got {step_range!r}") from None
    if not (_real(a) and _real(b)) or not all(0.0 < float(v) < _INF for v in (a, b)):
        raise cls(f"step_range must be two positive finite step sizes (h_min, h_max), got {step_range!r}")
    return min(float(a), float(b)), max(float(a), float(b))


def study_executor(executor: object, cls: type = InvalidProblem) -> object:
    """``executor`` of a convergence study: ``None``, ``"serial"``, ``"process"`` or a ``concurrent.futures``
    executor (an object with ``submit``); ``cls`` otherwise."""
    if executor is None or (executor in ("serial", "process") if isinstance(executor, str)
                            else hasattr(executor, "submit")):
        return executor
    raise cls(f"executor must be a concurrent.futures.Executor, 'process', 'serial' or None, got {executor!r}")


def refinement_of(value: object, cls: type = InvalidProblem) -> int:
    """``reference_refinement``: an integer ``>= 2`` (the fine reference grid is that many times finer than the
    finest grid studied: 1 would measure the finest grid against itself, a fraction would be no refinement)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral) or value < 2:
        raise cls(f"reference_refinement must be an integer >= 2, got {value!r}")
    return int(value)


__all__ = ["step_range_of", "study_executor", "refinement_of", "check_lam", "bad_lam", "real_array", "finite_point", "bad_param", "batch_column"]
