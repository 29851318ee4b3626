"""Verified solutions of small convex quadratic programs.

``min ½ zᵀPz + qᵀz  s.t.  Gz ≤ h, Az = b`` with ``P ≻ 0`` is solved by the back-ends that qpsolvers
offers (ProxQP with tight tolerances and its duality-gap check on, then DAQP), but no back-end's status
is trusted: each candidate is polished by re-solving the equality-constrained problem on its detected
active set, and accepted only when verimono's own KKT check passes — primal feasibility, and a
nonnegative multiplier combination of the active rows reproducing ``-(Pz + q)`` (a nonnegative least
squares residual), both to ``QP_RTOL`` relative to the data.  When no candidate passes,
:class:`verimono.SolverFailure` is raised with every back-end's reason.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
from scipy.optimize import nnls

from .errors import InfeasibleStep, SolverFailure
from .tolerances import QP_RTOL

#: back-ends tried in order, with the options that make them accurate
BACKENDS: dict[str, dict] = {
    "proxqp": dict(eps_abs=1e-12, eps_rel=0.0, check_duality_gap=True, max_iter=10_000),
    "daqp": dict(),
}


@dataclasses.dataclass
class KKTReport:
    primal: float   # max constraint violation, relative
    dual: float     # stationarity residual of the best nonnegative multipliers, relative
    ok: bool


def kkt_residual(P, q, G, h, A, b, z, rtol: float = QP_RTOL) -> KKTReport:
    """Verify optimality of ``z`` for the strictly convex QP independently of any solver."""
    scale = 1.0 + max(np.abs(q).max(initial=0.0), np.abs(h).max(initial=0.0) if h is not None else 0.0,
                      np.abs(b).max(initial=0.0) if b is not None else 0.0, np.abs(P @ z).max(initial=0.0))
    viol = 0.0
    rows = []
    tol_act = 1e-7 * scale
    if G is not None and len(h):
        slack = G @ z - h
        viol = max(viol, float(np.max(slack, initial=0.0)))
        active = slack >= -tol_act
        rows.append(G[active])
    if A is not None and len(b):
        viol = max(viol, float(np.max(np.abs(A @ z - b), initial=0.0)))
        rows.extend([A, -A])  # free multipliers as differences of nonnegative ones
    grad = P @ z + q
    if rows:
        R = np.vstack(rows)
        _, res = nnls(R.T, -grad, maxiter=50 * max(R.shape))
    else:
        res = float(np.linalg.norm(grad))
    primal, dual = viol / scale, res / scale
    return KKTReport(primal, dual, primal <= rtol and dual <= rtol)


def _polish(P, q, G, h, A, b, z):
    """Re-solve the KKT system on the active set of ``z`` (exact when the active set is right)."""
    scale = 1.0 + np.abs(z).max(initial=0.0)
    blocks, rhs = [], []
    if G is not None and len(h):
        act = G @ z - h >= -1e-7 * scale
        blocks.append(G[act]); rhs.append(h[act])
    if A is not None and len(b):
        blocks.append(A); rhs.append(b)
    n = P.shape[0]
    if not blocks:
        return np.linalg.solve(P, -q)
    E, e = np.vstack(blocks), np.concatenate(rhs)
    m = E.shape[0]
    K = np.block([[P, E.T], [E, np.zeros((m, m))]])
    sol = np.linalg.lstsq(K, np.concatenate([-q, e]), rcond=None)[0]
    return sol[:n]


def solve_qp(P, q, G=None, h=None, A=None, b=None, *, backends=None) -> np.ndarray:
    """Solve the strictly convex QP and return a KKT-verified minimiser.

    Raises :class:`InfeasibleStep` when the constraints admit no point (every back-end reports
    infeasibility and none returns a point), :class:`SolverFailure` when candidates exist but none
    verifies.
    """
    import qpsolvers

    # writable copies: back-ends such as DAQP reject read-only buffers (constant parameters are read-only)
    P = np.array(P, float); q = np.array(q, float)
    G = None if G is None or len(G) == 0 else np.atleast_2d(np.array(G, float))
    h = None if G is None else np.atleast_1d(np.array(h, float))
    A = None if A is None or len(A) == 0 else np.atleast_2d(np.array(A, float))
    b = None if A is None else np.atleast_1d(np.array(b, float))
    reasons = []
    got_point = False
    for name in backends or BACKENDS:
        if name not in qpsolvers.available_solvers:
            reasons.append(f"{name}: not installed")
            continue
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                z = qpsolvers.solve_qp(P, q, G, h, A, b, solver=name, **BACKENDS.get(name, {}))
        except Exception as exc:  # a back-end's own failure is one reason among others
            reasons.append(f"{name}: raised {type(exc).__name__}: {exc}")
            continue
        if z is None or not np.all(np.isfinite(z)):
            reasons.append(f"{name}: returned no solution")
            continue
        got_point = True
        best_rep = None
        for cand in (_polish(P, q, G, h, A, b, z), z):
            rep = kkt_residual(P, q, G, h, A, b, cand)
            if rep.ok:
                return cand
            if best_rep is None or max(rep.primal, rep.dual) < max(best_rep.primal, best_rep.dual):
                best_rep = rep
        reasons.append(f"{name}: KKT check failed (primal {best_rep.primal:.2e}, dual {best_rep.dual:.2e})")
    if not got_point:
        raise InfeasibleStep("no back-end found a feasible point: " + "; ".join(reasons))
    raise SolverFailure("no QP back-end produced a verified solution: " + "; ".join(reasons))
