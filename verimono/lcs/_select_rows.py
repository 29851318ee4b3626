"""The selection over the multipliers of ``H(t, x)`` for a block of rows at once (issue 43 item 3, branch example6).

:meth:`verimono.lcs.system.LCSOperator._select` minimises ``½zᵀPz + c_iᵀz`` over ``SOL(q_i, M)`` one row at a time:
Lemke (or the unit-data memo) for a solution ``z̄``, a rank certificate of uniqueness, and otherwise the
selection QP over ``SOL = {z ≥ 0, Mz + q ≥ 0, (M + Mᵀ)(z − z̄) = 0, qᵀ(z − z̄) = 0}`` (CPS Thm 3.1.7, PSD ``M``)
through :func:`verimono.lcs._warm_qp.solve_qp_warm`.  On the edge of ``dom H(t,·)`` the multipliers are not
unique and most rows pay the QP (7,145 of the 8,681 selections of the paper's Example's sine unit at ci).

Here ``M`` (the box LCP's matrix, the same for every row) and ``P`` are fixed and only ``q_i``, ``c_i`` move, so:

* **faces enumerated once** (:func:`faces`): the minimiser ``z*`` over ``SOL`` minimises the QP over the affine
  set ``L = {z_j = 0 (j ∈ Z), (Mz + q)_j = 0 (j ∈ W)}`` of its active rows (``Z ∪ W`` every index, since
  ``z* ∈ SOL``: points of ``L`` near ``z*`` are in ``SOL``), so ``z*`` solves that face's KKT system
  ``[[P, Eᵀ], [E, 0]]``, a matrix of ``M`` and ``P`` alone.  Its pseudo-inverse is made once per face (``3^k``
  faces, each index in ``Z``, ``W`` or both) and every row's candidate is one product of a stack.
* **each row's candidate is accepted only by the per-row path's own checks**, in the same units:
  ``solve_lcp``'s residual check (``‖min(z, Mz + q)‖∞ ≤ QP_RTOL·(1 + max(|q|∞, ‖M‖∞|z|∞))`` on the data scaled
  as :func:`verimono.lcs.solve_lcp` scales them), so the candidate is a verified ``z̄`` and proves
  ``x_i ∈ dom H(t_i)``; then the selection QP's description of ``SOL`` built from that ``z̄`` exactly as
  :func:`verimono.lcs.lcp.sol_polyhedron` builds it, equilibrated as :func:`verimono.core.qp.equilibrate` does, and
  :func:`verimono.core.qp.kkt_residual` at ``QP_RTOL`` with the far half-spaces' check — ``solve_qp``'s own
  acceptance.  Among a row's candidates that pass the residual check the one of least objective is checked;
  a row whose candidate fails, a row with far half-spaces or a zero constraint row, a non-finite row, a row
  that :func:`verimono.lcs._warm_qp.row_infeasible` proves outside: the caller takes it as its own call.

``H^0 = −Ax − Bλ*`` is unique even where ``λ*`` is not, so the answers agree with the per-row path's to the
QP's verification tolerance (in practice to the last bits).
"""

from __future__ import annotations

import itertools

import numpy as np

from ..core.qp import FAR, kkt_residual
from ..core.tolerances import QP_RTOL, RTOL
from ._warm_qp import INFEASIBLE_MARGIN

#: entries of a :class:`Faces`' memory of KKT verdicts (forgotten all at once when full)
KKT_MEMO_SIZE = 4096

#: the largest LCP size (``m`` plus the box's finite upper bounds) whose ``3^k`` faces are enumerated
MAX_FACES_K = 5


def _kkt_ok(memo: dict, P, q, G, h, A, b, y) -> bool:
    """``kkt_residual(P, q, G, h, A, b, y).ok``, remembered in ``memo`` by its arrays' exact bytes (a function of
    them alone; ``P`` and ``G`` are the memo owner's, fixed); the memo is forgotten all at once when full."""
    key = (q.tobytes(), h.tobytes(), None if A is None else (A.shape, A.tobytes()),
           None if b is None else b.tobytes(), y.tobytes())
    hit = memo.get(key)
    if hit is None:
        hit = kkt_residual(P, q, G, h, A, b, y).ok
        if len(memo) >= KKT_MEMO_SIZE:
            memo.clear()
        memo[key] = hit
    return hit


class Faces:
    """What depends on ``(M, P)`` alone: the faces' KKT pseudo-inverses and ``sol_polyhedron``'s fixed rows."""

    def __init__(self, M: np.ndarray, P: np.ndarray) -> None:
        k = M.shape[0]
        self.M, self.P, self.k = M, P, k
        self.faces = []
        eye = np.eye(k)
        for labels in itertools.product((0, 1, 2), repeat=k):      # 0: z_j = 0, 1: w_j = 0, 2: both
            Z = [j for j in range(k) if labels[j] != 1]
            W = [j for j in range(k) if labels[j] != 0]
            E = np.vstack([eye[Z], M[W]])
            e = E.shape[0]
            K = np.zeros((k + e, k + e))
            K[:k, :k], K[:k, k:], K[k:, :k] = P, E.T, E
            self.faces.append((np.array(W, dtype=int), len(Z), np.linalg.pinv(K)[:k]))
        # sol_polyhedron's inequality rows G = [−I; −M] in unit-normal form (equilibrate's _unit_rows)
        G = np.vstack([-eye, -M])
        gn = np.sqrt(np.add.reduce(G * G, axis=1))
        self.G_zero = bool((gn == 0.0).any())
        self.G_unit = None if self.G_zero else G / gn[:, None]
        self.g_norms = gn
        self.sym = M + M.T
        self.m_max = float(np.abs(M).max(initial=0.0))
        self.beta = self.m_max or 1.0
        self.row_norm_unit = float(np.abs(M / self.beta).sum(axis=1).max(initial=0.0))
        self.nonpos = np.all(M <= 0.0, axis=1)
        self.p = float(np.abs(P).max(initial=0.0)) or 1.0
        self.kkt_memo: dict = {}        # kkt_residual's verdicts on the equilibrated selection QPs, by their bytes


def _candidates(F: Faces, Q: np.ndarray, Cc: np.ndarray, scales: np.ndarray):
    """Every face's candidate for every row; ``(Z, f, usable)``: per row the candidate of least objective among
    those that pass ``solve_lcp``'s residual check (a verified solution of ``LCP(q_i, M)``), its objective (``inf``
    when none passes), and whether the row may be decided here (finite, and not proved outside by
    :func:`verimono.lcs._warm_qp.row_infeasible`'s margin: such a row is its own call, which raises)."""
    B, k = Q.shape
    M, P = F.M, F.P
    Zbest = np.zeros((B, k))
    with np.errstate(all="ignore"):
        finite = np.isfinite(Q).all(axis=1) & np.isfinite(Cc).all(axis=1) & np.isfinite(scales)
        # row_infeasible's proof of x ∉ dom H: left to the row's own call, which raises OutsideDomain
        qmax = np.abs(Q).max(axis=1)
        tol = INFEASIBLE_MARGIN * (1.0 + qmax + F.m_max)
        outside = (F.nonpos[None, :] & (Q < -tol[:, None])).any(axis=1)
        # solve_lcp's units: q / s with s = max(|q|∞, scale), M / β
        s_lcp = np.maximum(qmax, scales)
        s_lcp = np.where(s_lcp > 0.0, s_lcp, 1.0)
        qu_max = np.abs(Q / s_lcp[:, None]).max(axis=1)
        best_f = np.full(B, np.inf)
        for W, nz, pinvk in F.faces:
            rhs = np.zeros((B, pinvk.shape[1]))
            rhs[:, :k] = -Cc
            rhs[:, k + nz:] = -Q[:, W]
            Zc = rhs @ pinvk.T
            Wc = Zc @ M.T + Q
            zu = Zc * (F.beta / s_lcp)[:, None]
            wu = Wc / s_lcp[:, None]
            res = np.abs(np.minimum(zu, wu)).max(axis=1)
            lscale = 1.0 + np.maximum(qu_max, F.row_norm_unit * np.abs(zu).max(axis=1))
            good = res <= QP_RTOL * lscale
            f = 0.5 * np.einsum("bi,ij,bj->b", Zc, P, Zc) + np.einsum("bi,bi->b", Cc, Zc)
            take = good & (f < best_f)
            if take.any():
                Zbest[take] = Zc[take]
                best_f[take] = f[take]
    return Zbest, best_f, finite & ~outside


def solvable_rows(F: Faces, Q: np.ndarray, scales: np.ndarray) -> np.ndarray:
    """Rows ``q_i`` for which some face's candidate is a solution of ``LCP(q_i, M)`` verified as
    :func:`verimono.lcs.lcp.proved_solvable` verifies Lemke's point (the same scaling, the same residual check):
    the proof that ``x_i ∈ dom H(t_i)`` which :meth:`LCSOperator._project_domain` makes row by row."""
    if F.G_zero or not len(Q):
        return np.zeros(len(Q), dtype=bool)
    _, f, usable = _candidates(F, Q, np.zeros(Q.shape), scales)
    return usable & np.isfinite(f)


def select_rows(F: Faces, Q: np.ndarray, Cc: np.ndarray, scales: np.ndarray):
    """Minimisers ``z_i`` of ``½zᵀPz + c_iᵀz`` over ``SOL(q_i, M)`` for the rows ``q_i`` of ``Q`` (``c_i`` of ``Cc``),
    ``scales`` the size of the numbers each ``q_i`` was computed from (``_select``'s ``scale``).  Returns
    ``(Z, ok)``: ``Z[i]`` is the accepted minimiser where ``ok[i]`` (see the module docstring), else undefined."""
    B, k = Q.shape
    P = F.P
    ok = np.zeros(B, dtype=bool)
    if F.G_zero or B == 0:
        return np.zeros((B, k)), ok
    Zbest, best_f, usable = _candidates(F, Q, Cc, scales)
    with np.errstate(all="ignore"):
        cand = usable & np.isfinite(best_f)
        idx = np.flatnonzero(cand)
        if not idx.size:
            return Zbest, ok
        Zs, Qs, Cs, sc = Zbest[idx], Q[idx], Cc[idx], scales[idx]
        # sol_polyhedron(M, q, z̄ = z, scale): A = _row_basis([M + Mᵀ; qᵀ], floors), b = A z̄
        n = k
        Eq = np.concatenate([np.broadcast_to(F.sym, (len(idx), n, n)), Qs[:, None, :]], axis=1)
        floors = np.concatenate([np.full((len(idx), n), F.m_max), sc[:, None]], axis=1)
        norms = np.maximum(np.sqrt(np.add.reduce(Eq * Eq, axis=2)), floors)
        Eq = Eq / np.where(norms > 0.0, norms, 1.0)[:, :, None]
        _, sv, Vt = np.linalg.svd(Eq, full_matrices=False)
        ranks = (sv > RTOL).sum(axis=1)
        # equilibrate(P, c, G, h, A, b, scale): the same units (h = [0; q] over G's row norms)
        Hu = np.concatenate([np.zeros((len(idx), n)), Qs], axis=1) / F.g_norms
        cmax = np.abs(Cs).max(axis=1) / F.p
    Pu = P / F.p
    for j, i in enumerate(idx.tolist()):
        r = int(ranks[j])
        z = Zs[j]
        if r:
            A = Vt[j, :r]
            b = A @ z
            an = np.sqrt(np.add.reduce(A * A, axis=1))
            A, b = A / an[:, None], b / an
            bmax = float(np.abs(b).max())
        else:
            A = b = None
            bmax = 0.0
        h = Hu[j]
        hmax = float(np.abs(h).max())
        floor = float(sc[j])
        core = max(bmax, float(cmax[j]), floor)
        if hmax > FAR * core:           # far half-spaces: equilibrate sets them aside; the row's own call
            continue
        s = max(core, hmax)
        if not (np.isfinite(s) and s > 0.0):
            s = 1.0
        q_s, h_s, b_s, y = Cs[j] / (F.p * s), h / s, None if b is None else b / s, z / s
        # kkt_residual is a function of its arrays alone: remembered by their exact bytes (the Example's rows on the
        # edge x = 0 are the same problem at every t once equilibrated: q/s = (±1, 0), y = (0, 1) or 0)
        ok[i] = _kkt_ok(F.kkt_memo, Pu, q_s, F.G_unit, h_s, A, b_s, y)
    return Zbest, ok




class ProjectionFaces:
    """The projection onto ``dom H(t,·)`` of a complementarity LCS (:meth:`LCSOperator._project_domain`'s QP):
    ``min ½|x' − x|²`` over ``(x', z)`` with ``z ≥ 0``, ``Cx' + Dz + v ≥ 0``, i.e. ``P = diag(I, 0)``,
    ``c = (−x, 0)``, ``G = [[0, −I], [−C, −D]]``, ``h = (0, v)``: ``G`` and ``P`` are the system's, so each of the
    ``2^{2m}`` active sets' KKT pseudo-inverse is made once, and every row's candidates are stack products."""

    def __init__(self, P: np.ndarray, G: np.ndarray) -> None:
        nv, r = P.shape[0], G.shape[0]
        self.P, self.G, self.nv = P, G, nv
        gn = np.sqrt(np.add.reduce(G * G, axis=1))
        self.G_zero = bool((gn == 0.0).any())
        self.g_norms = gn
        self.G_unit = None if self.G_zero else G / gn[:, None]
        self.kkt_memo: dict = {}        # kkt_residual's verdicts on the equilibrated projection QPs, by their bytes
        self.sets = []
        for mask in range(1 << r):
            act = np.array([i for i in range(r) if mask >> i & 1], dtype=int)
            e = act.size
            K = np.zeros((nv + e, nv + e))
            K[:nv, :nv] = P
            if e:
                K[:nv, nv:], K[nv:, :nv] = G[act].T, G[act]
            self.sets.append((act, np.linalg.pinv(K)))


def project_rows(F: ProjectionFaces, c: np.ndarray, h: np.ndarray):
    """Minimisers ``y_i`` of ``½yᵀPy + c_iᵀy`` over ``Gy ≤ h_i`` for the rows ``c_i``, ``h_i``; ``(Y, ok)``.  A row's
    candidate (the first active set, in order, whose KKT solution is feasible with nonnegative multipliers to
    ``QP_RTOL`` of the data) is accepted only by :func:`verimono.core.qp.kkt_residual` at ``QP_RTOL`` on the QP
    equilibrated as :func:`verimono.core.qp.equilibrate` does (``solve_qp``'s own acceptance); a row with a far
    half-space, a non-finite row or one no candidate reaches is left to its own call."""
    B, nv = c.shape
    ok = np.zeros(B, dtype=bool)
    Y = np.zeros((B, nv))
    if F.G_zero or B == 0:
        return Y, ok
    with np.errstate(all="ignore"):
        finite = np.isfinite(c).all(axis=1) & np.isfinite(h).all(axis=1)
        size = 1.0 + np.maximum(np.abs(c).max(axis=1), np.abs(h).max(axis=1))
        found = ~finite
        for act, pk in F.sets:
            rhs = np.concatenate([-c, h[:, act]], axis=1)
            sol = rhs @ pk.T
            y, mu = sol[:, :nv], sol[:, nv:]
            tol = QP_RTOL * size * (1.0 + np.abs(y).max(axis=1))
            good = ~found & ((y @ F.G.T - h).max(axis=1) <= tol)
            if act.size:
                good &= (mu.min(axis=1) >= -tol)
            if good.any():
                Y[good] = y[good]
                found |= good
        idx = np.flatnonzero(found & finite)
        hu = h[idx] / F.g_norms
        cmax = np.abs(c[idx]).max(axis=1) / (float(np.abs(F.P).max()) or 1.0)
    p = float(np.abs(F.P).max()) or 1.0
    Pu = F.P / p
    for j, i in enumerate(idx.tolist()):
        core = float(cmax[j])
        hmax = float(np.abs(hu[j]).max())
        if hmax > FAR * core:
            continue
        s = max(core, hmax)
        if not (np.isfinite(s) and s > 0.0):
            s = 1.0
        q_s, h_s, y = c[i] / (p * s), hu[j] / s, Y[i] / s
        ok[i] = _kkt_ok(F.kkt_memo, Pu, q_s, F.G_unit, h_s, None, None, y)
    return Y, ok


__all__ = ["Faces", "select_rows", "solvable_rows", "ProjectionFaces", "project_rows", "MAX_FACES_K"]
