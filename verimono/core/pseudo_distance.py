"""Lower bounds of Vladimirov's pseudo-distance (the paper's Definition ``def:dis``)

    dis(F1, F2) = sup { ⟨y1 − y2, x2 − x1⟩ / (1 + |y1| + |y2|) : y1 ∈ F1(x1), y2 ∈ F2(x2) }.

Any finite set of graph points gives a lower bound.  Graph points of a maximal monotone ``F`` come from its
resolvent: ``(J_λ x, Y_λ x) ∈ graph F`` for every ``x`` and ``λ > 0`` (Proposition
``prop:maxmon-resolvent-Yosida`` v), so sampling ``x`` and ``λ`` explores the whole graph, including the
unbounded normal-cone parts at the boundary of the domain (large ``|x − J_λ x|/λ``).
"""

from __future__ import annotations

import dataclasses
from typing import Any, Sequence

import numpy as np

from .errors import InvalidProblem


@dataclasses.dataclass
class PseudoDistanceBound:
    """``value ≤ dis(F1, F2)``, attained by ``(x1, y1) ∈ graph F1`` and ``(x2, y2) ∈ graph F2``."""

    value: float
    x1: np.ndarray
    y1: np.ndarray
    x2: np.ndarray
    y2: np.ndarray

    def __float__(self) -> float:
        return self.value


def graph_points(F: Any, samples: Any, lams: Sequence[float] = (1.0,), t: float = 0.0):
    """``(X, Y)`` with ``Y[i] ∈ F(t, X[i])``: resolvent points ``(J_λ x, Y_λ x)`` of an Operator, or ``F`` itself
    when it is already a pair of arrays of graph points."""
    if isinstance(F, tuple) and len(F) == 2:
        X, Y = (np.atleast_2d(np.asarray(a, dtype=float)) for a in F)
    else:
        S = np.asarray(samples, dtype=float)
        if S.ndim < 2:
            S = S.reshape(-1, 1) if F.dim == 1 else S.reshape(1, -1)
        Xs, Ys = [], []
        for lam in lams:
            J = np.array([F.resolvent(s, lam, t) for s in S])
            Xs.append(J)
            Ys.append((S - J) / lam)
        X, Y = np.vstack(Xs), np.vstack(Ys)
    if X.shape != Y.shape or not (np.all(np.isfinite(X)) and np.all(np.isfinite(Y))):
        raise InvalidProblem(f"graph points must be finite arrays of equal shape, got {X.shape} and {Y.shape}")
    return X, Y


def pseudo_distance_lower_bound(F1: Any, F2: Any, samples: Any, *, lams: Sequence[float] = (1.0,),
                                t1: float = 0.0, t2: float = 0.0) -> PseudoDistanceBound:
    """Lower bound of ``dis(F1(t1,·), F2(t2,·))`` over sampled graph points (see the module docstring).

    ``F1``/``F2`` are :class:`verimono.Operator` objects (graph points from their resolvents at the
    ``samples`` with every ``λ`` in ``lams``) or pairs ``(X, Y)`` of graph points.  Every pair of points is
    compared; the maximiser is returned with the value.
    """
    X1, Y1 = graph_points(F1, samples, lams, t1)
    X2, Y2 = graph_points(F2, samples, lams, t2)
    num = Y1 @ X2.T - np.sum(Y1 * X1, axis=1)[:, None] - np.sum(Y2 * X2, axis=1)[None, :] + X1 @ Y2.T
    den = 1.0 + np.linalg.norm(Y1, axis=1)[:, None] + np.linalg.norm(Y2, axis=1)[None, :]
    R = num / den
    i, j = np.unravel_index(int(np.argmax(R)), R.shape)
    return PseudoDistanceBound(float(R[i, j]), X1[i], Y1[i], X2[j], Y2[j])


__all__ = ["pseudo_distance_lower_bound", "graph_points", "PseudoDistanceBound"]
