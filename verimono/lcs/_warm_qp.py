"""Active-set warm starts for the small QPs an :class:`~verimono.lcs.system.LCSOperator` solves again and again
(the projection onto ``dom H(t,·)``, the selection over the multipliers of ``H(t, x)``), and a cheap proof of
infeasibility of ``FEA(q, M)``.

:func:`verimono.core.qp.solve_qp` hands each QP to a back-end (ProxQP, ~1 ms through qpsolvers on these 2×2 to
4×4 problems), *polishes* its answer by re-solving the KKT system on the detected active set, and accepts that
polished point only when its own KKT check passes.  An assumption law evaluates the same operator at thousands
of neighbouring ``(t, x)`` whose QPs have the same few active sets: :func:`solve_qp_warm` first re-solves the KKT
system on the active sets that verified last (most recent first, :data:`WARM_SETS` of them) — the very
polishing step of ``solve_qp``, on the same equilibrated data — and returns the first candidate that passes the
same KKT check (and the far half-spaces' check), so what it returns carries the guarantee ``solve_qp``'s
answers carry, and it is bit for bit ``solve_qp``'s answer whenever the back-end's point has that active set.
Otherwise (no warm set, or none verifies) it calls ``solve_qp`` itself and remembers the active set of its
answer.  The memory belongs to the caller (one per operator and QP kind), so nothing is shared between
operators or between tests.
"""

from __future__ import annotations

import numpy as np

from ..core._linalg import absmax, lstsq_solution
from ..core.qp import ACTIVE_RTOL, equilibrate, kkt_residual, qp_arrays, solve_qp
from ..core.tolerances import QP_RTOL

#: active sets remembered per QP shape (most recent first)
WARM_SETS = 4


def _on_active(S, act: np.ndarray) -> np.ndarray:
    """``solve_qp``'s polishing step (``verimono.core.qp._polish``) with the active rows ``act`` given."""
    n = S.P.shape[0]
    blocks, rhs = [], []
    if S.G is not None:
        blocks.append(S.G[act]); rhs.append(S.h[act])
    if S.A is not None:
        blocks.append(S.A); rhs.append(S.b)
    if not blocks:
        return np.linalg.solve(S.P, -S.q)
    E, e = np.vstack(blocks), np.concatenate(rhs)
    m = E.shape[0]
    K = np.zeros((n + m, n + m))      # np.block([[P, Eᵀ], [E, 0]]), assembled directly
    K[:n, :n], K[:n, n:], K[n:, :n] = S.P, E.T, E
    return lstsq_solution(K, np.concatenate([-S.q, e]))[:n]


def _scaled_key(S) -> tuple | None:
    """The exact bytes of the equilibrated QP (None when it is too large to remember)."""
    arrays = (S.P, S.q, S.G, S.h, S.A, S.b, S.G_far, S.h_far)
    if sum(0 if a is None else a.size for a in arrays) > 512:
        return None
    return tuple(None if a is None else (a.shape, a.tobytes()) for a in arrays)


def _trial(S, act: np.ndarray, skey) -> tuple[np.ndarray | None, bool]:
    """``(y, verified)``: the KKT solve of the equilibrated ``S`` on the active rows ``act`` and whether it
    passes ``solve_qp``'s KKT check and the far half-spaces' — a function of ``(S, act)`` alone, remembered by
    their exact bytes (:data:`TRIAL_MEMO_SIZE` entries): the equilibrated QPs of an LCS operator repeat where
    the raw ones do not (the selection QP on the edge of the paper's Example's domain is the same problem at every
    ``t`` once scaled; 8,235 distinct among the 20,732 of its assumption checks at ci)."""
    key = None if skey is None else (skey, act.tobytes())
    hit = _TRIALS.get(key) if key is not None else None
    if hit is None:
        with np.errstate(all="ignore"):
            y = _on_active(S, act)
        if not np.all(np.isfinite(y)):
            hit = (None, False)
        else:
            rep = kkt_residual(S.P, S.q, S.G, S.h, S.A, S.b, y)
            hit = (y, bool(rep.ok and S.far_violation(y) <= QP_RTOL))
        if key is not None:
            if len(_TRIALS) >= TRIAL_MEMO_SIZE:
                _TRIALS.clear()
            _TRIALS[key] = hit
    return hit


#: entries of :func:`_trial`'s memory (forgotten all at once when full)
TRIAL_MEMO_SIZE = 4096
_TRIALS: dict[tuple, tuple] = {}


def solve_qp_warm(memory: dict, P, q, G=None, h=None, A=None, b=None, *, scale: float | None = None) -> np.ndarray:
    """:func:`verimono.core.qp.solve_qp` (same arguments, same verification), trying the active sets kept in
    ``memory`` first (see the module docstring)."""
    P, q, G, h, A, b = qp_arrays(P, q, G, h, A, b)
    S = equilibrate(P, q, G, h, A, b, scale)
    key = (P.shape[0], None if S.G is None else S.G.shape[0], None if S.A is None else S.A.shape[0],
           S.G_far is None)
    sets = memory.setdefault(key, [])
    skey = None
    for k, act in enumerate(sets):
        if skey is None:
            skey = _scaled_key(S)
        y, ok = _trial(S, act, skey)
        if ok:
            if k:
                sets.insert(0, sets.pop(k))
            return S.scale * y
    z = solve_qp(P, q, G, h, A, b, scale=scale)
    if S.G is not None:
        y = z / S.scale
        act = S.G @ y - S.h >= -ACTIVE_RTOL * (1.0 + np.abs(y).max(initial=0.0))
        if not any(np.array_equal(act, a) for a in sets):
            sets.insert(0, act)
            del sets[WARM_SETS:]
    return z


def row_infeasible(M: np.ndarray, q: np.ndarray) -> bool:
    """A proof, by one row, that ``FEA(q, M) = {z ≥ 0 : Mz + q ≥ 0}`` is empty, with a margin: some row ``i`` has
    ``M_i ≤ 0`` (every entry) and ``q_i < −MARGIN·(1 + |q|∞ + max|M|)``, so ``(Mz + q)_i ≤ q_i < 0`` for every
    ``z ≥ 0`` (the Farkas certificate ``y = e_i``).  The margin keeps the answer the one of the linear program of
    :func:`verimono.lcs.lcp._feasible` (HiGHS, feasibility tolerance 1e-7), which it spares: a row violated by
    less is left to that program.  ``False`` proves nothing."""
    key = (M.shape, M.tobytes()) if M.size <= 256 else None
    hit = _ROWS_OF.get(key) if key is not None else None
    if hit is None:     # what depends on M alone, once per M (the operator's D at every call)
        hit = (float(np.abs(M).max(initial=0.0)), np.all(M <= 0.0, axis=1))
        if key is not None:
            if len(_ROWS_OF) >= 64:
                _ROWS_OF.clear()
            _ROWS_OF[key] = hit
    m_max, nonpos = hit
    tol = INFEASIBLE_MARGIN * (1.0 + absmax(q) + m_max)
    return bool((nonpos & (q < -tol)).any())


_ROWS_OF: dict[tuple, tuple] = {}


#: how far (relative to the data) a row must be violated for :func:`row_infeasible` to decide without the LP
INFEASIBLE_MARGIN = 1e-5


__all__ = ["solve_qp_warm", "row_infeasible", "WARM_SETS", "INFEASIBLE_MARGIN"]
