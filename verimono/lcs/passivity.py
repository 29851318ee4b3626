"""Passivity of ``Σ(A, B, C, D)`` (the paper's Section 7, ``e:lmis``; Kalman–Yakubovich–Popov).

``Σ`` is passive with storage ``½xᵀKx`` iff ``K = Kᵀ ⪰ 0`` and

    Q(K) = [[AᵀK + KA, KB − Cᵀ], [BᵀK − C, −(D + Dᵀ)]] ⪯ 0.

With ``K`` given (the paper's theorems use ``K = I``) this is an eigenvalue test of ``Q(K)``; with ``K``
unknown an SDP ``min λ_max(Q(K))`` over ``K ⪰ 0, tr K ≤ κ`` (cvxpy with Clarabel, an optional dependency,
imported lazily), whose answer is re-verified by eigenvalues.  The consequences of Proposition ``p:pass``
are checked too: ``D + Dᵀ ⪰ 0`` and ``(KB − Cᵀ) ker(D + Dᵀ) = {0}``.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import InvalidProblem, VerimonoError
from ..tolerances import RTOL, SDP_RTOL


class MissingOptionalDependency(VerimonoError, ImportError):
    """An optional extra (here cvxpy/clarabel for the KYP SDP) is not installed."""


@dataclasses.dataclass
class PassivityResult:
    """``passive`` iff ``margin = −λ_max(Q(K)) ≥ −tol`` and ``K ⪰ 0``; ``D_psd`` and ``kernel_ok`` are the
    consequences i and ii of Proposition ``p:pass`` (``kernel_residual = ‖(KB − Cᵀ)N‖``, ``N`` an orthonormal
    basis of ``ker(D + Dᵀ)``)."""

    passive: bool
    K: np.ndarray
    margin: float
    tol: float
    D_psd: bool
    kernel_ok: bool
    kernel_residual: float
    method: str
    message: str = ""

    def __bool__(self) -> bool:
        return self.passive


def kyp_matrix(A, B, C, D, K) -> np.ndarray:
    """``Q(K)`` of ``e:lmis``."""
    return np.block([[A.T @ K + K @ A, K @ B - C.T], [B.T @ K - C, -(D + D.T)]])


def _check(A, B, C, D):
    A = np.array(A, float, ndmin=2)
    n = A.shape[0]
    B = np.array(B, float, ndmin=2)
    m = B.shape[1] if B.shape[0] == n else -1
    C, D = np.array(C, float, ndmin=2), np.array(D, float, ndmin=2)
    if A.shape != (n, n) or B.shape != (n, m) or C.shape != (m, n) or D.shape != (m, m):
        raise InvalidProblem(f"need A (n×n), B (n×m), C (m×n), D (m×m); got {A.shape}, {B.shape}, {C.shape}, {D.shape}")
    if not all(np.all(np.isfinite(X)) for X in (A, B, C, D)):
        raise InvalidProblem("A, B, C, D must be finite")
    return A, B, C, D


def _verdict(A, B, C, D, K, method, rtol):
    Q = kyp_matrix(A, B, C, D, K)
    scale = 1.0 + max(np.abs(Q).max(initial=0.0), np.abs(K).max(initial=0.0) * (1 + np.abs(A).max(initial=0.0)))
    tol = rtol * scale
    margin = -float(np.linalg.eigvalsh(0.5 * (Q + Q.T))[-1])
    k_psd = bool(np.linalg.eigvalsh(0.5 * (K + K.T))[0] >= -tol and np.abs(K - K.T).max(initial=0.0) <= tol)
    S = D + D.T
    ev, V = np.linalg.eigh(S)
    D_psd = bool(ev[0] >= -tol)
    N = V[:, np.abs(ev) <= RTOL * (1.0 + np.abs(S).max(initial=0.0))]
    kres = float(np.linalg.norm((K @ B - C.T) @ N, 2)) if N.size else 0.0
    kernel_ok = bool(kres <= tol)
    passive = bool(margin >= -tol and k_psd)
    msg = (f"λ_max(Q(K)) = {-margin:.3g} (tolerance {tol:.2g}); K {'⪰' if k_psd else 'is not ⪰'} 0; "
           f"D + Dᵀ {'⪰ 0' if D_psd else 'is not ⪰ 0'}; ‖(KB − Cᵀ) ker(D + Dᵀ)‖ = {kres:.3g}")
    return PassivityResult(passive, K, margin, tol, D_psd, kernel_ok, kres, method, msg)


def is_passive(A, B, C, D, K=None, *, trace_bound: float | None = None) -> PassivityResult:
    """Whether ``Σ(A, B, C, D)`` is passive; with ``K`` given, for the storage ``½xᵀKx``.

    ``K=None`` searches ``K ⪰ 0`` by an SDP (needs the optional ``sdp`` extra: cvxpy, clarabel) with
    ``tr K ≤ trace_bound`` (default ``n``, a normalisation: the LMI is not homogeneous in ``K``, so a
    system needing a larger ``K`` should pass a larger bound).  The result is truthy iff passive.
    """
    A, B, C, D = _check(A, B, C, D)
    n = A.shape[0]
    if K is not None:
        K = np.array(K, float, ndmin=2)
        if K.shape != (n, n) or not np.all(np.isfinite(K)):
            raise InvalidProblem(f"K must be a finite {n}×{n} matrix, got shape {K.shape}")
        return _verdict(A, B, C, D, K, "eigenvalues of Q(K)", RTOL)
    try:
        import cvxpy as cp
    except ImportError:
        raise MissingOptionalDependency("is_passive(K=None) solves the KYP LMI as an SDP and needs the optional "
                                        "extra 'sdp' (pip install cvxpy clarabel); pass K explicitly "
                                        "(e.g. K=np.eye(n)) for the eigenvalue test") from None
    m = B.shape[1]
    Kv = cp.Variable((n, n), symmetric=True)
    t = cp.Variable()
    Q = cp.bmat([[A.T @ Kv + Kv @ A, Kv @ B - C.T], [B.T @ Kv - C, -(D + D.T)]])
    cons = [Kv >> 0, 0.5 * (Q + Q.T) << t * np.eye(n + m), cp.trace(Kv) <= (trace_bound or float(n))]
    prob = cp.Problem(cp.Minimize(t), cons)
    try:
        prob.solve(solver="CLARABEL")
    except Exception as exc:  # the solver's own failure becomes a typed one
        raise MissingOptionalDependency(f"the KYP SDP could not be solved by Clarabel: {exc}") from None
    if Kv.value is None:
        raise VerimonoError(f"the KYP SDP returned no K (status {prob.status})")
    Kval = 0.5 * (Kv.value + Kv.value.T)
    return _verdict(A, B, C, D, Kval, f"SDP (cvxpy/Clarabel, status {prob.status})", SDP_RTOL)


__all__ = ["is_passive", "PassivityResult", "kyp_matrix", "MissingOptionalDependency"]
