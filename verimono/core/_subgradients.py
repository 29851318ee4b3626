"""Function values ``g`` of subdifferential operators ``F = ∂g``: the typed error for bad prox/value output,
the checked value, and the value-based membership evidence ``y ∈ ∂g(x)`` used by :mod:`verimono.core.prox`
and by ``operator_from_resolvent(..., value=g)``.  Duck-typed on ``op.resolvent``/``op.value``/``op.name``
(no import of :mod:`verimono.core.operators`, which uses it)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .errors import ProxOutputError
from .tolerances import current_rtol, tolerance

#: sampled points ``z`` of the subgradient inequality in :meth:`ProxOperator.contains`
CONTAINS_POINTS = 24


def checked_value(op: Any, v: Any) -> float:
    """``v`` as a float ``g(x) ∈ R ∪ {+inf}``; anything else is a :class:`ProxOutputError` — a bool too: it is a
    membership test (PyProximal's indicators return ``True`` inside), which as a number would state ``g = 1`` on
    the set and ``0`` outside, and fail the value laws of a correct projection."""
    if isinstance(v, bool) or getattr(v, "dtype", None) == np.bool_:
        raise ProxOutputError(f"{op.name}: value returned a bool ({v}): a membership test, not g; pass the "
                              "indicator, value=lambda x: 0.0 if member(x) else np.inf")
    try:
        a = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        raise ProxOutputError(f"{op.name}: value returned {type(v).__name__}, expected a number") from None
    if a.shape != ():
        raise ProxOutputError(f"{op.name}: value returned shape {a.shape}, expected a scalar")
    f = float(a)
    if math.isnan(f) or f == -math.inf:
        raise ProxOutputError(f"{op.name}: value returned {f}; g must be real or +inf")
    return f


def subgradient_contains(op: Any, x, y, t: float = 0.0, tol: float | None = None) -> bool:
    """Evidence for ``y ∈ ∂g(t, x)`` from ``op.value`` and ``op.resolvent`` — not a proof:

    * the resolvent characterisation ``J_1(x + y) = x`` (exact for a maximal monotone ``F``, but it trusts
      the resolvent, so alone it would make ``yosida_in_graph`` circular), and
    * the subgradient inequality ``g(x) + ⟨y, z - x⟩ ≤ g(z) + tol·(1 + |z - x|)(1 + |y|)`` at the
      ``CONTAINS_POINTS`` points ``z`` of :func:`contains_points` (``0``, and ``x ± s·d`` along coordinates,
      ``y`` and seeded random directions ``d`` at scales ``s`` from ``10^-6`` to ``10`` times
      ``1 + |x|_∞``; the same ``(x, y)`` always gets the same ``z``), which is what ties the pair to ``g``.

    ``g(x) = +inf`` (``x ∉ dom g``) is never contained; points ``z`` with ``g(z) = +inf`` are skipped."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    tol = tolerance(x, y) if tol is None else float(tol)
    ny = float(np.linalg.norm(y))
    p = np.asarray(op.resolvent(x + y, 1.0, t), dtype=float)
    if np.max(np.abs(p - x), initial=0.0) > tol * (1.0 + ny):
        return False
    gx = op.value(x, t)
    if not math.isfinite(gx):
        return False
    for z in contains_points(x, y):
        gz = op.value(z, t)
        if gz == math.inf:
            continue
        d = float(np.linalg.norm(z - x))
        if gx + float(y @ (z - x)) > gz + tol * (1.0 + d) * (1.0 + ny) + current_rtol() * (1.0 + max(abs(gx), abs(gz))):
            return False
    return True


def _unit(n: int, i: int) -> np.ndarray:
    """``e_i`` in ``R^n`` (without the ``n x n`` identity)."""
    e = np.zeros(n)
    e[i] = 1.0
    return e


def contains_points(x: np.ndarray, y: np.ndarray, count: int = CONTAINS_POINTS) -> list[np.ndarray]:
    """The deterministic test points ``z`` of :meth:`ProxOperator.contains` (see there)."""
    n = x.size
    rng = np.random.default_rng(n)
    s0 = 1.0 + float(np.max(np.abs(x), initial=0.0))
    dirs = [_unit(n, i) for i in range(min(n, 4))]
    ny = float(np.linalg.norm(y))
    if ny > 0:
        dirs.append(y / ny)
    while len(dirs) < max(8, count // 3):
        v = rng.standard_normal(n)
        dirs.append(v / np.linalg.norm(v))
    pts = [np.zeros(n)]
    scales = (1e-6, 1e-3, 1e-1, 1.0, 10.0)
    k = 0
    while len(pts) < count:
        d, s = dirs[k % len(dirs)], scales[(k // len(dirs)) % len(scales)]
        sign = 1.0 if k % 2 == 0 else -1.0
        pts.append(x + sign * s * s0 * d)
        k += 1
    return pts


__all__ = ["ProxOutputError", "checked_value", "subgradient_contains", "contains_points", "CONTAINS_POINTS"]
