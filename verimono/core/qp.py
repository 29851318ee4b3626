"""Verified solutions of small convex quadratic programs.

``min ½ zᵀPz + qᵀz  s.t.  Gz ≤ h, Az = b`` with ``P ⪰ 0`` is solved by the back-ends that qpsolvers
offers (ProxQP with tight tolerances and its duality-gap check on, then DAQP), but no back-end's status
is trusted: each candidate is polished by re-solving the equality-constrained problem on its detected
active set, and accepted only when verimono's own KKT check passes — primal feasibility, and a
nonnegative multiplier combination of the active rows reproducing ``-(Pz + q)`` (a nonnegative least
squares residual), both to ``QP_RTOL`` relative to the data.  When no candidate passes,
:class:`verimono.UnverifiedSolution` (a :class:`verimono.SolverFailure`) is raised with every back-end's reason.

The problem is equilibrated first (:func:`equilibrate`): constraint rows scaled to unit length, the
objective to ``max |P| = 1``, and the variable to ``z = s·y`` with ``s`` the size of the data
(``max(|h|∞, |b|∞, |q|∞/max|P|)``; a half-space more than ``1/ε`` beyond all nearer data is set aside,
:data:`FAR`, and checked on the answer).  None of this changes the minimiser, but it makes "relative to the
data" mean the same at every scale: the back-ends' absolute stopping floors and the KKT check's would
otherwise lose constraints of size 1e-9 (the one-step problems of a complementarity system near
``t = 0``), and ProxQP 0.8 does not return at all on a linear term 1e100 times its constraints (seen
on a membership query of the Section 7 Example).
"""

from __future__ import annotations

import dataclasses
import warnings
from typing import Any

import numpy as np

from ._highs import linprog_highs
from ._linalg import absmax, lstsq_solution
from .errors import InfeasibleStep, UnverifiedSolution
from .tolerances import QP_RTOL

_EMPTY = np.zeros(0)


def _nnls_routines():
    """``scipy.optimize.nnls`` and SciPy's own routine behind it (``None`` in another SciPy layout), imported on
    the first KKT check: ``scipy.optimize`` (its ``linprog`` pulls in ``scipy.fft``, ``special``, ``sparse``,
    ``spatial``: 0.3-0.5 s) is not imported with the checks, where most runs — a stepper's ``verimono check``
    on the ball or the box — solve no QP."""
    global _ROUTINES
    if _ROUTINES is None:
        from scipy.optimize import nnls
        try:    # SciPy's routine behind ``nnls`` (its wrapper's argument handling costs more than the solve)
            from scipy.optimize._slsqplib import nnls as routine
        except ImportError:     # pragma: no cover - another SciPy layout: the public function
            routine = None
        _ROUTINES = (nnls, routine)
    return _ROUTINES


_ROUTINES = None


def load_optimizers() -> None:
    """Import what a QP solve needs from SciPy now (``scipy.optimize``): the stages whose units use it import it
    before the workers fork (``verimono.run.stages``), to be inherited.  No law's time budget pays the import
    where it is not: the batteries that search under a budget (the operator, assumption, Section 7 and Hoffman
    laws) load ``scipy.optimize`` with their modules (the search engine's ``direct``); the stepper battery, which
    does not, solves its QPs (the paper's Example's a-priori bounds) under no search budget."""
    _nnls_routines()


def _nnls(A, b, maxiter):
    """``scipy.optimize.nnls(A, b, maxiter=maxiter)``: the same routine with the same arguments (``A`` C-ordered
    ``float64``, finite, ``b`` of matching length), without the wrapper's argument checks, which cost more than
    the solve on these small matrices; the same answer bit for bit, the same errors."""
    nnls, _nnls_routine = _nnls_routines()
    if _nnls_routine is None:
        return nnls(A, b, maxiter=maxiter)
    A = np.asarray_chkfinite(A, dtype=np.float64, order="C")
    b = np.asarray_chkfinite(b, dtype=np.float64)
    if A.ndim != 2 or b.ndim != 1 or A.shape[0] != b.shape[0]:
        return nnls(A, b, maxiter=maxiter)      # the wrapper's own errors
    x, rnorm, info = _nnls_routine(A, b, maxiter or 3 * A.shape[1])
    if info == 3:
        raise RuntimeError("Maximum number of iterations reached.")
    return x, rnorm

#: back-ends tried in order, with the options that make them accurate
BACKENDS: dict[str, dict] = {
    "proxqp": dict(eps_abs=1e-12, eps_rel=0.0, check_duality_gap=True, max_iter=10_000),
    "daqp": dict(),
}


#: rows whose slack is within this (relative) of zero are candidates for the active set of the KKT check;
#: complementary slackness then decides: a row with a multiplier must have (almost) no slack
ACTIVE_RTOL = 1e-7


@dataclasses.dataclass
class KKTReport:
    primal: float   # max constraint violation, relative
    dual: float     # stationarity residual of the best nonnegative multipliers, relative
    comp: float     # complementary slackness max_i μ_i |slack_i|, relative
    ok: bool


def kkt_residual(P, q, G, h, A, b, z, rtol: float = QP_RTOL) -> KKTReport:
    """Verify optimality of ``z`` for the convex QP independently of any solver.

    The KKT conditions: primal feasibility; stationarity ``Pz + q + Gᵀμ + Aᵀν = 0`` with ``μ ≥ 0`` on the
    rows within ``ACTIVE_RTOL`` of their bound (the best such ``μ`` by nonnegative least squares); and
    complementary slackness ``μ_i (h - Gz)_i = 0`` — without it a point at distance 1e-8 from a bound that
    the multipliers treat as active passes, while the optimum is on the bound (ProxQP returned such a
    point, 5e-7 off, for the projection onto the domain of the Example's H).  All three to ``rtol``
    relative to the data.
    """
    # the same arithmetic as np.max(..., initial=0.0) and np.linalg.norm, through the arrays' own methods: these
    # QPs have 2-6 variables, where NumPy's wrappers cost more than the reductions (same values, bit for bit)
    Pz = P @ z
    scale = 1.0 + max(absmax(q), absmax(h) if h is not None else 0.0, absmax(b) if b is not None else 0.0,
                      absmax(Pz))
    viol = 0.0
    rows, gaps = [], _EMPTY
    if G is not None and len(h):
        slack = G @ z - h
        viol = max(viol, float(slack.max(initial=0.0)))
        active = slack >= -ACTIVE_RTOL * scale
        rows.append(G[active])
        gaps = -slack[active]                    # ≥ 0 up to the violation, 0 on the bound
    if A is not None and len(b):
        viol = max(viol, absmax(A @ z - b))
        rows.extend([A, -A])  # free multipliers as differences of nonnegative ones
    grad = Pz + q
    R = (rows[0] if len(rows) == 1 else np.vstack(rows)) if rows else np.zeros((0, z.size))
    comp = 0.0
    if R.shape[0]:
        mu, res = _nnls(R.T, -grad, maxiter=50 * max(R.shape))
        if gaps.size:
            comp = float((mu[:gaps.size] * np.abs(gaps)).max(initial=0.0)) / (1.0 + float(mu.max(initial=0.0)))
    else:  # no active row (an interior minimiser): SciPy's nnls aborts the process on an empty matrix
        res = float(np.sqrt(grad.dot(grad)))     # np.linalg.norm(grad), bit for bit
    primal, dual, comp = viol / scale, res / scale, comp / scale
    return KKTReport(primal, dual, comp, primal <= rtol and dual <= rtol and comp <= rtol)


def _polish(P, q, G, h, A, b, z):
    """Re-solve the KKT system on the active set of ``z`` (exact when the active set is right)."""
    scale = 1.0 + np.abs(z).max(initial=0.0)
    blocks, rhs = [], []
    if G is not None and len(h):
        act = G @ z - h >= -ACTIVE_RTOL * scale
        blocks.append(G[act]); rhs.append(h[act])
    if A is not None and len(b):
        blocks.append(A); rhs.append(b)
    n = P.shape[0]
    if not blocks:
        return np.linalg.solve(P, -q)
    E, e = np.vstack(blocks), np.concatenate(rhs)
    m = E.shape[0]
    K = np.block([[P, E.T], [E, np.zeros((m, m))]])
    sol = lstsq_solution(K, np.concatenate([-q, e]))
    return sol[:n]


@dataclasses.dataclass
class ScaledQP:
    """``min ½yᵀPy + qᵀy  s.t. Gy ≤ h, Ay = b`` with ``z = scale·y`` the original problem's variable.

    ``G_far y ≤ h_far``: the far half-spaces (:data:`FAR`), left out of the solve and checked on its answer."""
    P: np.ndarray
    q: np.ndarray
    G: np.ndarray | None
    h: np.ndarray | None
    A: np.ndarray | None
    b: np.ndarray | None
    scale: float
    G_far: np.ndarray | None = None
    h_far: np.ndarray | None = None

    def far_violation(self, y: np.ndarray) -> float:
        """How far ``y`` violates a far half-space, relative to its offset (0 when it satisfies all)."""
        if self.G_far is None:
            return 0.0
        return float(np.max((self.G_far @ y - self.h_far) / self.h_far, initial=0.0))


def _unit_rows(E, e, kind, ref):
    """Rows of ``E`` scaled to unit length (with ``e``); zero rows dropped after checking ``0 ≤ e``
    (inequalities) or ``0 = e`` (equalities) up to ``QP_RTOL·ref`` (``ref`` the size of the data) — a zero
    row whose right-hand side has the wrong sign beyond rounding is an empty feasible set."""
    if E is None or E.shape[0] == 0:
        return None, None
    key = (E.shape, E.dtype.str, E.tobytes()) if E.size <= 256 else None
    hit = _UNIT_ROWS.get(key) if key is not None else None
    if hit is None:
        norms = np.sqrt(np.add.reduce(E * E, axis=1))     # np.linalg.norm(E, axis=1), bit for bit
        zero = norms == 0.0
        anyzero = bool(zero.any())
        hit = (norms, zero, anyzero, None if anyzero else E / norms[:, None])
        if key is not None:
            if len(_UNIT_ROWS) >= 256:
                _UNIT_ROWS.clear()
            _UNIT_ROWS[key] = hit
    norms, zero, anyzero, unit = hit
    if anyzero:
        slack = QP_RTOL * ref
        bad = e[zero] < -slack if kind == "<=" else np.abs(e[zero]) > slack
        if np.any(bad):
            raise InfeasibleStep(f"the QP has a zero constraint row with right-hand side "
                                 f"{e[zero][bad][0]:.3g} ({'0 <= h' if kind == '<=' else '0 = b'} fails)")
        E, e, norms = E[~zero], e[~zero], norms[~zero]
        if E.shape[0] == 0:
            return None, None
        return E / norms[:, None], e / norms
    return unit.copy(), e / norms


#: the unit rows of small constraint matrices by their bytes (:func:`_unit_rows`): a check's QPs share their
#: constraint matrices (the selection and projection QPs of an LCS operator), only their right-hand sides move
_UNIT_ROWS: dict[tuple, tuple] = {}


#: a half-space ``⟨g, z⟩ ≤ d`` (``|g| = 1``) is *far* when ``d`` exceeds ``FAR`` times the size of all the data
#: nearer to the origin: at that distance it contains every point the solve can represent in the data's units.
#: Kept in the solve it would set the units (``s = d``) and every other constraint would fall below their
#: resolution: the row ``1.4e-37 z₂ ≥ -1`` of an LCP whose matrix has a 1.4e-37 entry made ``s = 7e36`` and
#: turned a verified ``y = -1e-37`` into a multiplier ``z = -0.67`` (found by the Section 7 operator property).
#: Far rows are solved without and checked on the answer: a minimiser that satisfies them is the minimiser
#: with them (its feasible set only shrank around it); one that violates them is a ``UnverifiedSolution``.
FAR = 1.0 / float(np.finfo(float).eps)


def _far(h: np.ndarray, core: float) -> np.ndarray:
    """Mask of the far rows among unit-normal offsets ``h``: taken in increasing order, a row is far once its
    offset exceeds ``FAR`` times the largest of ``core`` and the offsets before it (so a far row never
    hides a nearer one, and rows at every scale below the data's stay)."""
    far = np.zeros(h.shape, dtype=bool)
    size = core
    if h.size and h.max() <= FAR * core:     # no row beyond FAR times the data (the usual case; NaN: the loop)
        return far
    order = np.argsort(h)
    for pos, i in enumerate(order):
        if h[i] > FAR * size:
            far[order[pos:]] = True
            break
        size = max(size, abs(float(h[i])))
    return far


def equilibrate(P, q, G, h, A, b, scale: float | None = None, set_aside_far: bool = True) -> ScaledQP:
    """The same QP in units where its data are of size 1 (same minimiser, up to ``z = s·y``).

    ``s = max(|h|∞, |b|∞, |q|∞/p, scale)`` after the rows are normalised and the far half-spaces (:data:`FAR`)
    set aside (unless ``set_aside_far=False``), with ``p = max |P|``: the size of the constraints' offsets and of the unconstrained minimiser.
    ``scale`` is a floor for ``s``: the size of the numbers the data were computed from, when their rounding
    errors are larger than the data (see :func:`verimono.lcs.solve_lcp`).  Substituting ``z = s·y`` and
    dividing the objective by ``p·s²``::

        min ½ yᵀ(P/p)y + (q/(p s))ᵀy   s.t.  (G/‖G_i‖)y ≤ h/(‖G_i‖ s),  (A/‖A_i‖)y = b/(‖A_i‖ s).
    """
    p = absmax(P) or 1.0
    floor = 0.0 if scale is None else float(scale)
    ref = max(absmax(h) if h is not None else 0.0, absmax(b) if b is not None else 0.0, absmax(q) / p, floor)
    G, h = _unit_rows(G, h, "<=", ref)
    A, b = _unit_rows(A, b, "=", ref)
    core = max(absmax(b) if b is not None else 0.0, absmax(q) / p, floor)
    G_far = h_far = None
    if G is not None and set_aside_far:
        far = _far(h, core)
        if np.any(far):
            G_far, h_far = G[far], h[far]
            G, h = (G[~far], h[~far]) if not np.all(far) else (None, None)
    s = max(core, absmax(h) if h is not None else 0.0)
    if not (np.isfinite(s) and s > 0.0):
        s = 1.0
    return ScaledQP(P / p, q / (p * s), G, None if h is None else h / s, A, None if b is None else b / s, s,
                    G_far, None if h_far is None else h_far / s)


def _badness(rep: KKTReport, S: ScaledQP, y: np.ndarray) -> float:
    """How far a candidate is from verified: its largest KKT residual, or its far-row violation."""
    return max(rep.primal, rep.dual, rep.comp, S.far_violation(y))


#: the packages of qpsolvers' back-ends that :data:`BACKENDS` does not name (qpsolvers imports every back-end it
#: finds when it is imported: JAX for jaxopt_osqp, Jinja2 for OSQP's code generation, ...)
UNUSED_BACKEND_PACKAGES = ("jax", "jaxopt", "qpax", "osqp", "scs", "highspy", "clarabel", "cvxopt", "kvxopt", "ecos",
                           "gurobipy", "mosek", "piqp", "qpalm", "qpoases", "qpSWIFT", "quadprog", "hpipm_python",
                           "coptpy", "pyqpmad", "sip_qp_python", "nppro", "pdhcg", "qtqp")


_PRIVATE: list = []


def _qpsolvers(full: bool = False) -> Any:
    """qpsolvers for verimono's own QPs, imported without the back-ends :data:`BACKENDS` never names
    (:data:`UNUSED_BACKEND_PACKAGES`): its package imports every back-end it finds, the jaxopt one importing JAX —
    0.4-1.9 s of CPU in every process that solves a QP (a worker of ``verimono check``), where qpsolvers with ProxQP
    and DAQP alone takes 0.07 s.  That import is verimono's **private copy**: it is taken out of ``sys.modules``
    again, so the user's code (a subject solving its own QPs with OSQP, say) that imports qpsolvers later gets the
    whole package with every back-end, as without verimono.  ``full`` (a back-end outside :data:`BACKENDS` asked for
    by name), or a process that imported qpsolvers before, gets the shared, whole package; a process that imported
    JAX (PyProximal does, through PyLops) still gets the private copy without jaxopt (0.66 s CPU and a
    DeprecationWarning spared), the back-ends it imported itself left as they are.  The hidden
    packages stay importable — except to another thread importing one of them during the 10 ms of this first
    import, which would see an ImportError."""
    import sys

    if full or "qpsolvers" in sys.modules:
        import qpsolvers

        return qpsolvers
    if _PRIVATE:
        return _PRIVATE[0]
    hidden = [m for m in UNUSED_BACKEND_PACKAGES if m not in sys.modules]
    before = set(sys.modules)
    for m in hidden:
        sys.modules[m] = None       # an ImportError for those back-ends, which qpsolvers skips
    try:
        import qpsolvers
    finally:
        for m in hidden:
            if m in sys.modules and sys.modules[m] is None:
                del sys.modules[m]
    # the partial package stays verimono's: the next ``import qpsolvers`` (the user's) imports the whole one
    for m in [m for m in sys.modules if (m == "qpsolvers" or m.startswith("qpsolvers.")) and m not in before]:
        del sys.modules[m]
    _PRIVATE.append(qpsolvers)
    return qpsolvers


def _attempt(name: str, S: ScaledQP) -> tuple[np.ndarray | None, str, bool]:
    """One back-end on the equilibrated ``S``: ``(verified minimiser or None, reason, whether it returned a
    point)``."""
    qpsolvers = _qpsolvers(full=name not in BACKENDS)
    if name not in qpsolvers.available_solvers:
        return None, f"{name}: not installed", False
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            y = qpsolvers.solve_qp(S.P, S.q, S.G, S.h, S.A, S.b, solver=name, **BACKENDS.get(name, {}))
    except Exception as exc:  # a back-end's own failure is one reason among others
        return None, f"{name}: raised {type(exc).__name__}: {exc}", False
    if y is None or not np.all(np.isfinite(y)):
        return None, f"{name}: returned no solution", False
    best = None
    for cand in (_polish(S.P, S.q, S.G, S.h, S.A, S.b, y), y):
        rep = kkt_residual(S.P, S.q, S.G, S.h, S.A, S.b, cand)
        if rep.ok and S.far_violation(cand) <= QP_RTOL:
            return S.scale * cand, "", True
        if best is None or _badness(rep, S, cand) < _badness(best[0], S, best[1]):
            best = (rep, cand)
    rep, cand = best
    if rep.ok:
        return None, (f"{name}: its minimiser without the far half-spaces violates one by "
                      f"{S.far_violation(cand):.2e} of its offset"), True
    return None, (f"{name}: KKT check failed (primal {rep.primal:.2e}, dual {rep.dual:.2e}, "
                  f"complementarity {rep.comp:.2e})"), True


def qp_arrays(P, q, G=None, h=None, A=None, b=None) -> tuple:
    """``(P, q, G, h, A, b)`` as :func:`solve_qp` takes them: writable float copies (back-ends such as DAQP reject
    read-only buffers, and constant parameters are read-only), ``G, h`` and ``A, b`` ``None`` when empty."""
    P = np.array(P, float); q = np.array(q, float)
    G = None if G is None or len(G) == 0 else np.atleast_2d(np.array(G, float))
    h = None if G is None else np.atleast_1d(np.array(h, float))
    A = None if A is None or len(A) == 0 else np.atleast_2d(np.array(A, float))
    b = None if A is None else np.atleast_1d(np.array(b, float))
    return P, q, G, h, A, b


def solve_qp(P, q, G=None, h=None, A=None, b=None, *, backends=None, scale: float | None = None) -> np.ndarray:
    """Solve the convex QP (``P ⪰ 0``, unique minimiser) and return a KKT-verified minimiser.

    The data are equilibrated first (:func:`equilibrate`; ``scale`` as there) and the KKT check is made in
    those units, i.e. relative to the size of the data at every scale.

    Raises :class:`InfeasibleStep` when the constraints admit no point (no back-end returns one, and HiGHS'
    phase one certifies infeasibility), :class:`UnverifiedSolution` when candidates exist but none verifies,
    or when no back-end returned a point but infeasibility is not certified (a limit of verimono's solvers).
    """
    P, q, G, h, A, b = qp_arrays(P, q, G, h, A, b)
    S = equilibrate(P, q, G, h, A, b, scale)
    attempts = [("", S)]
    if S.G_far is not None:   # far rows set aside first; with them in the solve (their units) if that fails
        attempts.append(("with the far half-spaces: ", equilibrate(P, q, G, h, A, b, scale, set_aside_far=False)))
    reasons = []
    got_point = False
    for label, S in attempts:
        for name in backends or BACKENDS:
            z, reason, point = _attempt(name, S)
            got_point = got_point or point
            if z is not None:
                return z
            reasons.append(label + reason)
    if not got_point:
        E = attempts[-1][1]            # every row, in unit-normal form: HiGHS' tolerances apply at any scale
        if _feasible(E.G, E.h, E.A, E.b, P.shape[0]) is False:
            raise InfeasibleStep("the constraints admit no point (HiGHS' LP certifies it; the back-ends: "
                                 + "; ".join(reasons) + ")")
        # a back-end that returns nothing has not shown infeasibility: without HiGHS' certificate of it, the
        # failure is verimono's own solvers' (a limit of the harness, never charged to the subject)
        raise UnverifiedSolution("no back-end returned a point although the constraints are not shown infeasible: "
                                 + "; ".join(reasons))
    raise UnverifiedSolution("no QP back-end produced a verified solution: " + "; ".join(reasons))


def _feasible(G, h, A, b, n: int) -> bool | None:
    """Whether ``{y : Gy ≤ h, Ay = b}`` has a point, by HiGHS' phase one (``scipy.optimize.linprog`` with a zero
    objective): ``False`` only on its certificate of infeasibility (status 2), ``True`` when it found a point,
    ``None`` when it could not tell.  Asked through :func:`verimono.core._highs.linprog_highs`, ``linprog``'s
    model, options and status without its wrapper (2.5-3 ms of Python a call, a third of the Siconos LCP files'
    unit: 128 calls there)."""
    try:
        status, _, _ = linprog_highs(np.zeros(n), np.zeros((0, n)) if G is None else G,
                                     np.zeros(0) if h is None else h, A, b,
                                     np.full(n, -np.inf), np.full(n, np.inf))
    except Exception:       # noqa: BLE001 - no certificate either way
        return None
    return False if status == 2 else (True if status == 0 else None)
