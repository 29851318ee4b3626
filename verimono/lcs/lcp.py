"""Linear complementarity problems ``LCP(q, M)``: find ``z ≥ 0`` with ``w = Mz + q ≥ 0`` and ``⟨z, w⟩ = 0``.

The paper's one-step problem for complementarity systems (Section 7, ``e:lcp``).  For a positive
semidefinite (not necessarily symmetric) ``M`` Proposition ``p:lcp2`` gives: ``LCP(q, M)`` is solvable iff
it is feasible iff ``q ∈ Q_M^+``, and there is a unique **least-norm** solution ``z*(q)`` (item iv; Han,
Tiwari, Camlibel, Pang 2009).  It is computed in two phases:

1. *any* solution ``z̄`` — Lemke's complementary pivoting (exact, and for PSD ``M``, which is
   copositive-plus, ray termination proves infeasibility: Cottle–Pang–Stone (CPS) Thm 4.4.13), then the
   convex QP ``min ½zᵀ(M+Mᵀ)z + qᵀz`` over ``FEA(q, M)`` (value 0 exactly at solutions), and for
   non-PSD ``M`` enumeration of complementary pieces when ``n ≤ ENUM_MAX``;
2. the least-norm one: for PSD ``M`` (CPS Thm 3.1.7)

       SOL(q, M) = {z ≥ 0 : Mz + q ≥ 0, (M + Mᵀ)(z − z̄) = 0, qᵀ(z − z̄) = 0},

   a polyhedron, so ``z*`` is the projection of 0 onto it, a strictly convex QP (:func:`verimono.core.qp.solve_qp`).
   (Proof: for ``z ∈ SOL`` and ``d = z − z̄``, complementarity and feasibility give ``dᵀMd ≤ 0``, so
   ``(M+Mᵀ)d = 0``, hence ``zᵀMz = z̄ᵀMz̄`` and ``qᵀz = −zᵀMz = qᵀz̄``; conversely those equalities make
   ``zᵀ(Mz + q) = z̄ᵀ(Mz̄ + q) = 0``.)  The QP is skipped when ``SOL`` is provably a singleton: every
   other solution differs by ``d ∈ ker(M+Mᵀ)`` with ``d_i = 0`` where ``w̄_i > 0`` and ``(Md)_i = 0``
   where ``z̄_i > 0`` (the cross-complementarity ``zᵀw̄ = z̄ᵀw = 0``), so a trivial kernel of those rows
   certifies uniqueness.

No back-end's status is trusted: every candidate is checked by the natural residual
``‖min(z, Mz + q)‖∞`` (zero exactly at solutions) against ``QP_RTOL`` relative to the data, polished by
one principal pivot solve when already close (``POLISH_RTOL``), and the next back-end is tried otherwise.

Box-constrained counterpart (relay): :func:`solve_box` finds ``λ ∈ [l, u]`` with ``−(Mλ + q) ∈ N_[l,u](λ)``
through an equivalent LCP of size ``m + #{u < ∞}``, least-norm in ``λ``.
"""

from __future__ import annotations

import dataclasses
import itertools
from typing import Callable

import numpy as np

from ..core.errors import InfeasibleStep, InvalidProblem, UnverifiedSolution, VerimonoError
from ..core._linalg import absmax, eigvalsh_values, lstsq_solution, singular_values, svd_reduced
from ..core.qp import solve_qp
from ..core.tolerances import POLISH_RTOL, QP_RTOL, RTOL
from ..core._highs import linprog_highs

#: largest n for which complementary pieces are enumerated (2^n pieces)
ENUM_MAX = 12
#: PSD ``M`` up to this size are enumerated when Lemke and the phase-1 QP both fail (2^n pieces, on that path only)
PSD_ENUM_MAX = 6


@dataclasses.dataclass
class LCPResult:
    """A verified solution ``z`` of ``LCP(q, M)`` with ``w = Mz + q`` and how it was obtained.

    ``residual`` is ``‖min(z, w)‖∞`` and ``scale`` the data size it is measured against
    (``residual ≤ QP_RTOL·scale``).  ``least_norm`` is True when ``z`` is certified the least-norm solution
    (uniqueness certificate or least-norm QP); ``unique`` is True/False when decided, None otherwise.
    """

    z: np.ndarray
    w: np.ndarray
    residual: float
    scale: float
    backend: str
    psd: bool
    unique: bool | None
    least_norm: bool
    reasons: list[str] = dataclasses.field(default_factory=list)

    @property
    def relative_residual(self) -> float:
        return self.residual / self.scale


# --- validation and measures ---------------------------------------------------------------------------
def _validate(M, q) -> tuple[np.ndarray, np.ndarray]:
    try:
        M = np.array(M, dtype=float, ndmin=2)
        q = np.array(q, dtype=float).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise InvalidProblem(f"LCP data must be numeric: {exc}") from None
    if M.ndim != 2 or M.shape[0] != M.shape[1]:
        raise InvalidProblem(f"LCP matrix M must be square, got shape {M.shape}")
    if q.shape != (M.shape[0],):
        raise InvalidProblem(f"LCP vector q must have shape ({M.shape[0]},) to match M {M.shape}, got {q.shape}")
    if not (np.isfinite(M).all() and np.isfinite(q).all()):
        raise InvalidProblem("LCP data M and q must be finite")
    return M, q


def lcp_residual(M: np.ndarray, q: np.ndarray, z: np.ndarray) -> float:
    """Natural residual ``‖min(z, Mz + q)‖∞``: zero iff ``z ∈ SOL(q, M)``."""
    return absmax(np.minimum(z, M @ z + q))


def lcp_scale(M: np.ndarray, q: np.ndarray, z: np.ndarray | None = None) -> float:
    """Size of the data a residual is measured against: ``1 + max(|q|∞, ‖M‖∞|z|∞)``."""
    mz = 0.0 if z is None else float(_row_norm(M) * np.float64(absmax(z)))
    return 1.0 + max(absmax(q), mz)


#: ‖M‖∞ of small matrices by their bytes (:func:`lcp_scale` is asked about the same few at every call)
_ROW_NORMS: dict[tuple, np.float64] = {}


def _row_norm(M: np.ndarray) -> np.float64:
    """``np.abs(M).sum(axis=1).max(initial=0.0)`` (a NumPy float), made once per small ``M``."""
    key = (M.shape, M.dtype.str, M.tobytes()) if M.size <= 64 else None
    out = _ROW_NORMS.get(key) if key is not None else None
    if out is None:
        out = np.abs(M).sum(axis=1).max(initial=0.0)
        if key is not None:
            if len(_ROW_NORMS) >= 256:
                _ROW_NORMS.clear()
            _ROW_NORMS[key] = out
    return out


#: answers of :func:`is_psd` for small matrices, by their bytes: a system's one-step and multiplier problems
#: ask about the same few matrices at every step (bounded: emptied when it reaches this many)
_PSD_SEEN: dict[tuple, bool] = {}
_PSD_SEEN_MAX = 256


def is_psd(M: np.ndarray, rtol: float = RTOL) -> bool:
    """``M + Mᵀ ⪰ 0`` up to ``rtol`` relative to ``max |M|`` (``M`` need not be symmetric)."""
    if M.size == 0:
        return True
    key = (M.shape, M.dtype.str, M.tobytes(), rtol) if M.size <= 1024 else None
    seen = _PSD_SEEN.get(key) if key is not None else None
    if seen is not None:
        return seen
    answer = bool(eigvalsh_values(M + M.T)[0] >= -rtol * (1.0 + np.abs(M).max()))   # np.linalg.eigvalsh's
    if key is not None:
        if len(_PSD_SEEN) >= _PSD_SEEN_MAX:
            _PSD_SEEN.clear()
        _PSD_SEEN[key] = answer
    return answer


def _verified(M, q, z, scale=None) -> tuple[bool, float, float]:
    res = lcp_residual(M, q, z)
    s = lcp_scale(M, q, z) if scale is None else scale
    return res <= QP_RTOL * s, res, s


def principal_solve(M: np.ndarray, q: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """``z_α = −M_αα^{-1} q_α`` (least squares when singular), ``z = 0`` off ``α``: the active-set step."""
    z = np.zeros(q.shape[0])
    idx = np.flatnonzero(alpha)
    if idx.size:
        z[idx] = lstsq_solution(M[np.ix_(idx, idx)], -q[idx])     # np.linalg.lstsq's, bit for bit
    return z


def _polish(M, q, z):
    """One principal pivot solve on the support guessed from ``z`` (``z_i > w_i``)."""
    return principal_solve(M, q, z > M @ z + q)


# --- back-ends: each returns (candidate or None, status text) -----------------------------------------
def lemke(M: np.ndarray, q: np.ndarray, max_iter: int | None = None) -> tuple[np.ndarray | None, str]:
    """Lemke's complementary pivoting with covering vector ``d = 1`` and a lexicographic ratio test.

    Returns ``(z, "solved")`` or ``(None, "ray termination")`` / ``(None, "iteration limit")``.
    For copositive-plus (e.g. PSD) ``M`` ray termination proves ``LCP(q, M)`` infeasible (CPS Thm 4.4.13).
    """
    n = q.shape[0]
    if (q >= 0).all():
        return np.zeros(n), "solved"
    if n <= LEMKE_SMALL:
        out = _lemke_small(M, q, max_iter)
        if out is not None:
            return out
    T = np.hstack([np.eye(n), -M, -np.ones((n, 1)), q[:, None]])
    basis = np.arange(n)
    piv_tol = 1e-12 * max(1.0, float(np.abs(M).max(initial=0.0)))
    entering = 2 * n
    r = int(np.argmin(q))
    max_iter = max_iter or 1000 + 100 * n
    for _ in range(max_iter):
        T[r] /= T[r, entering]
        col = T[:, entering].copy()
        col[r] = 0.0
        T -= np.outer(col, T[r])
        leaving, basis[r] = basis[r], entering
        if leaving == 2 * n:
            break
        entering = leaving + n if leaving < n else leaving - n
        c = T[:, entering]
        cand = np.flatnonzero(c > piv_tol)
        if cand.size == 0:
            return None, "ray termination"
        # lexicographic minimum of (rhs, B^{-1}) rows scaled by the pivot column
        for j in [T.shape[1] - 1] + list(range(n)):
            ratios = T[cand, j] / c[cand]
            best = ratios.min()
            cand = cand[ratios <= best + 1e-12 * max(1.0, abs(best))]
            if cand.size == 1:
                break
        r = int(cand[0])
    else:
        return None, "iteration limit"
    z = np.zeros(n)
    for i, b in enumerate(basis):
        if n <= b < 2 * n:
            z[b - n] = max(T[i, -1], 0.0)
    return z, "solved"


#: :func:`lemke` pivots in Python floats up to this size (its NumPy form costs ~10 µs a pivot in call overhead)
LEMKE_SMALL = 6


def _lemke_small(M: np.ndarray, q: np.ndarray, max_iter: int | None):
    """:func:`lemke` in Python floats, operation for operation (each pivot row divided by its pivot, each row
    less its multiple of the pivot row — NumPy's ``outer`` then ``-=``, two roundings, as here — and the same
    lexicographic ratio test), so the same ``(z, status)`` bit for bit; ``None`` when a ratio is NaN (overflowed
    data) or a cut leaves no candidate, whose NumPy semantics (and errors) :func:`lemke` itself then follows."""
    n = q.shape[0]
    Ml, ql = M.tolist(), q.tolist()
    T = [[1.0 if j == i else 0.0 for j in range(n)] + [-v for v in Ml[i]] + [-1.0, ql[i]] for i in range(n)]
    width = 2 * n + 2
    basis = list(range(n))
    piv_tol = 1e-12 * max(1.0, float(np.abs(M).max(initial=0.0)))
    entering = 2 * n
    r = int(np.argmin(q))
    max_iter = max_iter or 1000 + 100 * n
    order = [width - 1] + list(range(n))
    for _ in range(max_iter):
        row = T[r]
        p = row[entering]
        row = T[r] = [v / p for v in row]
        for i in range(n):
            ci = T[i][entering] if i != r else 0.0
            Ti = T[i]
            T[i] = [Ti[j] - ci * row[j] for j in range(width)]
        leaving, basis[r] = basis[r], entering
        if leaving == 2 * n:
            break
        entering = leaving + n if leaving < n else leaving - n
        cand = [i for i in range(n) if T[i][entering] > piv_tol]
        if not cand:
            return None, "ray termination"
        for j in order:
            if not cand:        # a NaN cut emptied it (overflowed data): NumPy's own errors, from lemke
                return None
            ratios = [T[i][j] / T[i][entering] for i in cand]
            if any(x != x for x in ratios):
                return None
            best = min(ratios)
            cut = best + 1e-12 * max(1.0, abs(best))
            cand = [i for i, x in zip(cand, ratios) if x <= cut]
            if len(cand) == 1:
                break
        r = cand[0]
    else:
        return None, "iteration limit"
    z = np.zeros(n)
    for i, b in enumerate(basis):
        if n <= b < 2 * n:
            z[b - n] = max(T[i][-1], 0.0)
    return z, "solved"


def _qp_backend(M, q):
    """Phase-1 QP for PSD ``M``: ``min ½zᵀ(M+Mᵀ)z + qᵀz`` over ``FEA(q, M)`` (objective ``zᵀ(Mz + q) ≥ 0``).

    Like every back-end it receives the unit-scaled data of :func:`_solve_unit`, whose scale is 1 even
    when ``|q|∞ < 1`` (``solve_lcp``'s ``scale`` larger than ``|q|∞``): the QP is solved in those units."""
    n = q.shape[0]
    try:
        z = solve_qp(M + M.T, q, np.vstack([-np.eye(n), -M]), np.concatenate([np.zeros(n), q]), scale=1.0)
    except VerimonoError as exc:
        return None, f"{type(exc).__name__}: {exc}"
    return z, "solved"


def _pieces(n: int):
    for k in range(n + 1):
        for alpha in itertools.combinations(range(n), k):
            mask = np.zeros(n, bool)
            mask[list(alpha)] = True
            yield mask


def _piece_point(M, q, alpha, P=None, c=None):
    """Least ``½zᵀPz + cᵀz`` point of the piece ``{z_ᾱ = 0, z_α ≥ 0, w_α = 0, w_ᾱ ≥ 0}``, or None."""
    n = q.shape[0]
    idx = np.flatnonzero(alpha)
    Maa = M[np.ix_(idx, idx)]
    if idx.size == 0 or np.linalg.cond(Maa) < 1e12:
        z = principal_solve(M, q, alpha)
        ok, _, _ = _verified(M, q, z)
        return z if ok else None
    zp = principal_solve(M, q, alpha)  # w_α = 0 needs −q_α ∈ im M_αα: a cheap emptiness test
    if np.max(np.abs(M[alpha] @ zp + q[alpha])) > RTOL * lcp_scale(M, q, zp):
        return None
    Aeq = np.vstack([np.eye(n)[~alpha], M[alpha]])
    beq = np.concatenate([np.zeros(n - idx.size), -q[alpha]])
    G = np.vstack([-np.eye(n)[alpha], -M[~alpha]])
    h = np.concatenate([np.zeros(idx.size), q[~alpha]])
    try:
        z = solve_qp(np.eye(n) if P is None else P, np.zeros(n) if c is None else c, G, h, Aeq, beq, scale=1.0)
    except VerimonoError:
        return None
    ok, _, _ = _verified(M, q, z)
    return z if ok else None


def _enum_backend(M, q, least_norm=False):
    """Enumerate the ``2^n`` complementary pieces (``n ≤ ENUM_MAX``); exact for any ``M``."""
    n = q.shape[0]
    if n > ENUM_MAX:
        return None, f"n = {n} > ENUM_MAX = {ENUM_MAX}"
    best = None
    for alpha in _pieces(n):
        z = _piece_point(M, q, alpha)
        if z is not None:
            if not least_norm:
                return z, "solved"
            if best is None or z @ z < best @ best:
                best = z
    return (best, "solved") if best is not None else (None, "no piece contains a solution")


#: phase-1 back-ends by name (tests may replace one to check that a wrong status is caught)
BACKENDS: dict[str, Callable] = {"lemke": lemke, "qp": _qp_backend, "enumerate": _enum_backend}
PSD_BACKENDS = ("lemke", "qp")
GENERAL_BACKENDS = ("lemke", "enumerate")


# --- infeasibility -----------------------------------------------------------------------------------
def _feasible(M, q) -> bool:
    """Whether ``FEA(q, M) = {z ≥ 0, Mz + q ≥ 0}`` is nonempty (linear programming)."""
    n = q.shape[0]
    status, _, _ = linprog_highs(np.zeros(n), -M, q)     # linprog(method="highs")'s answer (z ≥ 0 by default)
    return status != 2


def proved_solvable(M, q, scale: float | None = None) -> bool:
    """A cheap proof that ``LCP(q, M)`` has a solution: Lemke's pivoting, on the data scaled as in
    :func:`solve_lcp`, returns a point that passes the residual check.  ``False`` proves nothing."""
    M, q = np.asarray(M, float), np.asarray(q, float)
    if np.all(q >= 0):
        return True
    s = max(float(np.abs(q).max()), 0.0 if scale is None else float(scale))
    beta = float(np.abs(M).max()) or 1.0
    z, _ = lemke(M / beta, q / s)
    return z is not None and bool(np.all(np.isfinite(z))) and _verified(M / beta, q / s, z)[0]


def _infeasibility_certificate(M, q) -> np.ndarray | None:
    """``ζ ∈ Q_M = {ζ ≥ 0, Mζ ≥ 0, (M+Mᵀ)ζ = 0}`` with ``qᵀζ < 0`` (so ``q ∉ Q_M^+``), for PSD ``M``."""
    n = q.shape[0]
    A_eq = np.vstack([M + M.T, np.ones((1, n))])
    b_eq = np.concatenate([np.zeros(n), [1.0]])
    status, fun, x = linprog_highs(q, -M, np.zeros(n), A_eq, b_eq)      # z ≥ 0 by default, as linprog's
    if status == 0 and fun < 0:
        return x
    return None


def _raise_infeasible(M, q, psd, reasons):
    """Raise :class:`InfeasibleStep` for the unit-scaled data of :func:`_solve_unit` (``|q|∞ = 1``)."""
    if psd:
        zeta = _infeasibility_certificate(M, q)
        cert = "" if zeta is None else (f"; certificate ζ = {np.array2string(zeta, precision=4)} ∈ Q_M "
                                        f"(normalised Σζ = 1) has ⟨q, ζ⟩/|q|∞ = {q @ zeta:.3g} < 0")
        raise InfeasibleStep(f"LCP(q, M) has no solution: q ∉ Q_M^+ (no z ≥ 0 with Mz + q ≥ 0; "
                             f"Proposition p:lcp2){cert}")
    raise InfeasibleStep("LCP(q, M) has no solution: " + "; ".join(reasons))


# --- least-norm / selection over SOL(q, M) for PSD M ------------------------------------------------------
def _row_basis(E: np.ndarray, floors: np.ndarray | None = None) -> np.ndarray:
    """Orthonormal basis (rows) of the row space of ``E``, rank decided at ``RTOL``.

    Each row is divided by ``max(|E_i|, floor_i)`` first: the rank is a property of the constraints, not
    of their units — the row ``qᵀ`` of :func:`sol_polyhedron` is as binding at ``|q| = 1e-9`` as at
    ``|q| = 1`` — unless the row is smaller than ``RTOL`` times the size ``floor_i`` of the numbers it
    was computed from, when it is rounding and drops out (``floors`` default to 0)."""
    if E.size == 0:
        return E
    norms = np.sqrt(np.add.reduce(E * E, axis=1))      # np.linalg.norm(E, axis=1), bit for bit
    if floors is not None:
        norms = np.maximum(norms, floors)
    E = E[norms > 0] / norms[norms > 0, None]
    if E.size == 0:
        return E
    _, s, Vt = svd_reduced(E)     # np.linalg.svd's, bit for bit
    r = int(np.sum(s > RTOL))     # rows of norm ≤ 1: singular values are absolute
    return Vt[:r]


def sol_polyhedron(M, q, zbar, scale: float | None = None):
    """``SOL(q, M)`` for PSD ``M`` as ``(G, h, A, b)``: ``Gz ≤ h``, ``Az = b`` (CPS Thm 3.1.7).

    Each equality row is judged against the size of the numbers it was computed from (:func:`_row_basis`):
    the rows of ``M + Mᵀ`` against ``max |M|`` (cancellation leaves ``ε max |M|`` where ``M + Mᵀ`` vanishes),
    ``qᵀ(z − z̄) = 0`` against ``scale`` (as in :func:`solve_lcp`; ``q`` is exact by default)."""
    n = q.shape[0]
    floors = np.concatenate([np.full(n, float(np.abs(M).max(initial=0.0))), [0.0 if scale is None else float(scale)]])
    A = _row_basis(np.vstack([M + M.T, q[None, :]]), floors)
    return np.vstack([-_eye(n), -M]), np.concatenate([np.zeros(n), q]), A, A @ zbar


def select_over_sol(M, q, zbar, P, c, scale: float | None = None) -> np.ndarray:
    """Minimise ``½zᵀPz + cᵀz`` over ``SOL(q, M)`` (PSD ``M``; ``z̄`` any solution), KKT-verified.

    ``scale``: the size of the numbers ``q`` was computed from (as in :func:`solve_lcp`), a floor for the
    units the QP is solved in (:func:`verimono.core.qp.equilibrate`)."""
    G, h, A, b = sol_polyhedron(M, q, zbar, scale)
    return solve_qp(P, c, G, h, A if len(A) else None, b if len(A) else None, scale=scale)


_EYES: dict[int, np.ndarray] = {}


def _eye(n: int) -> np.ndarray:
    """``np.eye(n)``, read-only and made once per ``n`` (indexed and stacked, never written)."""
    e = _EYES.get(n)
    if e is None:
        e = np.eye(n)
        e.flags.writeable = False
        if n <= 64:
            _EYES[n] = e
    return e


def unique_certificate(M, q, z, w, scale) -> bool:
    """True when ``SOL(q, M)`` is provably ``{z}`` (PSD ``M``): the rows ``M+Mᵀ``, ``e_i (w_i > 0)``,
    ``M_i (z_i > 0)`` have full column rank (see the module docstring)."""
    n = q.shape[0]
    tau = RTOL * scale
    rows = np.vstack([M + M.T, _eye(n)[w > tau], M[z > tau]])
    s = singular_values(rows)     # np.linalg.svd's, bit for bit
    return bool(s.size >= n and s[n - 1] > RTOL * max(s[0], 1.0))


# --- the public solver -----------------------------------------------------------------------------------
def solve_lcp(M, q, *, least_norm: bool = True, backends: tuple[str, ...] | None = None,
              info: bool = False, scale: float | None = None):
    """Solve ``LCP(q, M)``; return its least-norm solution ``z`` (or an :class:`LCPResult` with ``info``).

    For PSD ``M`` the least-norm solution of Proposition ``p:lcp2`` item iv is returned.  For other ``M``
    ``SOL(q, M)`` need not be convex; with ``least_norm`` and ``n ≤ ENUM_MAX`` the least-norm point over all
    complementary pieces is returned, otherwise a verified solution (``LCPResult.least_norm`` False) — as for PSD
    ``M`` when the least-norm QP over ``SOL(q, M)`` fails numerically although it holds a verified point (data
    spanning more decades than the QP solvers keep; the reason is in ``LCPResult.reasons``).

    The problem is homogeneous — ``z ∈ SOL(q, M)`` iff ``(β/s) z ∈ SOL(q/s, M/β)`` for ``s, β > 0`` — so it
    is solved with ``β = max |M|`` and ``s = max(|q|∞, scale)`` and scaled back: every tolerance, support
    and rank decision is relative to the size of the data.  ``scale`` is the size of the numbers ``q`` was
    computed from (its rounding errors are relative to them: ``q = Cx + v`` carries errors of order
    ``ε(‖C‖|x| + |v|)`` however small ``q`` is); the default, ``|q|∞``, treats ``q`` as exact, so that a
    one-step problem of size ``h`` or ``t`` is solved as accurately as one of size 1.

    Raises :class:`verimono.InfeasibleStep` when there is no solution (for PSD ``M``: ``q ∉ Q_M^+``, with a
    certificate ``ζ ∈ Q_M``, ``⟨q, ζ⟩ < 0``), :class:`verimono.UnverifiedSolution` when solutions exist but no
    back-end produced one that passes the residual check.
    """
    M, q = _validate(M, q)
    n = q.shape[0]
    if (q >= 0).all():  # z = 0 solves it and has the least norm
        res = LCPResult(np.zeros(n), q.copy(), 0.0, lcp_scale(M, q), "trivial (q ≥ 0)", is_psd(M), None, True)
        return res if info else res.z
    s = max(float(np.abs(q).max()), 0.0 if scale is None else float(scale))   # > 0: some q_i < 0
    beta = float(np.abs(M).max()) or 1.0
    unit = _solve_unit_memo(M / beta, q / s, least_norm, backends)
    z = unit.z * (s / beta)
    res = dataclasses.replace(unit, z=z, w=M @ z + q, residual=lcp_residual(M, q, z), scale=unit.scale * s)
    return res if info else z


#: entries of :func:`_solve_unit_memo`'s memory (forgotten all at once when full)
UNIT_MEMO_SIZE = 4096
_UNIT_MEMO: dict[tuple, LCPResult] = {}


def _solve_unit_memo(M, q, least_norm, backends) -> LCPResult:
    """:func:`_solve_unit`, remembered by the exact bytes of its unit-scaled data (and the back-end functions it
    would call): it is a function of them alone — pivoting, polishing, certificates, QPs and linear programs
    are deterministic — so a hit returns what the call would compute, bit for bit.  Scaling makes such data
    repeat where the raw data do not: the multipliers of the paper's Example on the edge ``x = 0`` of
    ``dom H(t,·)`` are ``LCP((−t, 0), D)`` at every ``t``, all ``LCP((−1, 0), D)`` once scaled (an assumption
    law asks thousands of such points: three in four of its unit solves are repeats).  Only answers are
    remembered, never failures, and a hit's arrays are copies."""
    names = backends or (PSD_BACKENDS if is_psd(M) else GENERAL_BACKENDS)
    key = (M.shape, M.tobytes(), q.tobytes(), bool(least_norm), tuple(names),
           tuple(BACKENDS.get(n) for n in names)) if M.size <= 256 else None
    hit = _UNIT_MEMO.get(key) if key is not None else None
    if hit is None:
        hit = _solve_unit(M, q, least_norm, backends)
        if key is not None:
            if len(_UNIT_MEMO) >= UNIT_MEMO_SIZE:
                _UNIT_MEMO.clear()
            _UNIT_MEMO[key] = hit
    return dataclasses.replace(hit, z=hit.z.copy(), w=hit.w.copy(),
                               reasons=None if hit.reasons is None else list(hit.reasons))


def _solve_unit(M, q, least_norm, backends) -> LCPResult:
    """:func:`solve_lcp` on data scaled to ``|q|∞ = 1``, ``max |M| = 1`` (``q`` not ``≥ 0``)."""
    n = q.shape[0]
    psd = is_psd(M)
    reasons: list[str] = []
    zbar, used, lemke_ray = None, None, False
    for name in backends or (PSD_BACKENDS if psd else GENERAL_BACKENDS):
        try:
            z, status = BACKENDS[name](M, q)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
            reasons.append(f"{name}: raised {type(exc).__name__}: {exc}")
            continue
        if z is None:
            reasons.append(f"{name}: {status}")
            lemke_ray |= name == "lemke" and status == "ray termination"
            continue
        z = np.asarray(z, dtype=float).reshape(-1)
        if z.shape != (n,) or not np.isfinite(z).all():
            reasons.append(f"{name}: returned a non-finite or misshapen point with status {status!r}")
            continue
        ok, res, scale = _verified(M, q, z)
        if not ok and res <= POLISH_RTOL * scale:
            zp = _polish(M, q, z)
            okp, resp, _ = _verified(M, q, zp)
            if okp:
                z, ok = zp, True
        elif ok:
            zp = _polish(M, q, z)
            if _verified(M, q, zp)[0] and lcp_residual(M, q, zp) < res:
                z = zp
        if ok:
            zbar, used = z, name
            break
        reasons.append(f"{name}: status {status!r} but residual ‖min(z, Mz+q)‖∞ = {res:.3g} "
                       f"> {QP_RTOL:g}·{scale:.3g}")
    if zbar is None and psd and n <= PSD_ENUM_MAX and backends is None:
        # Lemke's pivots and the phase-1 QP at their numerical limit on data spanning many decades (the paper's
        # Example at λ = 1e-15, x = −1e-9: M = [[0, 1], [−1, 1e-15]], z = (0, 1e6), Lemke ends on a ray): the
        # complementary pieces are exact for any M: each piece's principal solve, verified (ill-conditioned pieces
        # included — the Example at λ = 1e7 has cond M = 1e14 — the residual check is the arbiter)
        for alpha in _pieces(n):
            try:
                with np.errstate(all="ignore"):
                    z = principal_solve(M, q, alpha)
            except (np.linalg.LinAlgError, ValueError):
                continue
            if np.isfinite(z).all() and _verified(M, q, z)[0]:
                zbar, used = z, "enumerate"
                break
        else:
            reasons.append("enumerate: no piece's principal solve verified")
    if zbar is None:
        if not _feasible(M, q):
            _raise_infeasible(M, q, True if psd else False, reasons + ["FEA(q, M) is empty (linear programming)"])
        if psd:
            raise UnverifiedSolution("LCP(q, M) with PSD M is feasible, hence solvable (Proposition p:lcp2), but no "
                                "back-end produced a verified solution: " + "; ".join(reasons))
        if n <= ENUM_MAX and "enumerate" in (backends or GENERAL_BACKENDS):
            _raise_infeasible(M, q, False, reasons + [f"none of the 2^{n} complementary pieces holds a solution"])
        raise UnverifiedSolution("no back-end produced a verified solution of LCP(q, M) (non-PSD M, undecided): "
                            + "; ".join(reasons))
    w = M @ zbar + q
    scale = lcp_scale(M, q, zbar)
    unique, certified = None, False
    if psd:
        unique = unique_certificate(M, q, zbar, w, scale)
        certified = unique
    z = zbar
    if least_norm and not certified:
        if psd:
            try:
                zl = select_over_sol(M, q, zbar, np.eye(n), np.zeros(n), scale=1.0)
            except (InfeasibleStep, UnverifiedSolution) as exc:
                # SOL(q, M) holds z̄, so a QP that finds no point there is at its numerical limit, not the problem: data
                # spanning more decades than they keep (HiGHS drops matrix entries below 1e-9: the paper's
                # Example at λ = 3.6e-13 has M = [[0, 1], [-1, λ]] and z̄ = (0, 1.9e6)).  z̄ is kept, verified, not
                # certified the least-norm one (as for a non-PSD M): every solution gives the same state
                # W^{-1}(x + λBz) of a maximal monotone H, the least norm only chooses among multipliers
                reasons.append(f"least-norm QP over SOL(q, M): {exc} (z̄ kept)")
                return LCPResult(zbar, M @ zbar + q, lcp_residual(M, q, zbar), lcp_scale(M, q, zbar), used, psd,
                                 unique, False, reasons)
            ok, _, _ = _verified(M, q, zl)
            if not ok:
                zp = _polish(M, q, zl)
                ok, _, _ = _verified(M, q, zp)
                zl = zp if ok and abs(zp @ zp - zl @ zl) <= RTOL * (1 + zl @ zl) else zl
            if not ok:
                raise UnverifiedSolution("least-norm QP over SOL(q, M) returned a point that fails the LCP residual check")
            z, certified, used = zl, True, used + "+least-norm QP"
        elif n <= ENUM_MAX:
            zl, status = _enum_backend(M, q, least_norm=True)
            if zl is not None and zl @ zl <= z @ z:
                z = zl
            certified, used = zl is not None, used + "+enumeration"
    w = M @ z + q
    return LCPResult(z, w, lcp_residual(M, q, z), lcp_scale(M, q, z), used, psd, unique, certified, reasons)


# --- box-constrained counterpart (relay) --------------------------------------------------------------------
def _box_lcp(M, q, lower, upper):
    """The LCP of size ``m + f`` equivalent to the box problem: ``λ = l + z``, ``s = (−y)⁺`` on finite ``u``."""
    m = q.shape[0]
    fin = np.flatnonzero(np.isfinite(upper))
    if fin.size == 0:       # complementarity: the LCP itself (np.block's result, without its 0.3 ms)
        return np.array(M, dtype=float), M @ lower + q, fin
    E = np.eye(m)[:, fin]
    big = np.block([[M, E], [-E.T, np.zeros((fin.size, fin.size))]])
    qq = np.concatenate([M @ lower + q, (upper - lower)[fin]])
    return big, qq, fin


def box_residual(M, q, lam, lower, upper) -> float:
    """Natural residual ``‖λ − proj_[l,u](λ − (Mλ + q))‖∞``: zero iff ``−(Mλ+q) ∈ N_[l,u](λ)``."""
    y = M @ lam + q
    return float(np.max(np.abs(lam - np.clip(lam - y, lower, upper)), initial=0.0))


def solve_box(M, q, lower, upper, *, least_norm: bool = True, info: bool = False, scale: float | None = None):
    """Find ``λ ∈ [l, u]`` with ``−(Mλ + q) ∈ N_[l,u](λ)`` (the relay law ``λ ∈ −sgn(y)`` for ``[−1, 1]``).

    Solved as the equivalent LCP (``l`` finite, ``u`` may be ``+∞``); with ``least_norm`` and PSD ``M`` the
    least-norm ``λ`` over the (polyhedral) solution set.  Returns ``λ`` or an :class:`LCPResult` whose ``z``
    is ``λ`` and ``w`` is ``y = Mλ + q``.  ``scale`` as in :func:`solve_lcp`.
    """
    M, q = _validate(M, q)
    m = q.shape[0]
    lower = np.broadcast_to(np.asarray(lower, float), (m,)).copy()
    upper = np.broadcast_to(np.asarray(upper, float), (m,)).copy()
    if not np.all(np.isfinite(lower)) or np.any(np.isnan(upper)) or np.any(lower > upper):
        raise InvalidProblem(f"box bounds must satisfy -inf < lower <= upper <= inf, got lower={lower}, upper={upper}")
    big, qq, fin = _box_lcp(M, q, lower, upper)
    r = solve_lcp(big, qq, least_norm=False, info=True, scale=scale)
    lam = lower + r.z[:m]
    psd = is_psd(M)
    certified = r.unique is True
    if least_norm and psd and not certified:
        P = np.zeros((big.shape[0],) * 2)
        P[:m, :m] = np.eye(m)
        c = np.concatenate([lower, np.zeros(fin.size)])
        try:
            zz = select_over_sol(big, qq, r.z, P, c, scale=scale)
        except (InfeasibleStep, UnverifiedSolution):   # r.z solves it: the QP solvers' numerical limit (_solve_unit)
            zz = None                                   # r.z kept, verified, not certified the least-norm one
        if zz is not None:
            if not _verified(big, qq, zz)[0]:
                raise UnverifiedSolution("least-norm QP over the relay solution set failed the residual check")
            lam, certified = lower + zz[:m], True
    res_val = box_residual(M, q, lam, lower, upper)
    scale = lcp_scale(M, q, lam) + float(np.abs(lower).max(initial=0.0))
    if res_val > QP_RTOL * scale:
        raise UnverifiedSolution(f"box problem residual {res_val:.3g} exceeds {QP_RTOL:g}·{scale:.3g}")
    out = LCPResult(lam, M @ lam + q, res_val, scale, r.backend, psd, r.unique, certified, r.reasons)
    return out if info else lam


def lcp_alpha(M: np.ndarray) -> float | None:
    """The constant of Proposition ``p:lcp2`` v, ``|z*(q)| ≤ α|q|``, where it is explicit: ``α = 1/λ_min(S)``
    for a positive definite symmetric part ``S = (M + Mᵀ)/2`` — for *every* solution ``z`` of
    ``LCP(q, M)``, ``λ_min(S)|z|² ≤ zᵀMz = −zᵀq ≤ |z||q|`` (``zᵀ(Mz + q) = 0``).  ``None`` when ``S`` is
    singular (``λ_min(S) ≤ RTOL·(1 + max|M|)``): the proposition (Cottle–Pang–Stone Cor. 3.8.10) then
    asserts that some α exists without giving one."""
    M = np.asarray(M, dtype=float)
    if M.size == 0:
        return 0.0
    lam = float(np.linalg.eigvalsh(0.5 * (M + M.T))[0])
    return 1.0 / lam if lam > RTOL * (1.0 + float(np.abs(M).max())) else None


__all__ = ["solve_lcp", "solve_box", "LCPResult", "lcp_residual", "box_residual", "lemke", "is_psd", "lcp_alpha",
           "BACKENDS", "ENUM_MAX", "select_over_sol", "sol_polyhedron", "principal_solve"]
