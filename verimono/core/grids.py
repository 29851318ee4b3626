"""Partitions ``Δ = {0 = t_0 < t_1 < ... < t_K = T}`` of ``[0, T]`` (Section 5.1 of the paper).

The scheme runs on any increasing partition, uniform or not.  ``uniform_grid(T, h)`` makes the uniform
one; :func:`graded_grid`, :func:`random_grid` and :func:`refine` make nonuniform ones; any increasing
array from ``0`` to ``T`` is accepted by :func:`verimono.solve` after :func:`validate_grid`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .errors import InvalidGrid

#: relative slack when matching a grid's last point to T (round-off of cumulative sums)
_END_RTOL = 1e-12


def validate_grid(t_grid, T: float | None = None) -> np.ndarray:
    """Return ``t_grid`` as a float array after checking it is a partition of ``[0, T]``.

    Raises :class:`InvalidGrid` when it is not one-dimensional, has fewer than two points, contains
    non-finite values, does not start at 0, does not end at ``T`` or is not strictly increasing.
    """
    if np.iscomplexobj(t_grid):   # np.asarray(z, dtype=float) would drop the imaginary part silently
        raise InvalidGrid("time grid must be real, got complex values")
    try:
        t = np.asarray(t_grid, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidGrid(f"time grid must be an array of numbers: {exc}") from None
    if t.ndim != 1 or t.size < 2:
        raise InvalidGrid(f"time grid must be a 1-D array of at least 2 points, got shape {t.shape}")
    if not np.all(np.isfinite(t)):
        raise InvalidGrid(f"time grid contains non-finite values at indices {np.flatnonzero(~np.isfinite(t))[:5]}")
    if t[0] != 0.0:
        raise InvalidGrid(f"time grid must start at t_0 = 0, got t_0 = {t[0]!r}")
    steps = np.diff(t)
    if np.any(steps <= 0):
        k = int(np.flatnonzero(steps <= 0)[0])
        raise InvalidGrid(f"time grid must be strictly increasing (all steps h_k > 0); "
                          f"step {k + 1} is h = {steps[k]!r} (t[{k}] = {t[k]!r}, t[{k + 1}] = {t[k + 1]!r})")
    if T is not None and abs(t[-1] - T) > _END_RTOL * max(1.0, abs(T)):
        raise InvalidGrid(f"time grid must end at T = {T!r}, got t_K = {t[-1]!r}")
    if T is not None:
        t = t.copy()
        t[-1] = T
    return t


#: at most this many cells in a grid built here (8·10^8 bytes of nodes): more is a mistake (a step size
#: meant in other units), refused with a clear error instead of a MemoryError or an hour of work
MAX_CELLS = 10 ** 8


def _horizon(T: Any) -> float:
    try:
        T = float(T)
    except (TypeError, ValueError):
        raise InvalidGrid(f"T must be a positive finite number, got {T!r}") from None
    if not np.isfinite(T) or T <= 0:
        raise InvalidGrid(f"T must be positive and finite, got {T!r}")
    return T


def _cells(steps: Any, what: str = "steps") -> int:
    """A positive whole number of cells, at most :data:`MAX_CELLS`."""
    try:
        K = int(steps)
    except (TypeError, ValueError, OverflowError):
        raise InvalidGrid(f"{what} must be a positive integer, got {steps!r}") from None
    if isinstance(steps, bool) or K < 1 or K != steps:
        raise InvalidGrid(f"{what} must be a positive integer, got {steps!r}")
    if K > MAX_CELLS:
        raise InvalidGrid(f"{what} = {K} exceeds {MAX_CELLS} cells (verimono.core.grids.MAX_CELLS): is the step in "
                          "the right units?")
    return K


def uniform_grid(T: float, h: float | None = None, *, steps: int | None = None) -> np.ndarray:
    """Uniform partition of ``[0, T]`` with step ``h`` (which must divide ``T``) or ``steps`` cells."""
    T = _horizon(T)
    if (h is None) == (steps is None):
        raise InvalidGrid("give exactly one of h and steps")
    if h is not None:
        if not np.isfinite(h) or h <= 0:
            raise InvalidGrid(f"step size must be positive and finite, got h = {h!r}")
        if T / h > MAX_CELLS:
            raise InvalidGrid(f"h = {h!r} gives {T / h:.3g} cells on [0, {T!r}], more than {MAX_CELLS} "
                              "(verimono.core.grids.MAX_CELLS): is the step in the right units?")
        K = int(round(T / h))
        if K < 1 or abs(K * h - T) > 1e-9 * T:
            raise InvalidGrid(f"h = {h!r} does not divide T = {T!r} (T/h = {T / h!r}); "
                              "use uniform_grid(T, steps=K) for K equal cells")
    else:
        K = _cells(steps)
    return np.linspace(0.0, T, K + 1)


def graded_grid(T: float, steps: int, power: float = 2.0) -> np.ndarray:
    """Graded partition ``t_k = T (k/K)^power`` (fine near 0 for ``power > 1``)."""
    T, K = _horizon(T), _cells(steps)
    if not (isinstance(power, (int, float)) and np.isfinite(power) and power > 0):
        raise InvalidGrid(f"power must be positive and finite, got {power!r}")
    s = np.linspace(0.0, 1.0, K + 1)
    t = T * s ** power
    t[-1] = T
    return validate_grid(t, T)


def random_grid(T: float, steps: int, *, seed: int = 0, spread: float = 0.5) -> np.ndarray:
    """Random partition with ``steps`` cells whose lengths vary by a factor up to ``(1+spread)/(1-spread)``."""
    T, K = _horizon(T), _cells(steps)
    if not (isinstance(spread, (int, float)) and 0 <= spread < 1):
        raise InvalidGrid(f"spread must lie in [0, 1), got {spread!r}")
    try:
        rng = np.random.default_rng(seed)
    except (TypeError, ValueError) as exc:
        raise InvalidGrid(f"seed must be a non-negative integer, got {seed!r} ({exc})") from None
    w = 1.0 + spread * rng.uniform(-1.0, 1.0, K)
    t = np.concatenate([[0.0], np.cumsum(w)]) * (T / w.sum())
    t[-1] = T
    return validate_grid(t, T)


def refine(t_grid, factor: int = 2) -> np.ndarray:
    """Split every cell of a partition into ``factor`` equal cells (nested refinement)."""
    t = validate_grid(t_grid)
    factor = _cells(factor, "factor")
    if (len(t) - 1) * factor > MAX_CELLS:
        raise InvalidGrid(f"refining {len(t) - 1} cells by {factor} exceeds {MAX_CELLS} cells (verimono.core.grids.MAX_CELLS)")
    s = np.linspace(0.0, 1.0, factor + 1)[:-1]
    fine = (t[:-1, None] + np.diff(t)[:, None] * s[None, :]).ravel()
    return np.concatenate([fine, t[-1:]])


def mesh(t_grid) -> float:
    """Granularity ``|Δ| = max_k h_k``."""
    return float(np.max(np.diff(np.asarray(t_grid, dtype=float))))


__all__ = ["validate_grid", "uniform_grid", "graded_grid", "random_grid", "refine", "mesh"]
