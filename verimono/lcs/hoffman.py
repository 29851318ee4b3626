"""Hoffman's bound for polyhedra (``e:hoffman``, used in the proof of ``e: linear case-comp``).

For ``𝓡 = {ζ : Rζ = 0, Qζ ≤ q} ≠ ∅`` there is ``α`` with ``dist(x, 𝓡) ≤ α(|Rx| + |max(0, Qx − q)|)`` for all
``x``.  :func:`hoffman_constant` computes a valid ``α`` in the Euclidean norms: with ``A = [R; −R; Q]``,

    α = max { 1/σ_min(A_J) : J a set of rows of A, linearly independent }.

Proof: let ``x̄`` be the projection of ``x`` onto ``𝓡``; ``x − x̄ = A_Jᵀ v`` with ``v ≥ 0`` on rows active at
``x̄``, and by Carathéodory ``J`` can be taken linearly independent (``r`` and ``−r`` never both).  Then
``|x − x̄|² = vᵀ A_J (x − x̄) = Σ v_i (a_i x − b_i) ≤ |v| |(A_J x − b_J)_+|`` and ``|x − x̄| = |A_Jᵀ v| ≥
σ_min(A_J)|v|``, so ``dist(x, 𝓡) ≤ |(Ax − b)_+|/σ_min(A_J)``; and ``|(Ax − b)_+| ≤ |Rx| + |max(0, Qx − q)|``.
The maximum runs over at most ``2^rows`` subsets (:data:`HOFFMAN_MAX_ROWS`); the bound does not depend on
``q`` (Hoffman's constant depends only on the matrices).
"""

from __future__ import annotations

import itertools

import numpy as np

from ..core.errors import InvalidCheckArgument

#: rows of ``[R; −R; Q]`` (after dropping ``−R`` duplicates of nothing) up to which subsets are enumerated
HOFFMAN_MAX_ROWS = 16


def hoffman_constant(Q, R=None) -> float:
    """A Hoffman constant ``α`` of ``{ζ : Rζ = 0, Qζ ≤ q}`` (any ``q``) for Euclidean norms (module docstring)."""
    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    rows = [Q] if R is None else [np.atleast_2d(np.asarray(R, dtype=float)), -np.atleast_2d(np.asarray(R, float)), Q]
    A = np.vstack(rows)
    A = A[np.linalg.norm(A, axis=1) > 0]
    if A.shape[0] > HOFFMAN_MAX_ROWS:
        raise InvalidCheckArgument(f"hoffman_constant enumerates row subsets: at most {HOFFMAN_MAX_ROWS} rows, got "
                                   f"{A.shape[0]}")
    n = A.shape[1]
    best = 0.0
    for size in range(1, min(n, A.shape[0]) + 1):
        for J in itertools.combinations(range(A.shape[0]), size):
            s = np.linalg.svd(A[list(J)], compute_uv=False)
            if s[-1] > 1e-12 * max(1.0, s[0]):             # linearly independent rows
                best = max(best, 1.0 / float(s[-1]))
    return best


__all__ = ["hoffman_constant", "HOFFMAN_MAX_ROWS"]
