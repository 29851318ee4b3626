"""Passivity of ``Σ(A, B, C, D)`` (the paper's Section 7, ``e:lmis``; Kalman–Yakubovich–Popov).

``Σ`` is passive with storage ``½xᵀKx`` iff ``K = Kᵀ ⪰ 0`` and

    Q(K) = [[AᵀK + KA, KB − Cᵀ], [BᵀK − C, −(D + Dᵀ)]] ⪯ 0.

With ``K`` given (the paper's theorems use ``K = I``) this is an eigenvalue test of ``Q(K)``; with ``K``
unknown the feasibility SDP ``min tr K`` s.t. ``Q(K) ⪯ 0, K ⪰ 0`` (cvxpy with Clarabel, an optional
dependency, imported lazily) — no bound on ``K`` — whose answer is re-verified by eigenvalues: a ``K``
proves passivity, a Farkas certificate proves the opposite, anything else is reported as undecided
(:class:`verimono.SolverFailure`).  The consequences of Proposition ``p:pass`` are checked too:
``D + Dᵀ ⪰ 0`` and ``(KB − Cᵀ) ker(D + Dᵀ) = {0}``.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..core.errors import InvalidProblem, MissingOptionalDependency, SolverFailure
from ..core.tolerances import RTOL, SDP_RTOL, tolerance


@dataclasses.dataclass
class PassivityResult:
    """``passive`` iff ``margin = −λ_max(Q(K)) ≥ −tol`` and ``K ⪰ 0``; ``D_psd`` and ``kernel_ok`` are the
    consequences i and ii of Proposition ``p:pass`` (``kernel_residual = ‖(KB − Cᵀ)N‖``, ``N`` an orthonormal
    basis of ``ker(D + Dᵀ)``).  When the SDP proves that no storage exists, ``K`` is None, ``margin = −∞``
    and ``certificate`` holds the verified Farkas certificate (see :func:`is_passive`)."""

    passive: bool
    K: np.ndarray | None
    margin: float
    tol: float
    D_psd: bool
    kernel_ok: bool
    kernel_residual: float
    method: str
    message: str = ""
    certificate: dict | None = None

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
    """Eigenvalue test of ``e:lmis`` for one ``K``, at ``rtol`` relative to the size of the terms ``Q(K)`` is
    summed from (``|Aᵀ||K| + |K||A|``, ``|K||B|``, ``|C|``, ``|D|`` entrywise; ``K ⪰ 0`` relative to ``|K|``):
    a storage matrix of size 100 for an input matrix of size 0.01 is judged in the units of ``KB``."""
    Q = kyp_matrix(A, B, C, D, K)
    aK, aA = np.abs(K), np.abs(A)
    terms = [aA.T @ aK + aK @ aA, aK @ np.abs(B), np.abs(C), np.abs(D)]
    tol = tolerance(*terms, rtol=rtol)
    tol_k = tolerance(K, rtol=rtol)
    margin = -float(np.linalg.eigvalsh(0.5 * (Q + Q.T))[-1])
    k_psd = bool(np.linalg.eigvalsh(0.5 * (K + K.T))[0] >= -tol_k and np.abs(K - K.T).max(initial=0.0) <= tol_k)
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


def is_passive(A, B, C, D, K=None) -> PassivityResult:
    """Whether ``Σ(A, B, C, D)`` is passive (the KYP LMIs ``e:lmis``); with ``K`` given, for the storage ``½xᵀKx``.

    ``K=None`` decides whether *some* ``K ⪰ 0`` solves ``Q(K) ⪯ 0`` by the SDP ``min tr K`` subject to
    ``Q(K) ⪯ 0, K ⪰ 0`` (optional ``sdp`` extra: cvxpy, clarabel) — no bound on ``K``, so no storage is
    excluded by a normalisation, and a non-strict LMI (no interior, e.g. ``K = 100`` the only solution)
    is decided too.  The solver's answer is never trusted: a ``K`` is accepted only if the eigenvalues of
    ``Q(K)`` and ``K`` pass at ``SDP_RTOL`` relative to the data (``passive=True``); "not passive" only
    with a Farkas certificate ``Z ⪰ 0``, ``L*(Z) ⪰ 0``, ``⟨Z, Q(0)⟩ > 0`` (``L(K) = Q(K) − Q(0)``) that
    passes the same eigenvalue checks (``passive=False``, ``certificate`` set).  Anything else is
    inconclusive and raises :class:`verimono.SolverFailure` with the solver's status — never a ``False``.
    The result is truthy iff passive.
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
    if "CLARABEL" not in cp.installed_solvers():
        raise MissingOptionalDependency("is_passive(K=None) needs the Clarabel SDP solver (optional extra 'sdp': "
                                        "pip install clarabel); pass K explicitly for the eigenvalue test")
    m = B.shape[1]
    Kv = cp.Variable((n, n), symmetric=True)
    Q = cp.bmat([[A.T @ Kv + Kv @ A, Kv @ B - C.T], [B.T @ Kv - C, -(D + D.T)]])
    lmi = 0.5 * (Q + Q.T) << 0
    prob = cp.Problem(cp.Minimize(cp.trace(Kv)), [Kv >> 0, lmi])
    try:
        prob.solve(solver="CLARABEL")
    except Exception as exc:  # the solver's own failure becomes a typed one, with its status
        raise SolverFailure(f"the KYP SDP (min tr K s.t. Q(K) ⪯ 0, K ⪰ 0) failed in Clarabel "
                            f"(status {prob.status}): {type(exc).__name__}: {exc}") from None
    status = prob.status
    method = f"SDP min tr K s.t. Q(K) ⪯ 0, K ⪰ 0 (cvxpy/Clarabel, status {status}), verified by eigenvalues"
    found = None
    if Kv.value is not None and np.all(np.isfinite(Kv.value)):
        found = _verdict(A, B, C, D, 0.5 * (Kv.value + Kv.value.T), method, SDP_RTOL)
        if found.passive:
            return found
    Z = lmi.dual_value
    if Z is not None and np.all(np.isfinite(Z)):
        cert = _farkas(A, B, C, D, np.array(Z, float, ndmin=2).reshape(n + m, n + m))
        if cert["verified"]:
            return _not_passive(A, B, C, D, cert, method)
    else:
        cert = None
    raise SolverFailure(
        f"passivity of Σ(A, B, C, D) is undecided: Clarabel status {status!r}; "
        + (f"the K it returned fails the eigenvalue check ({found.message}); " if found is not None else
           "no K returned; ")
        + (f"its infeasibility certificate fails verification ({cert['message']})" if cert is not None else
           "no infeasibility certificate"))


def _adjoint(A, B, Z) -> np.ndarray:
    """``L*(Z)`` for ``L(K) = [[AᵀK + KA, KB], [BᵀK, 0]]``: ``⟨Z, L(K)⟩ = ⟨L*(Z), K⟩`` (``K`` symmetric)."""
    n = A.shape[0]
    Z11, Z12 = Z[:n, :n], Z[:n, n:]
    S = A @ Z11 + Z11 @ A.T + B @ Z12.T + Z12 @ B.T
    return 0.5 * (S + S.T)


def _farkas(A, B, C, D, Z) -> dict:
    """Verify a Farkas certificate of infeasibility of ``e:lmis`` by eigenvalues.

    ``Z`` is projected onto the PSD cone and normalised to ``⟨Z, Q(0)⟩ = 1``.  For any ``K ⪰ 0`` with
    ``Q(K) ⪯ 0``: ``0 ≤ ⟨Z, −Q(K)⟩ = −1 − ⟨L*(Z), K⟩ ≤ −1 + δ tr K`` with ``δ = max(0, −λ_min(L*(Z)))``,
    so no storage has ``tr K < 1/δ`` (none at all when ``δ = 0``).  Verified when ``δ`` is within
    ``SDP_RTOL`` of the size of the terms ``L*(Z)`` is summed from.
    """
    Z = 0.5 * (Z + Z.T)
    ev, V = np.linalg.eigh(Z)
    Zp = (V * np.clip(ev, 0.0, None)) @ V.T
    g = float(np.sum(Zp * kyp_matrix(A, B, C, D, np.zeros((A.shape[0],) * 2))))
    if not np.isfinite(g) or g <= 0.0:
        return {"verified": False, "message": f"⟨Z, Q(0)⟩ = {g:.3g} is not positive"}
    Zp = Zp / g
    S = _adjoint(A, B, Zp)
    lam_min = float(np.linalg.eigvalsh(S)[0]) if S.size else 0.0
    delta = max(0.0, -lam_min)
    znorm = float(np.linalg.norm(Zp, 2))
    tol = tolerance(2.0 * (np.linalg.norm(A, 2) + np.linalg.norm(B, 2)) * znorm, rtol=SDP_RTOL)
    kappa = np.inf if delta == 0.0 else 1.0 / delta
    ok = delta <= tol
    return {"verified": ok, "Z": Zp, "delta": delta, "tol": tol, "trace_lower_bound": kappa,
            "message": f"Z ⪰ 0, ⟨Z, Q(0)⟩ = 1, λ_min(L*(Z)) = {lam_min:.3g} (tolerance {tol:.2g}): "
                       f"no K ⪰ 0 with tr K < {kappa:.3g} satisfies e:lmis"}


def _not_passive(A, B, C, D, cert, method) -> PassivityResult:
    """The result for a verified infeasibility certificate: no ``K`` (``K=None``, ``margin = −∞``)."""
    tol = cert["tol"]
    S = D + D.T
    D_psd = bool(np.linalg.eigvalsh(S)[0] >= -tolerance(S, rtol=SDP_RTOL)) if S.size else True
    msg = (f"not passive, certified: {cert['message']}; D + Dᵀ {'⪰ 0' if D_psd else 'is not ⪰ 0'}")
    return PassivityResult(False, None, float("-inf"), tol, D_psd, False, float("inf"), method, msg,
                           certificate=cert)


__all__ = ["is_passive", "PassivityResult", "kyp_matrix", "MissingOptionalDependency"]
