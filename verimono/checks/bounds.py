"""The a-priori bounds of the convergence proof (Section 5): lemmas ``lem:bndSeq``, ``lem:bndSeqYB`` and
``lem:bndEquiCont``, with β, γ and ψ computed as the lemmas define them.

* ``bounds_lg`` — lemma ``lem:bndSeq`` under (A3) and (LG): ``|x_k| ≤ β`` and
  ``|x_k - x_{k-1}| ≤ ψ(t_k) - ψ(t_{k-1})`` with ``β, ψ`` of ``e:only beta``, ``eq:defPsi``; with an
  input ``u``, applied to ``ξ_k = x_k - Φ(t_k)`` through lemma ``l:extinput`` (``φ̄ = φ + ∫|u|``,
  ``σ̄ = σ (1 + ∫_0^T |u|)``).
* ``bounds_yb`` — lemma ``lem:bndSeqYB`` under (YB): ``β = |x0| + αT``, ``ψ(t) = αt``,
  ``α = 2(θ(T) - θ(0)) + |F^0(0, x0)|``.
* ``psi_interpolation`` — lemma ``lem:bndEquiCont``: the ψ-interpolant ``x_Δ`` of ``e:x delta`` obeys
  ``|x_Δ(τ̄) - x_Δ(τ)| ≤ ψ(τ̄) - ψ(τ)``.

The constants φ, σ, θ are the problem's (stated), else what the operator declares of itself (a domain that
does not move, a growth :meth:`verimono.Operator.growth`); a law whose constants are not known is skipped
before the stepper runs.  They bind the proximal scheme only: the lemmas bound its iterates.
"""

from __future__ import annotations

from typing import Any, Callable, Iterable

import numpy as np

from ..core.claims import claim_of, steps_tolerance
from ..core.errors import NotApplicable, OutsideDomain
from ..core.operators import Operator, provides
from ..core.problem import Problem
from ..core.stepping import Trajectory
from ..core.tolerances import tolerance
from .core import PROXIMAL_CLAIM, Holds, Outcome
from .partitions import run_stepper, single, stepper_law
from .shared_runs import fingerprint, remembered_value, run_serial
from .trajectory_laws import ROW_BLOCK, norms, step_norms


def _vals(fn: Callable, t: Iterable[float]) -> np.ndarray:
    return np.array([float(fn(float(s))) for s in t])


#: Gauss–Kronrod (7, 15) on [-1, 1] (QUADPACK's ``qk15``, the nodes and weights to 33 digits): the Kronrod rule
#: integrates polynomials of degree ≤ 22 exactly, the Gauss rule — its odd nodes — those of degree ≤ 13.  Read from
#: text, not written as float literals: hypothesis (≥ 6.131) draws among the numeric literals of the modules
#: imported so far, and the operator stage's generated families are drawn through its engine — 22 new literals
#: here changed two of those six operators (the same six with the literals as text)
_XK, _WK, _WG = (np.array(text.split(), dtype=float) for text in (
    "0.991455371120812639206854697526329 0.949107912342758524526189684047851 0.864864423359769072789712788640926 "
    "0.741531185599394439863864773280788 0.586087235467691130294144845693013 0.405845151377397166906606412076961 "
    "0.207784955007898467600689403773245 0",
    "0.022935322010529224963732008058970 0.063092092629978553290700663189204 0.104790010322250183839876322541518 "
    "0.140653259715525918745189590510238 0.169004726639267902826583426598550 0.190350578064785409913256402421014 "
    "0.204432940075298892414161999234649 0.209482141084727828012999174891714",
    "0.129484966168869693270611432679082 0.279705391489276667901467771423780 0.381830050505118944950369775488975 "
    "0.417959183673469387755102040816327"))
_NODES = np.concatenate([-_XK[:-1], _XK[::-1]])                    # the 15 nodes, increasing
_WEIGHTS_K = np.concatenate([_WK[:-1], _WK[::-1]])
_WEIGHTS_G = np.zeros(15)
_WEIGHTS_G[1::2] = np.concatenate([_WG[:-1], _WG[::-1]])           # the 7 Gauss nodes are the odd ones
#: a piece is accepted once its error estimate |K15 − G7| is below QUAD_RTOL of its integral or QUAD_ATOL of the
#: whole integral over all cells (the first pass's Σ|K15|, at least the smallest normal float): scaled so, |u| of any
#: magnitude is integrated alike (an absolute 1e-14 accepted a piece of a jump at scale 1e-300 on its first, blind
#: estimate: 1e-4 below the integral), and a piece that never settles (noise, a jump on every scale) stops once it
#: is that small a part of the whole; beyond QUAD_DEPTH bisections its estimate is kept, added like any other;
#: ROUNDING_ULPS ulps of Σ w|f| cover the sums' own rounding
QUAD_RTOL, QUAD_ATOL, ROUNDING_ULPS = (float(x) for x in "1e-11 1e-14 16 (rtol atol ulps)".split()[:3])
QUAD_DEPTH = 40
#: open pieces at most per cell: the bisection of an input whose estimate never settles (a jump on every scale)
#: stops there, each piece's estimate added, rather than doubling the pieces at every level
QUAD_PIECES = 256
#: the Lagrange weights that extrapolate the 15 nodes' values to the end x = 1 of [-1, 1] (reversed: to x = -1;
#: Σ|L| = 3.84, so the extrapolation's rounding stays a few ulps), and the gap 1 − x_max between an end and its
#: outermost node: a kink or a jump in that gap is seen by no node (K15 = G7 there), only by the end's value
_TO_END = np.array([np.prod([(1.0 - xk) / (xj - xk) for k, xk in enumerate(_NODES) if k != j])
                    for j, xj in enumerate(_NODES)])
_GAP = 1.0 - _NODES[-1]


def _cell_integrals(fn: Callable, t: np.ndarray) -> np.ndarray:
    """``∫_{t_k}^{t_{k+1}} fn`` on every cell, taken on the large side: the Kronrod value plus its error estimate.

    ``fn`` (``|u|``, ``σ``) is a scalar callable that may be non-smooth (``|u|`` has a kink where ``u``
    vanishes).  Every cell is integrated by the 15-point Gauss–Kronrod rule, all cells at once; a piece whose
    estimate ``|K15 − G7|`` exceeds ``QUAD_RTOL`` of its value is bisected, down to
    ``QUAD_DEPTH`` times.  ``|K15 − G7|`` bounds the Kronrod rule's error by a wide margin where ``fn`` is smooth
    on the piece (it is the Gauss rule's error, of a rule 9 degrees lower) and the bisection shrinks the piece
    holding a kink until it is; the sum ``K15 + |K15 − G7|`` (and a few ulps of ``Σ w|fn|`` for the sums'
    rounding; not the rounding of the nodes' own positions, ``ulp(t)·|fn'|``, a few ulps of a cell where ``fn`` starts
    from 0) is therefore an upper estimate of the integral — the
    side on which the laws' ψ and β, nondecreasing in ``∫|u|`` and ``∫σ``, can only grow, never fail a correct
    iterate through the quadrature (QUADPACK's own estimate, which ``scipy.integrate.quad`` returned beside a
    value it did not add, is this figure scaled down).  Not a proof for an arbitrary callable — no quadrature of
    finitely many values is — but it errs the lenient way by at most the estimate, below ``QUAD_RTOL`` relative."""
    t = np.asarray(t, dtype=float)
    n = len(t) - 1
    total = np.zeros(max(n, 0))
    if n <= 0:
        return total
    a, b, owner = t[:-1].copy(), t[1:].copy(), np.arange(n)
    for depth in range(QUAD_DEPTH + 1):
        half, mid = 0.5 * (b - a), 0.5 * (a + b)
        pts = np.concatenate([a[:, None], mid[:, None] + half[:, None] * _NODES[None, :], b[:, None]], axis=1)
        ends = np.array([float(fn(s)) for s in pts.ravel().tolist()]).reshape(pts.shape)
        vals = ends[:, 1:-1]
        with np.errstate(invalid="ignore", over="ignore"):
            kron = half * (vals @ _WEIGHTS_K)
            # the estimate, and the sums' own rounding (a few ulps of Σ w|f|): the sum stays on the large side of
            # it; and what the gaps at the ends can hold that no node sees: the gap's width times how far the end's
            # value is from the nodes' polynomial extrapolated there (≥ a jump's area in the gap, ≥ a kink's)
            err = (np.abs(kron - half * (vals @ _WEIGHTS_G)) + ROUNDING_ULPS * np.finfo(float).eps * half * (np.abs(vals) @ _WEIGHTS_K)
                   + _GAP * half * (np.abs(ends[:, -1] - vals @ _TO_END) + np.abs(ends[:, 0] - vals @ _TO_END[::-1])))
        # a sum past the largest float: the integral is +inf on the large side (inf − inf is no estimate)
        err[np.isnan(err) & ~np.isnan(ends).any(axis=1)] = np.inf
        if depth == 0:
            floor = QUAD_ATOL * max(float(np.sum(np.abs(kron))), float(np.finfo(float).tiny))
        done = ~(err > np.maximum(QUAD_RTOL * np.abs(kron), floor)) | (depth == QUAD_DEPTH) | (half <= 0)
        if 2 * np.count_nonzero(~done) > QUAD_PIECES * n:     # an input that never settles (noise): its estimates
            done[:] = True                                    # kept, the work linear in the cells
        np.add.at(total, owner[done], kron[done] + err[done])
        if done.all():
            break
        keep = ~done
        a, b, owner, mid = a[keep], b[keep], owner[keep], mid[keep]
        a, b, owner = np.concatenate([a, mid]), np.concatenate([mid, b]), np.concatenate([owner, owner])
    return total


def _integral(fn: Callable, a: float, b: float) -> float:
    """``∫_a^b fn`` on the large side (:func:`_cell_integrals` of one cell)."""
    return float(_cell_integrals(fn, np.array([a, b], dtype=float))[0])


def _cumulative(fn: Callable, t: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(_cell_integrals(fn, t))])


def _holds(*tests: Callable[[Problem], Any]) -> Holds:
    """A requirement met when every test passes on the (first row of the) problem; the reason is the
    :class:`NotApplicable` message of the first that does not."""
    def check(problem: Problem) -> str | None:
        p = single(problem)
        for test in tests:
            try:
                test(p)
            except NotApplicable as exc:
                return str(exc)
        return None
    return Holds(check)


def _either(*tests: Callable[[Problem], Any]) -> Holds:
    """Met when at least one test passes (ψ of lem:bndSeq *or* of lem:bndSeqYB)."""
    def check(problem: Problem) -> str | None:
        reasons = [_holds(t).test(problem) for t in tests]
        return None if any(r is None for r in reasons) else "no ψ available — " + "; ".join(reasons)
    return Holds(check)


def _phi_of(problem: Problem) -> tuple[Callable[[float], float], str]:
    """φ of (A3): the problem's, or ``φ ≡ 0`` when ``dom F(t,·)`` cannot move (static or all of R^n)."""
    if problem.phi is not None:
        return problem.phi, "stated"
    op = problem.operator
    if getattr(op, "full_domain", False) or getattr(op, "static", False):
        return (lambda t: 0.0), "derived: dom F(t) does not move"
    raise NotApplicable("the problem states no φ of (A3) and the domain of F may move")


def _sigma_of(problem: Problem) -> tuple[Callable[[float], float], str]:
    """σ of (LG): the problem's, or the growth the operator states of itself (:meth:`verimono.Operator.growth`:
    ``N_S`` has ``F^0 = 0``, ``Linear`` ``‖M(t)‖₂``, ``∂(c|·|)`` and ``∂(Σc_i|x_i|)`` ``|F^0(t, 1)|``)."""
    if problem.sigma is not None:
        return problem.sigma, "stated"
    op = problem.operator
    if provides(op, "growth"):
        if getattr(op, "static", False):
            # F(t,·) = F(0,·): its growth is one number, asked once (the bounds ask σ at every node of every
            # partition, and a growth may cost O(n): |F^0(t, (1, ..., 1))|, 750 evaluations at n = 10^6 in a battery)
            value = op.growth(0.0)
            return (lambda t: value), f"derived: the growth {op.name} states (static: at t = 0)"
        return op.growth, f"derived: the growth {op.name} states"
    raise NotApplicable("the problem states no σ of (LG)")


def _theta_of(problem: Problem) -> tuple[Callable[[float], float], str]:
    """θ of (YB): the problem's, or ``θ ≡ 0`` for a static operator (Prop. ``prop:maxmon-resolvent-Yosida``
    vi: ``|Y_λ x| ≤ |F^0(x)|``; the paper's remark after Theorem ``thm:main``)."""
    if problem.theta is not None:
        return problem.theta, "stated"
    if getattr(problem.operator, "static", False):
        return (lambda t: 0.0), "derived: static operator, theta constant"
    raise NotApplicable("the problem states no θ of (YB)")


class LGBounds:
    """β, γ and ψ of lemma ``lem:bndSeq`` (``e:only beta``, ``eq:defPsi``, ``e:alpha and r alpha``,
    ``e:gamma and r gamma``) for ``|x0|``, ``φ`` and ``σ`` on ``[0, T]``.

    With an input (lemma ``l:extinput``) pass ``absu = |u|``: then ``φ̄ = φ + ∫_0^t |u|`` and
    ``σ̄ = σ (1 + ∫_0^T |u|)`` are used.
    """

    def __init__(self, x0_norm: float, phi: Callable, sigma: Callable, T: float,
                 absu: Callable | None = None, grid: np.ndarray | None = None) -> None:
        self.phi0, self.sigma0, self.T, self.absu = phi, sigma, T, absu
        self.grid = None if grid is None else np.asarray(grid, dtype=float)
        if self.grid is not None:
            # the proof uses (LG) only at the nodes, |F^0(t_k, ξ)| ≤ σ(t_k)(1 + |ξ|): on this partition ∫σ
            # becomes the right Riemann sum Σ h_k σ(t_k) (exact for σ piecewise constant on the cells; the
            # paper reaches ∫σ only along specially chosen partitions, via Lakshmikantham–Leela 3.3.1)
            h = np.diff(self.grid)
            self._sigma_nodes = np.concatenate([[0.0], np.cumsum(h * _vals(sigma, self.grid[1:]))])
        self.u_total = 0.0 if absu is None else _integral(absu, 0.0, T)
        dphi = float(phi(T)) - float(phi(0.0))
        if dphi < -tolerance(phi(T), phi(0.0)):
            raise NotApplicable(f"φ must be nondecreasing; φ(T) - φ(0) = {dphi:.3g}")
        dphi += self.u_total
        int_sigma = (1.0 + self.u_total) * float(self._sigma_cumulative(np.array([0.0, T]))[-1])
        self.alpha = x0_norm + dphi
        self.beta = self.alpha + dphi + (1.0 + self.alpha) * int_sigma
        self.gamma = self.beta + dphi

    def _sigma_cumulative(self, pts: np.ndarray) -> np.ndarray:
        """``∫_0^s σ`` at the increasing ``pts`` (from 0), or its Riemann-sum version on the partition."""
        if self.grid is None:
            return _cumulative(self.sigma0, pts)
        return np.interp(pts, self.grid, self._sigma_nodes)

    def psi_nodes(self, t: np.ndarray) -> np.ndarray:
        """``ψ`` at the increasing points ``t`` (``t_0 = 0`` or not)."""
        t = np.asarray(t, dtype=float)
        pts = np.concatenate([[0.0], t]) if t[0] > 0 else t
        phi = _vals(self.phi0, pts)
        if self.absu is not None:
            phi = phi + _cumulative(self.absu, pts)
        out = pts + 2.0 * phi + (1.0 + self.gamma) * (1.0 + self.u_total) * self._sigma_cumulative(pts)
        return out[1:] if t[0] > 0 else out

    def psi_function(self, points: np.ndarray) -> Callable[[float], float]:
        """``ψ`` tabulated at ``points`` (exact there), for :meth:`Trajectory.interpolate`."""
        pts = np.unique(np.asarray(points, dtype=float))
        table = dict(zip(pts.tolist(), self.psi_nodes(pts).tolist()))
        return lambda s: table[float(s)] if float(s) in table else float(self.psi_nodes(np.array([s]))[-1])

    def constants(self) -> dict:
        return {"alpha": self.alpha, "beta": self.beta, "gamma": self.gamma}


class YBBounds:
    """β and ψ of lemma ``lem:bndSeqYB``: ``α = 2(θ(T) - θ(0)) + |F^0(0, x0)|``, ``β = |x0| + αT``,
    ``ψ(t) = αt`` (``eq:betaYB``, ``eq:defPsiYB``)."""

    def __init__(self, x0: np.ndarray, theta: Callable, op: Operator, T: float) -> None:
        try:
            with np.errstate(over="ignore"):     # an overflow is the inf handled below
                f0 = float(np.linalg.norm(op.min_norm(x0, 0.0)))
        except OutsideDomain:
            raise NotApplicable("x0 is not in dom F(0,·) (lem:bndSeqYB needs |F^0(0, x0)|)") from None
        if not np.isfinite(f0):   # x0 within rounding of the boundary: F^0 overflows (c/x at x = 7e-304)
            raise NotApplicable(f"|F^0(0, x0)| = {f0} is not finite: x0 is at the edge of dom F(0,·), where "
                        "lem:bndSeqYB's α is infinite and its bounds say nothing")
        self.alpha = 2.0 * (float(theta(T)) - float(theta(0.0))) + f0
        self.beta = float(np.linalg.norm(x0)) + self.alpha * T
        self.f0 = f0

    def psi_nodes(self, t: np.ndarray) -> np.ndarray:
        return self.alpha * np.asarray(t, dtype=float)

    def psi_function(self, points: np.ndarray) -> Callable[[float], float]:
        return lambda s: self.alpha * float(s)

    def constants(self) -> dict:
        return {"alpha": self.alpha, "beta": self.beta, "F0_at_x0": self.f0}


def _lg_requirements(p: Problem) -> None:
    """What lem:bndSeq assumes of the problem (raises :class:`NotApplicable` with the reason)."""
    if p.initial_jump:
        raise NotApplicable("x0 is outside cl dom F(0,·) (catching-up jump): lem:bndSeq assumes x0 in the closure")
    if p.f is not None:
        raise NotApplicable("the bounds of the Lipschitz-perturbation theorem involve a constant C_1 that is not "
                    "explicit; lem:bndSeq covers f = 0")
    _phi_of(p), _sigma_of(p)
    if p.u is None and p.U is not None:
        raise NotApplicable("an input given only by its primitive U: ∫|u| is not available")


def _yb_requirements(p: Problem) -> None:
    """What lem:bndSeqYB assumes of the problem (raises :class:`NotApplicable` with the reason)."""
    if p.initial_jump:
        raise NotApplicable("x0 is outside dom F(0,·) (catching-up jump): lem:bndSeqYB assumes x0 in dom F(0,·)")
    if p.f is not None:
        raise NotApplicable("lem:bndSeqYB covers f = 0 (the Lipschitz theorem's constants are not explicit)")
    if p.u is not None or p.U is not None:
        raise NotApplicable("with an input, lem:bndSeqYB would apply to G(t, ξ) = F(t, ξ + Φ(t)) (l:extinput), but (YB) "
                    "does not pass from F to G: t:non-auto's θ̄ = M_u + θ has the increments of θ (the constant "
                    "cancels) while the defect |Φ(s+λ) − Φ(s)|/λ ≈ |u(s)| stays as λ → 0 (F = ∂|x|, u = 1: G "
                    "fails (YB) for every θ)")
    _theta_of(p)


def _lg_setup(p: Problem, t: np.ndarray):
    """Bounds of lem:bndSeq and the sequence they bound (``ξ_k = x_k - Φ(t_k)`` with an input)."""
    _lg_requirements(p)
    (phi, phi_src), (sigma, sigma_src) = _phi_of(p), _sigma_of(p)
    shift = None           # no input: ξ = x (no trajectory-sized array of zeros subtracted)
    extra = {"phi": phi_src, "sigma": sigma_src}
    absu = None
    if p.u is not None or p.U is not None:
        # lemma l:extinput: ξ = x - Φ solves the scheme of G(t, ξ) = F(t, ξ + Φ(t)), which satisfies (A3)
        # with φ̄ = φ + ∫|u| and (LG) with σ (1 + |Φ|) ≤ σ (1 + ∫_0^T |u|)
        if p.u is None:
            raise NotApplicable("an input given only by its primitive U: ∫|u| is not available")
        shift = np.concatenate([np.zeros((1, p.dim)), np.cumsum(p.input_increments(t), axis=0)])
        absu = lambda s: float(np.linalg.norm(p.u(s)))  # noqa: E731
        extra["via"] = "l:extinput (xi_k = x_k - Phi(t_k))"
    return LGBounds(float(np.linalg.norm(p.x0)), phi, sigma, p.T, absu, grid=t), shift, extra


def _yb_setup(p: Problem, t: np.ndarray):
    _yb_requirements(p)
    theta, src = _theta_of(p)
    return YBBounds(p.x0, theta, p.operator, p.T), None, {"theta": src}


def _bounded(stepper: Callable, p: Problem, t: np.ndarray, setup: Callable, label: str, passed: str) -> Outcome:
    """``|ξ_k| ≤ β`` and ``|ξ_k - ξ_{k-1}| ≤ ψ(t_k) - ψ(t_{k-1})`` for the sequence ``ξ`` the lemma bounds
    (``ξ = x`` without an input, ``x - Φ`` with one), with the lemma's β and ψ from ``setup``."""
    bounds, shift, extra = setup(p, t)
    x = run_stepper(stepper, p, t)
    xi = x if shift is None else x - shift
    psi = bounds.psi_nodes(t)
    nx, steps = _norms_and_steps(xi, stepper, p, t, shift is None)
    dpsi = np.diff(psi)
    # an inexact resolvent (Inexact): x_k is within E_k = Σ_{j≤k} ε(h_j) of the exact scheme's iterate, which
    # the lemma bounds (nonexpansive steps, f = 0 here)
    E = np.concatenate([[0.0], np.cumsum(steps_tolerance(claim_of(stepper), np.diff(t)))])
    r_beta = nx / (bounds.beta + E + tolerance(bounds.beta, nx))
    r_step = steps / (dpsi + E[1:] + E[:-1] + tolerance(xi, psi))
    ratios = np.maximum(r_beta[1:], r_step)
    bad = np.flatnonzero(ratios > 1.0)
    k = int(bad[0]) + 1 if bad.size else int(np.argmax(ratios)) + 1
    which = "|x_k| <= beta" if r_beta[k] >= r_step[k - 1] else "|x_k - x_(k-1)| <= psi(t_k) - psi(t_(k-1))"
    counter = {"k": k, "t_k": t[k], "x_k": xi[k].copy(), "x_k_minus_1": xi[k - 1].copy(), "bound": which,
               "norm_x_k": nx[k], "step": steps[k - 1], "psi_increment": dpsi[k - 1], **bounds.constants(),
               **extra,
               "message": f"{label}: {which} fails at k = {k}, t_k = {t[k]:.6g}: |x_k| = {nx[k]:.6g}, "
                          f"beta = {bounds.beta:.6g}, |x_k - x_(k-1)| = {steps[k - 1]:.6g}, "
                          f"psi increment = {dpsi[k - 1]:.6g}"}
    details = {**bounds.constants(), **extra, "max_ratio_beta": float(np.max(r_beta)),
               "max_ratio_psi": float(np.max(r_step))}
    return Outcome(float(np.max(ratios)), k, counter, details, message=passed)


def _norms_and_steps(xi: np.ndarray, stepper: Callable, p: Problem, t: np.ndarray, own: bool):
    """``(|ξ_k|, |ξ_k − ξ_{k−1}|)``; of a kept run itself (``own``: no input shift), measured once for both lemmas'
    laws (:func:`verimono.checks.shared_runs.remembered_value`, keyed by the run's serial number)."""
    serial = run_serial(xi) if own else None
    if serial is None:
        return norms(xi), step_norms(xi)
    key = ("norms_and_steps", id(stepper), id(p), float(p.T), fingerprint(np.asarray(p.x0)), fingerprint(t), serial)
    return remembered_value(key, (stepper, p), lambda: (norms(xi), step_norms(xi)))


@stepper_law("bounds_lg", "lem:bndSeq", PROXIMAL_CLAIM, _holds(_lg_requirements), every_grid=True,
             study_grids=True)
def check_bounds_lg(stepper: Callable, p: Problem, t: np.ndarray, *, seed: int = 0) -> Outcome:
    """Lemma ``lem:bndSeq`` (under (A3), (LG)): ``|x_k| ≤ β``, ``|x_k - x_{k-1}| ≤ ψ(t_k) - ψ(t_{k-1})``.

    ``β = α + φ(T) - φ(0) + (1 + α)∫_0^T σ``, ``ψ(t) = t + 2φ(t) + (1 + γ)∫_0^t σ``, ``α = |x0| + φ(T) -
    φ(0)``, ``γ = β + φ(T) - φ(0)``.  For non-constant σ the lemma holds on fine enough partitions (the
    proof's piecewise-constant approximation); the default partitions have 40 cells.

    Claim: ``proximal`` — the lemma bounds the iterates of the paper's scheme on the given partition.
    """
    return _bounded(stepper, p, t, _lg_setup, "lem:bndSeq",
                    "|x_k| <= beta and |x_k - x_(k-1)| <= psi(t_k) - psi(t_(k-1)) (lem:bndSeq)")


@stepper_law("bounds_yb", "lem:bndSeqYB", PROXIMAL_CLAIM, _holds(_yb_requirements), every_grid=True,
             study_grids=True)
def check_bounds_yb(stepper: Callable, p: Problem, t: np.ndarray, *, seed: int = 0) -> Outcome:
    """Lemma ``lem:bndSeqYB`` (under (YB), ``|Δ| < Λ``): ``|x_k| ≤ |x0| + αT`` and
    ``|x_k - x_{k-1}| ≤ α h_k`` with ``α = 2(θ(T) - θ(0)) + |F^0(0, x0)|``.

    Claim: ``proximal`` — the lemma bounds the iterates of the paper's scheme on the given partition."""
    return _bounded(stepper, p, t, _yb_setup, "lem:bndSeqYB",
                    "|x_k| <= |x0| + alpha T and |x_k - x_(k-1)| <= alpha h_k (lem:bndSeqYB)")


# -- ψ-interpolation --------------------------------------------------------------------------------

#: up to this many times, every pair; beyond, consecutive times and every pair of a subsample (a stepper's own
#: partition at a tight tolerance: solve_adaptive's 20 003 nodes at tol = 1e-4 on t|x| gave 40 000 times, 8e8
#: pairs, and the process was killed for its memory)
ALL_PAIRS = 1500


#: at most this many coordinates of pair differences are formed at once, and the all-pairs subsample is cut so
#: that its pairs hold no more (each pair is a difference of two states of the problem's dimension: at n = 10^6
#: the 3 000 pairs of 80 times were 3e9 numbers, 24 GB, and the battery had no verdict after 120 s)
PAIR_ELEMENTS = 1 << 24


def _pairs(n: int, dim: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Index pairs ``i < j`` of ``n`` sorted times of states of dimension ``dim``: all of them up to
    :data:`ALL_PAIRS` times (fewer when their differences would hold more than :data:`PAIR_ELEMENTS`
    numbers); beyond, the consecutive ones — which bound the rest: with ``ψ`` nondecreasing, the triangle
    inequality gives ``|x(τ_j) − x(τ_i)| ≤ Σ_k |x(τ_{k+1}) − x(τ_k)| ≤ max_k r_k (ψ(τ_j) − ψ(τ_i))``, ``r_k``
    the consecutive ratios — and every pair of that many evenly spaced times (the ratios the tolerance shapes).
    The work per time is then linear in ``dim``."""
    dim = max(1, int(dim))
    m = int((1 + np.sqrt(1 + 8 * PAIR_ELEMENTS / dim)) / 2)      # m (m - 1) / 2 pairs of dim numbers each
    m = max(2, min(ALL_PAIRS, m))
    if n <= m:
        return np.triu_indices(n, 1)
    k = np.arange(n - 1)
    sub = np.unique(np.linspace(0, n - 1, m).round().astype(int))
    si, sj = np.triu_indices(len(sub), 1)
    return np.concatenate([k, sub[si]]), np.concatenate([k + 1, sub[sj]])


#: numbers of pair differences formed at once by :func:`_pair_norms`: a block that stays in the cache (blocks of
#: PAIR_ELEMENTS, 128 MiB each, made the differences memory-bound)
PAIR_BLOCK = 1 << 16


def _pair_norms(X: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """``|X[j] - X[i]|`` for every pair, at most :data:`PAIR_BLOCK` numbers (or one pair) formed at once."""
    X = X.reshape(len(X), -1)
    step = max(1, PAIR_BLOCK // max(1, X.shape[1]))
    return np.concatenate([norms(X[j[a:a + step]] - X[i[a:a + step]]) for a in range(0, len(i), step)] or
                          [np.zeros(0)])


def _psi_interpolant(t: np.ndarray, x: np.ndarray, tau: np.ndarray, psi: Callable) -> np.ndarray:
    """:meth:`verimono.Trajectory.interpolate` ``(tau, kind="psi", psi=psi)`` of the states ``x`` on ``t`` — the same
    numbers — into one array, the rows formed :data:`verimono.checks.trajectory_laws.ROW_BLOCK` numbers at a time
    (``interpolate`` forms four arrays of all the times' states: 1 GB each for 121 times at n = 10^6)."""
    if x.size <= ROW_BLOCK or x.ndim != 2:
        return Trajectory(t, x, None).interpolate(tau, kind="psi", psi=psi)
    tau = np.asarray(tau, dtype=float)
    Trajectory(t, x[:, :1], None).interpolate(tau, kind="psi", psi=psi)   # its checks of tau and psi, on one coordinate
    k = np.clip(np.searchsorted(t, tau, side="right") - 1, 0, len(t) - 2)
    ps = np.vectorize(lambda s: float(psi(s)))
    a, b, s = ps(t[k]), ps(t[k + 1]), ps(tau)
    w = (s - a) / (b - a)
    out = np.empty((len(tau), x.shape[1]))
    tmp = np.empty(x.shape[1])
    for r in range(len(tau)):
        # (1 - w) x_k + w x_{k+1}, as interpolate computes it
        np.multiply(1.0 - w[r], x[k[r]], out=out[r])
        np.multiply(w[r], x[k[r] + 1], out=tmp)
        out[r] += tmp
    return out


def _streamed_pairs(t: np.ndarray, x: np.ndarray, tau: np.ndarray, psi: Callable, i: np.ndarray, j: np.ndarray):
    """``(rows, lhs, xmax)`` of the ψ-interpolant at ``tau`` formed one time at a time (:func:`_psi_interpolant`'s
    arithmetic): ``lhs`` the norms ``|X[j] − X[i]|`` of the pairs (as :func:`_pair_norms` forms them when a row holds
    :data:`PAIR_BLOCK` numbers or more), ``xmax = |X|_∞``, ``rows`` a mapping ``index -> X[index]`` of the rows a
    non-consecutive pair reads (a few at large n, :func:`_pairs`) and of those :func:`check_psi_interpolation`'s
    counterexample may read.  ``xmax``: each row's ``|X_r|_∞`` (what ``tolerance`` reads of ``X``).  Memory: O(n) per
    kept row, not O(len(tau) n)."""
    T = len(tau)
    Trajectory(t, x[:, :1], None).interpolate(tau, kind="psi", psi=psi)   # its checks of tau and psi
    k = np.clip(np.searchsorted(t, tau, side="right") - 1, 0, len(t) - 2)
    ps = np.vectorize(lambda s: float(psi(s)))
    a, b, s = ps(t[k]), ps(t[k + 1]), ps(tau)
    w = (s - a) / (b - a)
    consecutive = j == i + 1
    keep = set(i[~consecutive].tolist()) | set(j[~consecutive].tolist())
    by_j: dict[int, list[int]] = {}
    for p in np.flatnonzero(consecutive):
        by_j.setdefault(int(j[p]), []).append(int(p))
    lhs = np.empty(len(i))
    rows: dict[int, np.ndarray] = {}
    xmax = np.empty(T)
    prev, row, tmp = None, np.empty(x.shape[1]), np.empty(x.shape[1])
    for r in range(T):
        np.multiply(1.0 - w[r], x[k[r]], out=row)
        np.multiply(w[r], x[k[r] + 1], out=tmp)
        row += tmp
        xmax[r] = max(row.max(), -row.min())         # |X_r|_∞ (a NaN stays a NaN)
        for p in by_j.get(r, ()):
            np.subtract(row, prev, out=tmp)
            lhs[p] = norms(tmp[None])[0]
        if r in keep:
            rows[r] = row.copy()
        prev, row = row, (prev if prev is not None else np.empty(x.shape[1]))
    for p in np.flatnonzero(~consecutive):
        lhs[p] = norms((rows[int(j[p])] - rows[int(i[p])])[None])[0]
    return _Rows(rows, t, x, k, w), lhs, xmax


class _Rows:
    """The rows of the ψ-interpolant by index: kept ones as they were formed, others formed again (the same
    arithmetic)."""

    def __init__(self, rows, t, x, k, w):
        self.rows, self.x, self.k, self.w = rows, x, k, w

    def __getitem__(self, r):
        r = int(r)
        if r not in self.rows:
            self.rows[r] = (1.0 - self.w[r]) * self.x[self.k[r]] + self.w[r] * self.x[self.k[r] + 1]
        return self.rows[r]


@stepper_law("psi_interpolation", "lem:bndEquiCont", PROXIMAL_CLAIM, _either(_lg_requirements, _yb_requirements))
def check_psi_interpolation(stepper: Callable, p: Problem, t: np.ndarray, *, seed: int = 0,
                            samples: int = 40) -> Outcome:
    """Lemma ``lem:bndEquiCont``: ``|x_Δ(τ̄) - x_Δ(τ)| ≤ ψ(τ̄) - ψ(τ)`` for the ψ-interpolant ``e:x delta``.

    ``ψ`` from lem:bndSeq and/or lem:bndSeqYB (whichever applies); ``x_Δ`` from
    :meth:`verimono.Trajectory.interpolate` with ``kind="psi"``; all pairs among the nodes, cell
    midpoints and ``samples`` random times (beyond :data:`ALL_PAIRS` times, or fewer in a large dimension, the
    consecutive pairs, which bound the others, and all pairs of a subsample: :func:`_pairs`).

    Claim: ``proximal`` — ``x_Δ`` interpolates the proximal iterates with the ψ of their lemmas.
    """
    setups = []
    reasons = []
    for label, setup in (("lem:bndSeq", _lg_setup), ("lem:bndSeqYB", _yb_setup)):
        try:
            setups.append((label,) + setup(p, t))
        except NotApplicable as exc:
            reasons.append(f"{label}: {exc}")
    setups = [s for s in setups if not (isinstance(s[1], YBBounds) and s[1].alpha <= 0.0)]
    if not setups:
        raise NotApplicable("no ψ available — " + "; ".join(reasons) if reasons else "ψ ≡ 0 (α = 0)")
    x = run_stepper(stepper, p, t)
    # an inexact resolvent: x_Δ within E_K = Σ ε(h_k) of the exact scheme's ψ-interpolant (a convex combination
    # of nodes each within E_K), so the differences within 2 E_K more (Inexact)
    slack = 2.0 * float(np.sum(steps_tolerance(claim_of(stepper), np.diff(t))))
    rng = np.random.default_rng(seed)
    tau = np.unique(np.concatenate([t, 0.5 * (t[:-1] + t[1:]), rng.uniform(0.0, p.T, samples)]))
    worst, best, det = -np.inf, None, {}
    for label, bounds, shift, extra in setups:
        psi = bounds.psi_function(np.union1d(t, tau))
        P = np.array([psi(s) for s in tau])
        i, j = _pairs(len(tau), int(np.prod(x.shape[1:])))
        xs = x if shift is None else x - shift
        if xs.ndim == 2 and xs.size > ROW_BLOCK:
            # the interpolant's rows one at a time: the pairs' norms and |X|_∞ as they come, the rows of the
            # non-consecutive pairs kept (the same numbers as below without the array of all the times' states)
            X, lhs, xmax = _streamed_pairs(t, xs, tau, psi, i, j)
        else:
            X = _psi_interpolant(t, xs, tau, psi)
            lhs = _pair_norms(X, i, j)
            xmax = X
        rhs = P[j] - P[i]
        ratio = lhs / (rhs + slack + tolerance(xmax, P))
        m = int(np.argmax(ratio))
        det[label] = float(ratio[m])
        if ratio[m] > worst:
            worst = float(ratio[m])
            k = int(np.searchsorted(t, tau[j[m]], side="left"))
            best = {"k": max(1, min(k, len(t) - 1)), "lemma": label, "tau_low": tau[i[m]],
                    "tau_high": tau[j[m]], "x_low": X[i[m]].copy(), "x_high": X[j[m]].copy(), "lhs": lhs[m],
                    "rhs": rhs[m],
                    **bounds.constants(),
                    "message": f"{label}/lem:bndEquiCont: |x_D(tau') - x_D(tau)| = {lhs[m]:.6g} > "
                               f"psi(tau') - psi(tau) = {rhs[m]:.6g} for tau = {tau[i[m]]:.6g}, "
                               f"tau' = {tau[j[m]]:.6g}"}
    return Outcome(worst, best["k"], best, {"worst_by_lemma": det, "pairs": len(i), "times": len(tau)},
                   message="|x_D(tau') - x_D(tau)| <= psi(tau') - psi(tau) (lem:bndEquiCont)")


__all__ = ["check_bounds_lg", "check_bounds_yb", "check_psi_interpolation", "LGBounds", "YBBounds"]
