"""An operator's members as the laws evaluate them: every returned value checked to be a finite point of
the input's shape and converted to NumPy float64 for the laws' arithmetic — from any array library, its
precision reported to the judgement in progress (:func:`verimono.core.arrays.as_float64`), so that a float32
subject is judged at float32 precision — norms computed without underflow, points shortened for
counterexamples."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..core.arrays import as_float64
from .samples import NUMPY_DIM


class _BadOutput(Exception):
    """An operator member returned something that is not a finite point of the right shape."""


def point(value: Any, like: np.ndarray, member: str) -> np.ndarray:
    """``value`` as a float64 array of ``like``'s shape with finite entries (its precision observed);
    ``_BadOutput`` otherwise."""
    y = as_float64(value)
    if y.shape != like.shape:
        raise _BadOutput(f"{member} returned shape {y.shape} for a point of shape {like.shape}")
    if not np.all(np.isfinite(y)):
        raise _BadOutput(f"{member} returned non-finite values {y}")
    return y


def resolvent(op: Any, x: np.ndarray, lam: float, t: float) -> np.ndarray:
    """``J_λ x`` (on a copy of ``x``: an operator that modifies its input cannot corrupt the sample)."""
    return point(op.resolvent(x.copy(), lam, t), x, "resolvent")


def min_norm(op: Any, x: np.ndarray, t: float) -> np.ndarray:
    """``F^0(t, x)``."""
    return point(op.min_norm(x.copy(), t), x, "min_norm")


def value(op: Any, z: Any, t: float) -> float:
    """``g(t, z)`` of an operator ``F = ∂g`` that states ``g``."""
    v = op.value(np.array(z, dtype=float), t)
    if type(v) is not float:
        v = as_float64(v)
    return float(v)


def norm(v: Any) -> float:
    """Euclidean norm without underflow: sampled points may differ by 1e-250, whose square is 0."""
    v = np.asarray(v, dtype=float)
    m = float(np.max(np.abs(v), initial=0.0))
    return 0.0 if m == 0.0 or not math.isfinite(m) else m * float(np.linalg.norm(v / m))


def listed(a: np.ndarray) -> Any:
    """A point for a counterexample: its coordinates, or for ``n > NUMPY_DIM`` a summary (the sample's
    recipe replays it; a million coordinates per record would swamp the report)."""
    if a.size <= NUMPY_DIM:
        return a.tolist()
    return f"<{a.size} values, |.|_inf = {float(np.max(np.abs(a))):.6g}>"


__all__ = ["point", "resolvent", "min_norm", "value", "norm", "listed"]
