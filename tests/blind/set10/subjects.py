"""Blind set 10: planted violations of the paper's laws, and lawful controls, of kinds new against sets 1, 7, 8 and 9.

Written without reading ``verimono/checks/`` nor ``verimono/core/tolerances.py``: from the paper, README.md,
docs/checks.md, docs/paper.md, docs/precision.md and the public API.  Of the earlier blind sets only the names and
one-line bugs of their entries were read.  A third of the entries are operators (resolvents and proxes), a third
time-steppers, a third the other public subjects: problems with stated constants (``vm.Problem(..., lipschitz=,
phi=, exact=)``), LCPs and passive linear systems (``vm.lcs.LinearRelationSystem``), moving sets (a user's
``vm.sets.ConvexSet`` under ``vm.NormalCone``), each through the public entry points a user calls for it
(``check_operator``, ``check_stepper``, ``check_assumptions``, ``lcs.check_hypotheses``).

The kinds: bugs that need two quantifiers at once (a step off only for ``λ > 5`` *and* ``|x| > 50``), that depend
on the input's memory flags (read-only arrays take another path), on the call count (a "compiled" kernel after 256
warm-up calls), on randomness seeded per call (Dykstra with a random order and a fixed sweep count), on a batch's
size (``B ≥ 64`` in float32), on the grid (a cell ratio above 10, a near-uniform grid snapped, ``K > 5000``,
cells below ``10^-3``, ``n = K + 1``), on the problem's constants (``h·L > 1/2``), on the input (a jump in ``u``
the stated primitive ``U`` resolves), wrong by a relative ``10^-7`` (a bias, ``f`` on a float32 copy, an exact
solution), an operator monotone but not maximal (a projection whose range misses a band), a cancellation at
``x → -∞`` (the log barrier's prox), a smoothing ε in a norm, a stepper converging at order 1/2 claiming 1, an
LCP enumerator rejecting degenerate patterns, a passive system's resistor regularised below zero, an input table
held piecewise constant, a moving set whose projection lags by one call, a polygon projected face by face, an
ellipse projected with 20 bisection steps.

Each :class:`Entry` has ``build()`` (the subject as a user hands it over), the paper's law it breaks (``label``),
the smallest input showing it (``smallest``), what the bug is (``bug``), for a control the plant it is the lawful
twin of (``twin``), ``witness()`` (the law in plain NumPy at ``smallest``: ratio > 1 for a plant, ≤ 1 for a
control; a control's witness runs its plant's input) and, for the subjects that are neither an operator nor a
stepper, ``run(subject, seed, profile)``: the public entry points that judge it (a list of reports).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Callable

import numpy as np

import verimono as vm

RES = "prop:maxmon-resolvent-Yosida"
ITER = "eq:iteration"


@dataclasses.dataclass(frozen=True)
class Entry:
    name: str
    kind: str              # "operator" | "stepper" | "problem" | "lcs" | "set"
    label: str             # the paper's statement the plant breaks (a control obeys it)
    lawful: bool           # False: plant, True: control
    build: Callable[[], Any]
    smallest: str
    bug: str
    twin: str | None = None
    witness: Callable[[], float] | None = None     # plain NumPy: the law's ratio at ``smallest`` (> 1: violated)
    run: Callable[[Any, int, str | None], list] | None = None   # the entry points judging a non-operator subject


def _f(x):
    return np.asarray(x, dtype=float)


def _tol(*arrays, tol=None):
    """The witnesses' one rounding allowance: 1e-9 (1 + the largest magnitude touched)."""
    if tol is not None:
        return float(tol)
    s = 1.0 + max((float(np.max(np.abs(_f(a)), initial=0.0)) for a in arrays), default=0.0)
    return 1e-9 * s


def _ratio(a, b, *scale):
    """An equality law a = b: |a - b| / tol(a, b, scale)."""
    a, b = _f(a), _f(b)
    return float(np.max(np.abs(a - b), initial=0.0)) / _tol(a, b, *scale)


def _soft(x, lam):
    x = _f(x)
    return np.sign(x) * np.maximum(np.abs(x) - lam, 0.0)


def l1_min_norm(x, t=0.0):
    return np.sign(_f(x))


def l1_contains(x, y, t=0.0, tol=None):
    """y ∈ ∂|x|_1: y_i = sign x_i where x_i ≠ 0, |y_i| ≤ 1 where x_i = 0."""
    x, y = _f(x), _f(y)
    tol = _tol(x, y, tol=tol)
    nz = np.abs(x) > tol
    return bool(np.all(np.abs(y[nz] - np.sign(x[nz])) <= tol) and np.all(np.abs(y[~nz]) <= 1.0 + tol))


def box_contains(x, y, lo, hi, tol=None):
    """y ∈ N_[lo,hi](x), coordinate by coordinate."""
    x, y = _f(x), _f(y)
    tol = _tol(x, y, tol=tol)
    if np.any(x > hi + tol) or np.any(x < lo - tol):
        return False
    up, down = x >= hi - tol, x <= lo + tol
    return bool(np.all((up & (y >= -tol)) | (down & (y <= tol)) | (np.abs(y) <= tol)))


def proj_ball(x, c, r=1.0):
    d = _f(x) - c
    n = float(np.linalg.norm(d))
    return c + (d.copy() if n <= r else d * (r / n))


def ball_contains(x, y, c, r=1.0, tol=None):
    """y ∈ N_B(x), B = B(c, r): inside y = 0; on the sphere y = μ(x - c), μ ≥ 0."""
    x, y = _f(x), _f(y)
    tol = _tol(x, y, c, tol=tol)
    d = x - c
    nd, ny = float(np.linalg.norm(d)), float(np.linalg.norm(y))
    if nd > r + tol:
        return False
    if nd < r - tol:
        return bool(ny <= tol)
    return bool(float(y @ d) >= ny * nd - tol * (1.0 + ny) * (1.0 + nd))


def _linear_members(A):
    def contains(x, y, t=0.0, tol=None):
        x, y = _f(x), _f(y)
        return bool(np.max(np.abs(y - A @ x)) <= 4 * _tol(x, y, tol=tol) * (1.0 + float(np.abs(A).max())))
    return dict(contains=contains, min_norm=lambda x, t=0.0: A @ _f(x))


# ====================================================================================================
# operators
# ====================================================================================================

def _o_bigstep_build(bad, name):
    """F = ∂|·|_1 on R^3: soft thresholding.  The plant widens the step by 10^-3 "for robustness" only when
    λ > 5 *and* |x|_∞ > 50 (two quantifiers at once); the control never does."""
    def J(x, lam, t=0.0):
        x, lam = _f(x), float(lam)
        if bad and lam > 5.0 and float(np.max(np.abs(x), initial=0.0)) > 50.0:
            lam = lam * (1.0 + 1e-3)
        return _soft(x, lam)
    return vm.operator_from_resolvent(J, 3, name=name, contains=l1_contains, min_norm=l1_min_norm)


def _o_bigstep_witness():
    """Y_λx = (x - J_λx)/λ ∈ ∂|·|_1(J_λx) at x = (100, 0, 0), λ = 10."""
    def w(bad):
        op = _o_bigstep_build(bad, "w")
        x, lam = np.array([100.0, 0.0, 0.0]), 10.0
        J = op.resolvent(x, lam, 0.0)
        Y = (x - J) / lam
        return _ratio(Y[0], np.sign(J[0]), x)
    return w


_ROT = np.array([[1.0, 2.0], [-2.0, 1.0]])


def _o_readonly_build(bad, name):
    """N_B, B the unit ball of R^2: J = the projection.  The plant's read-only inputs (which it cannot "reuse as
    scratch") take a fallback path that clips to the box [-1, 1]^2 — the box is a superset of the ball."""
    def J(x, lam, t=0.0):
        xa = np.asarray(x)
        if not xa.flags.writeable:
            xc = np.array(xa, dtype=float)
            if bad:
                return np.clip(xc, -1.0, 1.0)
            return proj_ball(xc, np.zeros(2))
        return proj_ball(xa, np.zeros(2))
    return vm.operator_from_resolvent(J, 2, name=name, project_domain=lambda x, t=0.0: proj_ball(x, np.zeros(2)),
                                      contains=lambda x, y, t=0.0, tol=None: ball_contains(x, y, np.zeros(2), 1.0, tol))


def _o_readonly_witness(bad):
    op = _o_readonly_build(bad, "w")
    x = np.array([2.0, 2.0])
    x.flags.writeable = False
    J = op.resolvent(x, 1.0, 0.0)
    return max(0.0, float(np.linalg.norm(J)) - 1.0) / _tol(J)


def _o_warmup_build(bad, name, warm=256):
    """F(x) = Ax, A = [[1, 2], [-2, 1]]: J_λ = (I + λA)^{-1}.  After ``warm`` calls the resolvent switches to a
    "compiled" kernel: the plant bakes the inverse for the step of the call that triggered compilation into it
    (every later λ gets that inverse); the control's kernel keeps one inverse per λ."""
    state = {"calls": 0, "baked": None, "cache": {}}

    def J(x, lam, t=0.0):
        x, lam = _f(x), float(lam)
        state["calls"] += 1
        if state["calls"] <= warm:
            return np.linalg.solve(np.eye(2) + lam * _ROT, x)
        if bad:
            if state["baked"] is None:
                state["baked"] = np.linalg.inv(np.eye(2) + lam * _ROT)
            inv = state["baked"]
        else:
            inv = state["cache"].get(lam)
            if inv is None:
                inv = state["cache"][lam] = np.linalg.inv(np.eye(2) + lam * _ROT)
        return inv @ x
    return vm.operator_from_resolvent(J, 2, name=name, **_linear_members(_ROT))


def _o_warmup_witness(bad):
    op = _o_warmup_build(bad, "w")
    x = np.array([1.0, 0.0])
    for _ in range(257):
        op.resolvent(x, 1.0, 0.0)
    J = op.resolvent(x, 2.0, 0.0)
    Y = (x - J) / 2.0
    return _ratio(Y, _ROT @ J, x) / 4.0


def _o_bias_build(bias, name):
    """F(x) = Ax, A = [[1, 2], [-2, 1]]: J_λ = (I + λA)^{-1}x, the plant's result scaled by 1 + 10^-7 (a relative
    error float32 would hide and float64 resolves); the control's by 1."""
    def J(x, lam, t=0.0):
        return np.linalg.solve(np.eye(2) + float(lam) * _ROT, _f(x)) * (1.0 + bias)
    return vm.operator_from_resolvent(J, 2, name=name, **_linear_members(_ROT))


def _o_bias_witness(bias):
    op = _o_bias_build(bias, "w")
    x, lam = np.array([1.0, 0.0]), 1e-3
    J = op.resolvent(x, lam, 0.0)
    Y = (x - J) / lam
    return _ratio(Y, _ROT @ J, x) / 4.0


def _o_gap_build(bad, name):
    """N of the box [-1, 1]^2, J = clip.  The plant's first coordinate never lands in the band (0.2, 0.3) (a table
    of admissible set-points with a hole): points there snap to the nearer of 0.2, 0.3.  Its graph is still
    monotone where it is defined — the points (J_λx, Y_λx) are pairs of N_C for the nonconvex C with the hole — but
    J's range misses the band: F is not maximal and J not nonexpansive."""
    lo, hi = -np.ones(2), np.ones(2)

    def J(x, lam, t=0.0):
        out = np.clip(_f(x), -1.0, 1.0)
        if bad and 0.2 < out[0] < 0.3:
            out[0] = 0.2 if out[0] < 0.25 else 0.3
        return out
    return vm.operator_from_resolvent(J, 2, name=name, project_domain=lambda x, t=0.0: np.clip(_f(x), -1.0, 1.0),
                                      contains=lambda x, y, t=0.0, tol=None: box_contains(x, y, lo, hi, tol))


def _o_gap_witness(bad):
    """|J x1 - J x2| ≤ |x1 - x2| at x1 = (0.2499, 0), x2 = (0.2501, 0)."""
    op = _o_gap_build(bad, "w")
    x1, x2 = np.array([0.2499, 0.0]), np.array([0.2501, 0.0])
    a, b = op.resolvent(x1, 1.0, 0.0), op.resolvent(x2, 1.0, 0.0)
    return float(np.linalg.norm(a - b)) / (float(np.linalg.norm(x1 - x2)) + _tol(x1, x2))


# the wedge W = {x2 ≤ 0} ∩ {x2 ≤ x1/10} of R^2: two half-spaces at 5.7 degrees
_WA = np.array([[0.0, 1.0], [-0.1, 1.0]])


def _wedge_proj_exact(x):
    x = _f(x)
    cands = [np.zeros(2)]
    if np.all(_WA @ x <= 0.0):
        return x.copy()
    for i in range(2):
        a = _WA[i]
        p = x - max(0.0, float(a @ x)) / float(a @ a) * a
        if np.all(_WA @ p <= 1e-15 * (1.0 + np.abs(p).max())):
            cands.append(p)
    return min(cands, key=lambda p: float(np.linalg.norm(x - p)))


def _o_dykstra_build(name):
    """N_W, W a wedge of two half-spaces at 5.7 degrees: J = proj_W.  Computed by Dykstra's algorithm with a fixed
    20 sweeps, the two half-spaces visited in an order drawn from an unseeded generator on every call: points whose
    projection is the apex converge like cos² 5.7° a sweep, so J is neither the projection nor the same twice."""
    def J(x, lam, t=0.0):
        x = _f(x)
        rng = np.random.default_rng()
        p, incr = x.copy(), [np.zeros(2), np.zeros(2)]
        for _ in range(20):
            for i in rng.permutation(2):
                a = _WA[i]
                y = p + incr[i]
                q = y - max(0.0, float(a @ y)) / float(a @ a) * a
                incr[i] = y - q
                p = q
        return p
    return vm.operator_from_resolvent(J, 2, name=name, project_domain=lambda x, t=0.0: _wedge_proj_exact(x),
                                      contains=lambda x, y, t=0.0, tol=None: _wedge_contains(x, y, tol))


def _wedge_contains(x, y, tol=None):
    x, y = _f(x), _f(y)
    tol = _tol(x, y, tol=tol)
    if np.any(_WA @ x > tol):
        return False
    return bool(np.max(np.abs(_wedge_proj_exact(x + y) - x)) <= 4 * tol)


def _o_dykstra_witness():
    """J_λx = proj_W x at x = (-0.05, 1) (whose projection is the apex 0)."""
    op = _o_dykstra_build("w")
    x = np.array([-0.05, 1.0])
    return _ratio(op.resolvent(x, 1.0, 0.0), _wedge_proj_exact(x), x)


def _o_epsnorm_build(eps, name):
    """F = ∂|·| (the Euclidean norm) on R^3: prox_{λ|·|}(x) = x max(0, 1 - λ/|x|).  The plant smooths the norm in
    the denominator, sqrt(|x|² + 10^-12), "to avoid a division by zero": a relative error of order 10^-12/|x|²,
    all of it below |x| = 10^-5; the control's ε is 0 (and x = 0 is handled)."""
    def prox(x, lam):
        x, lam = _f(x), float(lam)
        nrm = math.sqrt(float(x @ x) + eps)
        if nrm == 0.0:
            return np.zeros_like(x)
        return x * max(0.0, 1.0 - lam / nrm)
    return vm.operator_from_prox(prox, value=lambda x: float(np.linalg.norm(_f(x))), shape=3, name=name)


def _o_epsnorm_witness(eps):
    """Y_λx ∈ ∂|·|(J_λx) = {J/|J|} at x = (10^-6, 0, 0), λ = 5·10^-7."""
    op = _o_epsnorm_build(eps, "w")
    x, lam = np.array([1e-6, 0.0, 0.0]), 5e-7
    J = op.resolvent(x, lam, 0.0)
    Y = (x - J) / lam
    return _ratio(Y, J / np.linalg.norm(J), x)


def _logbar_value(x):
    x = _f(x)
    return float(-np.sum(np.log(x))) if np.all(x > 0) else math.inf


def _o_logbar_build(stable, name):
    """F = ∂g, g(x) = -Σ log x_i (the log barrier) on R^2: prox_λg(x)_i = (x_i + sqrt(x_i² + 4λ))/2.  The plant
    evaluates that formula as written: for x_i ≪ -sqrt(λ) the sum cancels (x = -10^8, λ = 1: 1.49e-8/2 instead
    of 10^-8); the control uses 2λ/(sqrt(x_i² + 4λ) - x_i) for x_i < 0."""
    def prox(x, lam):
        x, lam = _f(x), float(lam)
        r = np.sqrt(x * x + 4.0 * lam)
        if stable:
            with np.errstate(divide="ignore", invalid="ignore"):
                neg = 2.0 * lam / (r - x)
            return np.where(x < 0, neg, 0.5 * (x + r))
        return 0.5 * (x + r)
    return vm.operator_from_prox(prox, value=_logbar_value, shape=2, name=name)


def _o_logbar_witness(stable):
    """Y_λx = (x - p)/λ ∈ ∂g(p) = {-1/p} at x = (-10^8, 1), λ = 1."""
    op = _o_logbar_build(stable, "w")
    x, lam = np.array([-1e8, 1.0]), 1.0
    p = op.resolvent(x, lam, 0.0)
    if np.any(p <= 0):
        return math.inf
    Y = (x - p) / lam
    return _ratio(Y, -1.0 / p, x)


def _o_batch32_J(bad, n=3):
    """The plant's batched projection on the unit ball of R^3: batches of 64 rows or more go to a float32 path
    ("the GPU kernel"); single points and smaller batches are projected in float64."""
    def J(x, lam, t=0.0):
        x = _f(x)
        if x.ndim == 1:
            return proj_ball(x, np.zeros(n))
        pts = x.astype(np.float32) if (bad and x.shape[0] >= 64) else x
        nr = np.linalg.norm(pts, axis=1, keepdims=True)
        return np.asarray(pts / np.maximum(nr, 1.0), dtype=float)
    return J


def _o_batch32_build(bad, name, n=3):
    """N_B, B the unit ball of R^3, declared ``batched=True`` (rows are points).  The plant computes batches of
    B ≥ 64 rows in float32: each row a relative 10^-7 off its single-point value; the control in float64."""
    return vm.operator_from_resolvent(_o_batch32_J(bad, n), n, name=name, batched=True,
                                      project_domain=lambda x, t=0.0: proj_ball(x, np.zeros(n)),
                                      contains=lambda x, y, t=0.0, tol=None: ball_contains(x, y, np.zeros(n), 1.0, tol))


def _o_batch32_witness(bad):
    """Row i of J(X) = J(X[i]) (a batch maps row by row) on 64 seeded rows of norm about 3 (the user's J called as
    verimono's wrapper calls it, with a step and a time per row)."""
    J = _o_batch32_J(bad)
    X = 3.0 * np.random.default_rng(0).standard_normal((64, 3))
    JB = J(X, np.ones(64), np.zeros(64))
    rows = np.array([J(r, 1.0, 0.0) for r in X])
    return _ratio(JB, rows, X)


# ---------------------------------------------------------------------------------------------------
# an LCP resolvent (Section 7's e:lcp, p:lcp2)
# ---------------------------------------------------------------------------------------------------

_M_LCP = np.array([[1.0, 1.0], [-1.0, 1.0]])        # M + Mᵀ = 2I: monotone


def _lcp_enum(Ml, x, strict):
    """z ≥ 0, w = Ml z - x ≥ 0, z ⊥ w by enumerating the active sets of R^2.  ``strict`` accepts a pattern only
    with z_S > 0 and w_rest > 0 (no degenerate pivots), falling back to max(x, 0) when none is accepted."""
    tol = 1e-12 * (1.0 + float(np.abs(x).max()))
    for S in [(), (0,), (1,), (0, 1)]:
        z = np.zeros(2)
        if S:
            idx = list(S)
            z[idx] = np.linalg.solve(Ml[np.ix_(idx, idx)], x[idx])
        w = Ml @ z - x
        rest = [i for i in range(2) if i not in S]
        if strict:
            ok = all(z[i] > 0 for i in S) and all(w[i] > 0 for i in rest)
        else:
            ok = all(z[i] >= -tol for i in S) and all(w[i] >= -tol for i in rest)
        if ok:
            return np.maximum(z, 0.0)
    return np.maximum(x, 0.0)


def _lcp_contains(x, y, t=0.0, tol=None):
    """y ∈ Mx + N_{R+^2}(x): x ≥ 0, v = y - Mx ≤ 0, v_i = 0 where x_i > 0."""
    x, y = _f(x), _f(y)
    tol = _tol(x, y, tol=tol) * 4.0
    if np.any(x < -tol):
        return False
    v = y - _M_LCP @ x
    return bool(np.all(v <= tol) and np.all(np.abs(v[x > tol]) <= tol))


def _l_lcp_build(strict, name):
    """F(x) = Mx + N_{R+^2}(x), M = [[1, 1], [-1, 1]]: J_λx is the solution z of LCP(-x, I + λM).  The user's
    enumerator (plant) rejects a degenerate pattern (z_i = 0 in the active set or w_i = 0 outside it) and falls
    back to max(x, 0), which is not complementary; the control accepts ≥ -tol."""
    def J(x, lam, t=0.0):
        return _lcp_enum(np.eye(2) + float(lam) * _M_LCP, _f(x), strict)
    return vm.operator_from_resolvent(J, 2, name=name, contains=_lcp_contains,
                                      project_domain=lambda x, t=0.0: np.maximum(_f(x), 0.0))


def _l_lcp_witness(strict):
    """Complementarity of J_λx: w = (I + λM)z - x ≥ 0, z ⊥ w, at x = (2, -1), λ = 1 (pattern {0} with w_1 = 0)."""
    x, lam = np.array([2.0, -1.0]), 1.0
    op = _l_lcp_build(strict, "w")
    z = op.resolvent(x, lam, 0.0)
    w = (np.eye(2) + lam * _M_LCP) @ z - x
    viol = max(float(np.max(-w)), float(np.max(-z)), float(abs(z @ w)), 0.0)
    return viol / _tol(x, z, w)


# ====================================================================================================
# steppers
# ====================================================================================================

def _scheme(problem, t_grid, *, h_used=None, t_used=None, f_eval=None, dU=None, after=None, skip_J=None):
    """The paper's scheme eq:iteration, x_{k+1} = J_{h F(t_{k+1})}(x_k + h f(x_k) + ∫u), with hooks for a plant:
    the steps and times it uses, how it evaluates f, its own ∫u, a map after each step, a cell whose resolvent
    it skips."""
    t = np.asarray(t_grid, dtype=float)
    K = len(t) - 1
    hs = np.diff(t) if h_used is None else h_used
    ts = t if t_used is None else t_used
    if dU is None:
        dU = problem.input_increments(t)
    x = [np.array(problem.x0, dtype=float)]
    for k in range(K):
        h = hs[k]
        z = x[-1].copy()
        if problem.f is not None:
            fx = problem.f(x[-1]) if f_eval is None else f_eval(problem, x[-1], h)
            z = z + h * fx
        if dU is not None:
            z = z + dU[k]
        xn = z if (skip_J is not None and skip_J(k, h)) else problem.operator.resolvent(z, h, ts[k + 1])
        if after is not None:
            xn = after(xn, k, h)
        x.append(np.asarray(xn, dtype=float))
    return np.array(x)


class _P:
    """A duck-typed problem for the witnesses: what a stepper reads from a verimono.Problem."""

    def __init__(self, J, x0, f=None, u=None, U=None, lipschitz=None):
        self.operator = type("Op", (), {"resolvent": staticmethod(J)})()
        self.x0, self.f, self.u, self.U, self.lipschitz = _f(x0), f, u, U, lipschitz

    def input_increments(self, t):
        t = _f(t)
        if self.U is not None:
            return np.array([self.U(b) - self.U(a) for a, b in zip(t[:-1], t[1:])])
        if self.u is None:
            return None
        return _gauss3(self.u, t)


def _gauss3(u, t):
    """∫u over each cell by 3-point Gauss–Legendre."""
    nodes = np.array([-math.sqrt(0.6), 0.0, math.sqrt(0.6)])
    wts = np.array([5.0, 8.0, 5.0]) / 9.0
    out = []
    for a, b in zip(t[:-1], t[1:]):
        m, r = 0.5 * (a + b), 0.5 * (b - a)
        out.append(r * sum(w * _f(u(m + r * s)) for w, s in zip(wts, nodes)))
    return np.array(out)


def _identity_J(z, lam, t=0.0):
    return _f(z).copy()


def _halfspace_J(z, lam, t=0.0):
    """J of N_{x_1 ≥ t - 1/2}: the projection."""
    z = _f(z).copy()
    z[0] = max(z[0], t - 0.5)
    return z


def _step_residual(xs, prob, t_grid):
    """eq:iteration's residual: max_k |x_{k+1} - J_{h F(t_{k+1})}(x_k + h f(x_k) + ∫u)| / tol."""
    t = _f(t_grid)
    dU = prob.input_increments(t)
    worst = 0.0
    if len(xs) != len(t) or _ratio(xs[0], prob.x0) > 1.0:
        return math.inf
    for k in range(len(t) - 1):
        h = t[k + 1] - t[k]
        z = xs[k] + (h * prob.f(xs[k]) if prob.f is not None else 0.0) + (dU[k] if dU is not None else 0.0)
        worst = max(worst, _ratio(xs[k + 1], prob.operator.resolvent(z, h, t[k + 1]), z))
    return worst


def _neg(x):
    return -_f(x)


def _s_order_half(p):
    """x_{k+1} = J(z_k) + h^p·1: a "stabilising" nudge whose sum K h^p = T h^{p-1} vanishes for p > 1.  p = 3/2
    (the plant) converges at order 1/2 and claims order 1; p = 2 (the control) converges at order 1."""
    def step(problem, t_grid):
        one = np.ones(np.shape(problem.x0)[-1])
        return _scheme(problem, t_grid, after=lambda xn, k, h: xn + h ** p * one)
    step.__name__ = f"nudged_h_pow_{p}"
    return step


def _s_order_witness(p):
    """Measured order of x' = -x, x0 = 1 on [0, 1] from K = 400 and 1600 cells, against the claim 1 with a 25%
    allowance: ratio 0.75·1/measured."""
    st = _s_order_half(p)
    errs = []
    for K in (400, 1600):
        t = np.linspace(0.0, 1.0, K + 1)
        xs = st(_P(_identity_J, [1.0], f=_neg), t)
        errs.append(abs(xs[-1, 0] - math.exp(-1.0)))
    order = math.log(errs[0] / errs[1]) / math.log(4.0)
    return 0.75 / order


def _s_ratio_geomean(bad):
    """The plant "smooths" a partition whose neighbouring cells differ by more than 10×: it steps with the
    geometric mean of each cell and the one before it.  The control steps with the cells themselves."""
    def step(problem, t_grid):
        hs = np.diff(np.asarray(t_grid, dtype=float))
        used = hs
        if bad and len(hs) > 1 and float(hs.max() / hs.min()) > 10.0:
            used = hs.copy()
            used[1:] = np.sqrt(hs[1:] * hs[:-1])
        return _scheme(problem, t_grid, h_used=used)
    step.__name__ = "geomean_cells" if bad else "own_cells"
    return step


def _s_time32(bad, above=5000):
    """The plant accumulates the node times t_{k+1} = t_k + h_k in float32 above K = 5000 cells "to save memory"
    (F is then taken at the drifted times); the control reads t_{k+1} from the grid."""
    def step(problem, t_grid):
        t = np.asarray(t_grid, dtype=float)
        K = len(t) - 1
        used = t
        if K > above:
            acc = np.zeros(K + 1, dtype=np.float32)
            hs32 = np.diff(t).astype(np.float32)
            for k in range(K):
                acc[k + 1] = acc[k] + hs32[k]
            used = acc.astype(float) + t[0] if bad else t
        return _scheme(problem, t_grid, t_used=used)
    step.__name__ = "time_float32_above_5000" if bad else "time_from_grid"
    return step


def _s_time32_witness(bad):
    prob = _P(_halfspace_J, [0.0, 0.0])
    t = np.linspace(0.0, 1.0, 6001)
    return _step_residual(_s_time32(bad)(prob, t), prob, t)


def _s_gauss3(bad):
    """The plant integrates u by its own 3-point Gauss–Legendre rule per cell, ignoring the primitive U the
    problem states: exact to order 6 for a smooth u, off by O(h) on a cell where u jumps.  The control asks
    ``problem.input_increments`` (exact from U)."""
    def step(problem, t_grid):
        t = np.asarray(t_grid, dtype=float)
        dU = None
        if bad and problem.u is not None:
            dU = _gauss3(problem.u, t)
        return _scheme(problem, t_grid, dU=dU)
    step.__name__ = "own_gauss3_input" if bad else "input_increments"
    return step


def _s_gauss3_witness(bad):
    """u = 1(t > 0.3), U = max(t - 0.3, 0), F = 0, x0 = 0, t = (0, 0.25, 0.5)."""
    prob = _P(_identity_J, [0.0], u=lambda s: np.array([1.0 if s > 0.3 else 0.0]),
              U=lambda s: np.array([max(s - 0.3, 0.0)]))
    t = np.array([0.0, 0.25, 0.5])
    return _step_residual(_s_gauss3(bad)(prob, t), prob, t)


def _s_f32(bad):
    """The plant evaluates f on a float32 copy of the state "to halve memory traffic" (a relative 10^-7 in
    h f(x_k)); the control on the float64 state."""
    def f_eval(problem, x, h):
        if bad:
            return np.asarray(problem.f(np.asarray(x, dtype=np.float32)), dtype=float)
        return np.asarray(problem.f(x), dtype=float)

    def step(problem, t_grid):
        return _scheme(problem, t_grid, f_eval=f_eval)
    step.__name__ = "field_on_float32_copy" if bad else "field_on_state"
    return step


def _s_f32_witness(bad):
    """F = 0, f(x) = -x, x0 = 1000/3, t = (0, 0.5, 1)."""
    prob = _P(_identity_J, [1000.0 / 3.0], f=_neg)
    t = np.array([0.0, 0.5, 1.0])
    return _step_residual(_s_f32(bad)(prob, t), prob, t)


def _s_tiny_cell():
    """A cell shorter than 10^-3 "barely moves the state": the plant skips its resolvent (x_{k+1} = z_k)."""
    def step(problem, t_grid):
        return _scheme(problem, t_grid, skip_J=lambda k, h: h < 1e-3)
    step.__name__ = "skip_resolvent_below_1e_3"
    return step


def _s_tiny_witness():
    """moving half-space x_1 ≥ t - 1/2, x0 = (0, 0), t = (0, 0.6, 0.6005)."""
    prob = _P(_halfspace_J, [0.0, 0.0])
    t = np.array([0.0, 0.6, 0.6005])
    return _step_residual(_s_tiny_cell()(prob, t), prob, t)


def _s_shape_guess(bad):
    """The plant accepts its states as (n, K + 1) or (K + 1, n): it transposes when the *second* axis has the
    grid's length — which a (K + 1, n) array with n = K + 1 has too; the control transposes only when the first
    axis does not have it."""
    def step(problem, t_grid):
        out = _scheme(problem, t_grid)
        L = len(t_grid)
        if bad:
            if out.ndim == 2 and out.shape[1] == L:
                out = out.T.copy()
        elif out.ndim == 2 and out.shape[0] != L and out.shape[1] == L:
            out = out.T.copy()
        return out
    step.__name__ = "shape_guess_second_axis" if bad else "shape_guess_first_axis"
    return step


def _s_shape_witness(bad):
    """F = 0, f(x) = -x, x0 = (1, 2, 3), t = (0, 0.5, 1): n = K + 1 = 3."""
    prob = _P(_identity_J, [1.0, 2.0, 3.0], f=_neg)
    t = np.array([0.0, 0.5, 1.0])
    return _step_residual(_s_shape_guess(bad)(prob, t), prob, t)


def _s_snap(rel):
    """A partition whose cells are within ``rel`` of their mean is "uniform up to rounding": the plant (rel =
    10^-3) steps on linspace(t_0, t_K, K + 1) instead; the control's rel = 0 never snaps."""
    def step(problem, t_grid):
        t = np.asarray(t_grid, dtype=float)
        hs = np.diff(t)
        if len(hs) and float(np.max(np.abs(hs - hs.mean()))) < rel * float(hs.mean()):
            u = np.linspace(t[0], t[-1], len(t))
            return _scheme(problem, u)
        return _scheme(problem, t)
    step.__name__ = f"snap_near_uniform_{rel:g}"
    return step


def _s_snap_witness(rel):
    """F = 0, f(x) = -x, x0 = 1, t = (0, 0.5004, 1)."""
    prob = _P(_identity_J, [1.0], f=_neg)
    t = np.array([0.0, 0.5004, 1.0])
    return _step_residual(_s_snap(rel)(prob, t), prob, t)


def _s_heun():
    """When the problem states a Lipschitz constant L and h·L > 1/2, the plant "stabilises" the drift with Heun's
    predictor-corrector (h(f(x) + f(x + h f(x)))/2) instead of the scheme's h f(x_k)."""
    def f_eval(problem, x, h):
        L = getattr(problem, "lipschitz", None)
        fx = np.asarray(problem.f(x), dtype=float)
        if L is not None and h * float(L) > 0.5:
            return 0.5 * (fx + np.asarray(problem.f(x + h * fx), dtype=float))
        return fx

    def step(problem, t_grid):
        return _scheme(problem, t_grid, f_eval=f_eval)
    step.__name__ = "heun_when_hL_gt_half"
    return step


def _s_heun_witness():
    """F = 0, f(x) = -x (L = 1), x0 = 1, t = (0, 1)."""
    prob = _P(_identity_J, [1.0], f=_neg, lipschitz=1.0)
    t = np.array([0.0, 1.0])
    return _step_residual(_s_heun()(prob, t), prob, t)


def _s_geomean_witness(bad):
    """F = 0, f(x) = -x, x0 = 1, t = (0, 0.01, 1): neighbouring cells 99× apart."""
    prob = _P(_identity_J, [1.0], f=_neg)
    t = np.array([0.0, 0.01, 1.0])
    return _step_residual(_s_ratio_geomean(bad)(prob, t), prob, t)


# ====================================================================================================
# problems with stated constants (check_assumptions, and vm.solve on them)
# ====================================================================================================

def _run_problem(problem, seed, profile):
    return [vm.check_assumptions(problem, seed=seed),
            vm.check_stepper(vm.solve, problems=[problem], seed=seed, profile=profile, generated=0)]


def _f_kinked(x):
    """0.5 x for |x| ≤ 2, sign(x)(1 + 3(|x| - 2)) beyond (coordinatewise): continuous, Lipschitz constant 3."""
    x = _f(x)
    a = np.abs(x)
    return np.where(a <= 2.0, 0.5 * x, np.sign(x) * (1.0 + 3.0 * (a - 2.0)))


def _p_lipschitz_build(L, name):
    """x' ∈ -N_B(x) + f(x), B the ball of radius 5, f kinked at |x_i| = 2 (slope 0.5 inside, 3 beyond), x0 = (1.9,
    0): the solution leaves the slope-0.5 region at t ≈ 0.1.  The plant states ``lipschitz=0.5`` (the slope near
    x0); the control 3."""
    S = vm.sets.Ball(np.zeros(2), 5.0)
    return vm.Problem(vm.NormalCone(S), x0=[1.9, 0.0], T=1.0, f=_f_kinked, lipschitz=L, name=name)


def _p_lipschitz_witness(L):
    """|f(x1) - f(x2)| ≤ L|x1 - x2| at x1 = (3, 0), x2 = (2.5, 0)."""
    x1, x2 = np.array([3.0, 0.0]), np.array([2.5, 0.0])
    return float(np.linalg.norm(_f_kinked(x1) - _f_kinked(x2))) / (L * float(np.linalg.norm(x1 - x2)) + _tol(x1))


def _kink_centre(t):
    t = np.asarray(t, dtype=float)
    return np.stack([2.0 * np.maximum(t - 0.5, 0.0), np.zeros_like(t)], axis=-1)


def _p_phi_build(late_rate, name):
    """x' ∈ -N_{B(c(t), 1)}(x), c(t) = (2 max(t - 1/2, 0), 0): the ball rests, then moves at speed 2 from t = 1/2.
    The plant states φ(t) = t (speed 1: right until the kink, too small after it); the control φ(t) =
    2 max(t - 1/2, 0)."""
    S = vm.sets.Ball(_kink_centre, 1.0)
    phi = (lambda t: np.asarray(t, dtype=float)) if late_rate == 1.0 else \
        (lambda t: 2.0 * np.maximum(np.asarray(t, dtype=float) - 0.5, 0.0))
    return vm.Problem(vm.NormalCone(S), x0=[0.0, 0.0], T=1.0, phi=phi, name=name)


def _p_phi_witness(late_rate):
    """(A3): sup_{z ∈ dom F(s)} dist(z, dom F(t)) = |c(t) - c(s)| ≤ φ(t) - φ(s) at s = 1/2, t = 1."""
    s, t = 0.5, 1.0
    phi = (lambda r: r) if late_rate == 1.0 else (lambda r: 2.0 * max(r - 0.5, 0.0))
    return float(np.linalg.norm(_kink_centre(t) - _kink_centre(s))) / (phi(t) - phi(s) + 1e-12)


def _p_exact_build(off, name):
    """x' ∈ -N_{B(0, 10)}(x) - x from x0 = (1, 0) on [0, 1]: the ball never binds, x(t) = e^{-t}x0.  The plant's
    stated exact solution is e^{-t}(1 + 10^-7 t)x0 (a relative 10^-7 off, say a constant transcribed with seven
    digits); the control's is e^{-t}x0."""
    x0 = np.array([1.0, 0.0])

    def exact(t):
        t = np.asarray(t, dtype=float)
        return np.multiply.outer(np.exp(-t) * (1.0 + off * t), x0)
    return vm.Problem(vm.NormalCone(vm.sets.Ball(np.zeros(2), 10.0)), x0=x0, T=1.0, f=_neg, lipschitz=1.0,
                      exact=exact, order=1.0, name=name)


def _p_exact_witness(off):
    """The stated x solves x' = -x (the ball inactive): |x'(t) + x(t)| / tol at t = 1/2."""
    t = 0.5
    x = math.exp(-t) * (1.0 + off * t)
    dx = -math.exp(-t) * (1.0 + off * t) + off * math.exp(-t)
    return abs(dx + x) / _tol([x])


# ====================================================================================================
# linear systems with a relation (Section 7): lcs.check_hypotheses
# ====================================================================================================

def _run_lcs(system, seed, profile):
    return [vm.lcs.check_hypotheses(system, 1.0, seed=seed)]


def _l_rlc_build(bad, R=5e-4, name=None):
    """A passive RLC-with-diode system x' = Ax + Bz, w = Cx + Dz, 0 ≤ z ⊥ w ≥ 0 built by the user's
    ``make_circuit(R)``: A = [[0, 1], [-1, -0.1]], B = (0, 1)ᵀ, C = Bᵀ, D = R.  The plant's builder subtracts a
    "regularisation" 10^-3 from the series resistance, so for R < 10^-3 D < 0 (not passive, p:pass i); the
    control's keeps D = R."""
    A = np.array([[0.0, 1.0], [-1.0, -0.1]])
    B = np.array([[0.0], [1.0]])
    D = np.array([[R - 1e-3 if bad else R]])
    return vm.lcs.LinearRelationSystem(A, B, B.T.copy(), D, vm.lcs.Complementarity(), name=name)


def _l_rlc_witness(bad):
    """p:pass i: D + Dᵀ ⪰ 0 (ratio -λ_min / tol)."""
    D = np.array([[5e-4 - 1e-3 if bad else 5e-4]])
    lmin = float(np.linalg.eigvalsh(D + D.T).min())
    return max(0.0, -lmin) / _tol(D)


_V_KNOTS = np.linspace(0.0, 1.0, 11)
_V_VALUES = np.cos(3.0 * _V_KNOTS)


def _v_table(hold):
    def v(t):
        t = np.asarray(t, dtype=float)
        if hold:
            idx = np.clip(np.floor(t * 10.0).astype(int), 0, 10)
            out = _V_VALUES[idx]
        else:
            out = np.interp(t, _V_KNOTS, _V_VALUES)
        return np.asarray(out, dtype=float)[..., None] if np.ndim(out) else np.array([float(out)])
    return v


def _l_vtable_build(hold, name):
    """x' = -x + z, w = x + v(t), 0 ≤ z ⊥ w ≥ 0 (passive with K = 1; C = 1 so im C = R): v read from a table of
    cos 3t at the knots 0, 0.1, ..., 1.  The plant holds each knot's value until the next (zero-order hold: v
    jumps at every knot, not absolutely continuous, e: linear case-comp iii); the control interpolates linearly."""
    one = np.array([[1.0]])
    return vm.lcs.LinearRelationSystem(-one, one, one, np.array([[0.0]]), vm.lcs.Complementarity(),
                                       v=_v_table(hold), name=name)


def _l_vtable_witness(hold):
    """v ∈ AC: |v(0.1 + δ) - v(0.1 - δ)| ≤ L_v·2δ (L_v = 3, the slope bound of cos 3t and its interpolant), δ = 1e-9."""
    v = _v_table(hold)
    d = 1e-9
    jump = abs(float(v(0.1 + d)[0]) - float(v(0.1 - d)[0]))
    return jump / (3.0 * 2 * d + 1e-15)


# ====================================================================================================
# moving sets (a user's ConvexSet under vm.NormalCone): check_operator, and vm.solve on its sweeping process
# ====================================================================================================

def _run_set(S, seed, profile):
    op = vm.NormalCone(S)
    problem = vm.Problem(op, x0=np.array(S.project(np.zeros(S.dim), 0.0), dtype=float), T=1.0,
                         name=f"sweeping process of {S.name}")
    return [vm.check_operator(op, seed=seed, profile=profile),
            vm.check_stepper(vm.solve, problems=[problem], seed=seed, profile=profile, generated=0)]


def _rows(fn, x, t):
    x = _f(x)
    if x.ndim == 1:
        return fn(x, float(np.asarray(t).reshape(-1)[0]) if np.ndim(t) else float(t))
    ts = np.broadcast_to(np.asarray(t, dtype=float), (x.shape[0],))
    return np.array([fn(r, float(s)) for r, s in zip(x, ts)])


class LagBall(vm.sets.ConvexSet):
    """The unit ball centred at c(t) = (t, 0).  The plant (``lag=True``) remembers the time of its previous call
    and projects onto the ball of *that* time ("the centre is updated after the projection"): one call late."""

    def __init__(self, lag, name):
        super().__init__(2, name)
        self.lag = lag
        self._prev = 0.0

    def _one(self, x, t):
        tc = self._prev if self.lag else t
        self._prev = t
        return proj_ball(x, np.array([tc, 0.0]))

    def project(self, x, t=0.0):
        return _rows(self._one, x, t)


def _m_lag_witness(lag):
    """J = proj_{S(1)}(5, 0) = (2, 0) after a call at t = 0."""
    S = LagBall(lag, "w")
    S.project(np.zeros(2), 0.0)
    J = S.project(np.array([5.0, 0.0]), 1.0)
    return _ratio(J, [2.0, 0.0], [5.0])


_TRI_A = np.array([[-1.0, 0.0], [0.0, -1.0], [1.0, 1.0]]) / np.array([[1.0], [1.0], [math.sqrt(2.0)]])
_TRI_B0 = np.array([1.0, 1.0, 1.0])


def _tri_b(t):
    return _TRI_B0 + np.array([0.0, 0.0, t])


def _tri_exact(x, t):
    """Projection onto the triangle {x : a_i·x ≤ b_i(t)} of R^2: the nearest feasible candidate among x, its
    projections on the three edges' lines and the three vertices (exact in the plane)."""
    b = _tri_b(t)
    if np.all(_TRI_A @ x <= b):
        return x.copy()
    cands = []
    for i in range(3):
        a = _TRI_A[i]
        cands.append(x - (float(a @ x) - b[i]) * a)
    for i in range(3):
        for j in range(i + 1, 3):
            cands.append(np.linalg.solve(_TRI_A[[i, j]], b[[i, j]]))
    tol = 1e-12 * (1.0 + float(np.abs(x).max()) + float(np.abs(b).max()))
    feas = [p for p in cands if np.all(_TRI_A @ p <= b + tol)]
    return min(feas, key=lambda p: float(np.linalg.norm(x - p)))


def _tri_sequential(x, t):
    """One pass over the faces, each violated half-space projected on in turn."""
    b = _tri_b(t)
    p = x.copy()
    for i in range(3):
        a = _TRI_A[i]
        s = float(a @ p) - b[i]
        if s > 0:
            p = p - s * a
    return p


class Triangle(vm.sets.ConvexSet):
    """The triangle {x_1 ≥ -1, x_2 ≥ -1, (x_1 + x_2)/√2 ≤ 1 + t}, growing with t.  The plant projects face by face
    in one pass (right off a single face, wrong — not the nearest point, even outside — beyond a vertex whose
    faces are not orthogonal); the control takes the nearest feasible candidate (exact in the plane)."""

    def __init__(self, bad, name):
        super().__init__(2, name)
        self.bad = bad

    def project(self, x, t=0.0):
        return _rows(_tri_sequential if self.bad else _tri_exact, x, t)


def _m_tri_witness(bad):
    """J = proj_S(x) at x = (-3, 4), t = 0: beyond the vertex (-1, 1 + √2) where faces 1 and 3 meet at 45°."""
    x = np.array([-3.0, 4.0])
    return _ratio(Triangle(bad, "w").project(x, 0.0), _tri_exact(x, 0.0), x)


def _ellipse_proj(x, axes, iters):
    """Projection onto {Σ x_i²/a_i² ≤ 1}: p_i = x_i a_i²/(a_i² + μ), μ ≥ 0 the root of Σ x_i² a_i²/(a_i² + μ)² = 1,
    by ``iters`` bisection steps on [0, |x| max a] (``iters=None``: until the bracket stops shrinking)."""
    x = _f(x)
    a2 = axes ** 2
    if float(np.sum(x * x / a2)) <= 1.0:
        return x.copy()
    lo, hi = 0.0, float(np.linalg.norm(x)) * float(axes.max())
    k = 0
    while iters is None or k < iters:
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if float(np.sum(x * x * a2 / (a2 + mid) ** 2)) > 1.0:
            lo = mid
        else:
            hi = mid
        k += 1
    mu = 0.5 * (lo + hi)
    return x * a2 / (a2 + mu)


class Ellipse(vm.sets.ConvexSet):
    """The ellipse {x_1² + x_2²/b(t)² ≤ 1}, b(t) = 1 + 19t (eccentricity growing to 20).  The plant projects with
    20 bisection steps on the secular equation (a relative 10^-6 of the bracket); the control bisects until the
    bracket stops shrinking."""

    def __init__(self, iters, name):
        super().__init__(2, name)
        self.iters = iters

    def project(self, x, t=0.0):
        return _rows(lambda r, s: _ellipse_proj(r, np.array([1.0, 1.0 + 19.0 * s]), self.iters), x, t)


def _m_ellipse_witness(iters):
    """J = proj_S(x) at x = (3, 30), t = 1, against the bisection to the last bit."""
    x = np.array([3.0, 30.0])
    axes = np.array([1.0, 20.0])
    return _ratio(_ellipse_proj(x, axes, iters), _ellipse_proj(x, axes, None), x)


# ====================================================================================================
# the entries
# ====================================================================================================

def _stepper(fn, **claim):
    def build():
        return vm.Stepper(fn, name=fn.__name__, **claim) if claim else fn
    return build


E = Entry
ENTRIES: list[Entry] = [
    # ---------------- operators: plants
    E("soft_step_widened_big_lambda_big_x", "operator", f"{RES} v (Y_λx ∈ ∂|·|_1(J_λx))", False,
      lambda: _o_bigstep_build(True, "soft threshold, step 1.001λ for λ > 5 and |x| > 50"),
      "x = (100, 0, 0), λ = 10: J_0 = 89.99, Y_0 = 1.001",
      "the step widened by 10^-3 only where λ > 5 and |x|_∞ > 50 at once", witness=lambda: _o_bigstep_witness()(True)),
    E("ball_readonly_fallback_clips_box", "operator", f"{RES} i (J_λx ∈ cl dom F = B)", False,
      lambda: _o_readonly_build(True, "ball, read-only inputs clipped to the box"),
      "x = (2, 2) read-only: J = (1, 1), |J| = 1.41",
      "a read-only input takes a fallback that clips to [-1, 1]^2 instead of projecting on the ball",
      witness=lambda: _o_readonly_witness(True)),
    E("linear_kernel_baked_after_256_calls", "operator", f"{RES} v (Y_λx ∈ F(J_λx) = {{AJ_λx}})", False,
      lambda: _o_warmup_build(True, "Ax, kernel compiled after 256 calls with its λ baked in"),
      "257 calls at λ = 1, then x = (1, 0), λ = 2: J = (I + A)^{-1}x",
      "after 256 warm-up calls a compiled kernel keeps the inverse of the step that triggered it",
      witness=lambda: _o_warmup_witness(True)),
    E("linear_relative_bias_1e_7", "operator", f"{RES} v (Y_λx = (x - J_λx)/λ ∈ F(J_λx))", False,
      lambda: _o_bias_build(1e-7, "Ax, J scaled by 1 + 1e-7"),
      "x = (1, 0), λ = 10^-3: J off by 10^-7, Y off by 10^-4",
      "the resolvent's output scaled by 1 + 10^-7", witness=lambda: _o_bias_witness(1e-7)),
    E("box_range_misses_band", "operator", f"{RES} i/ii (dom J_λ = R^n, J_λ nonexpansive; F maximal)", False,
      lambda: _o_gap_build(True, "box, no set-point in (0.2, 0.3)"),
      "x1 = (0.2499, 0), x2 = (0.2501, 0): |ΔJ| = 0.1 > |Δx| = 2e-4",
      "the first coordinate snaps out of the band (0.2, 0.3): monotone graph, range with a hole (not maximal)",
      witness=lambda: _o_gap_witness(True)),
    E("wedge_dykstra_random_order_20", "operator", f"{RES} i/ii (J_λ = proj_W, single-valued)", False,
      lambda: _o_dykstra_build("wedge, Dykstra 20 sweeps, random order per call"),
      "x = (-0.05, 1): proj_W x = 0, Dykstra leaves |J| ≈ 0.3",
      "projection onto a 5.7° wedge by 20 Dykstra sweeps in an order drawn unseeded on every call",
      witness=_o_dykstra_witness),
    E("norm_prox_epsilon_smoothed", "operator", f"{RES} v (Y_λx ∈ ∂|·|(J_λx) = {{J/|J|}})", False,
      lambda: _o_epsnorm_build(1e-12, "prox of λ|x|, |x| as sqrt(|x|² + 1e-12)"),
      "x = (10^-6, 0, 0), λ = 5·10^-7: J_0 = 6.5e-7, not 5e-7",
      "the norm smoothed to sqrt(|x|² + 10^-12) in the prox's denominator",
      witness=lambda: _o_epsnorm_witness(1e-12)),
    E("log_barrier_prox_cancellation", "operator", f"{RES} v (Y_λx ∈ ∂g(J_λx)), prox of g = -Σ log x_i", False,
      lambda: _o_logbar_build(False, "log barrier prox (x + sqrt(x² + 4λ))/2"),
      "x = (-10^8, 1), λ = 1: p_0 = 7.45e-9, not 10^-8",
      "(x + sqrt(x² + 4λ))/2 evaluated as written: it cancels for x ≪ -sqrt(λ)",
      witness=lambda: _o_logbar_witness(False)),
    E("ball_batch_float32_when_b_ge_64", "operator", f"{RES} i/ii (J_λ a function of each row's x)", False,
      lambda: _o_batch32_build(True, "ball, batched, float32 for B >= 64"),
      "64 rows of norm ~3: each projected row a relative 1e-7 off its single-point projection",
      "a declared batched resolvent computes batches of 64 rows or more in float32",
      witness=lambda: _o_batch32_witness(True)),
    # ---------------- operators: controls
    E("ctrl_soft_step_kept", "operator", f"{RES} v", True, lambda: _o_bigstep_build(False, "soft threshold"),
      "x = (100, 0, 0), λ = 10", "none (the plant's branch removed)", twin="soft_step_widened_big_lambda_big_x",
      witness=lambda: _o_bigstep_witness()(False)),
    E("ctrl_ball_readonly_projects", "operator", f"{RES} i", True,
      lambda: _o_readonly_build(False, "ball, read-only inputs copied and projected"), "x = (2, 2) read-only",
      "none (the fallback projects on the ball)", twin="ball_readonly_fallback_clips_box",
      witness=lambda: _o_readonly_witness(False)),
    E("ctrl_linear_kernel_per_lambda", "operator", f"{RES} v", True,
      lambda: _o_warmup_build(False, "Ax, kernel compiled after 256 calls, one inverse per λ"),
      "257 calls at λ = 1, then λ = 2", "none (the kernel keys its inverse by λ)",
      twin="linear_kernel_baked_after_256_calls", witness=lambda: _o_warmup_witness(False)),
    E("ctrl_linear_no_bias", "operator", f"{RES} v", True, lambda: _o_bias_build(0.0, "Ax, J scaled by 1"),
      "x = (1, 0), λ = 10^-3", "none (bias 0)", twin="linear_relative_bias_1e_7",
      witness=lambda: _o_bias_witness(0.0)),
    E("ctrl_box_full_range", "operator", f"{RES} i/ii", True, lambda: _o_gap_build(False, "box"),
      "x1 = (0.2499, 0), x2 = (0.2501, 0)", "none (no band)", twin="box_range_misses_band",
      witness=lambda: _o_gap_witness(False)),
    E("ctrl_norm_prox_exact", "operator", f"{RES} v", True,
      lambda: _o_epsnorm_build(0.0, "prox of λ|x|"), "x = (10^-6, 0, 0), λ = 5·10^-7", "none (ε = 0)",
      twin="norm_prox_epsilon_smoothed", witness=lambda: _o_epsnorm_witness(0.0)),
    E("ctrl_log_barrier_prox_stable", "operator", f"{RES} v", True,
      lambda: _o_logbar_build(True, "log barrier prox, 2λ/(sqrt(x² + 4λ) - x) for x < 0"),
      "x = (-10^8, 1), λ = 1", "none (the cancellation-free form for x < 0)",
      twin="log_barrier_prox_cancellation", witness=lambda: _o_logbar_witness(True)),
    E("ctrl_ball_batch_float64", "operator", f"{RES} i/ii", True,
      lambda: _o_batch32_build(False, "ball, batched, float64"), "64 rows of norm ~3", "none (float64 always)",
      twin="ball_batch_float32_when_b_ge_64", witness=lambda: _o_batch32_witness(False)),
    # ---------------- steppers: plants
    E("order_half_claims_one", "stepper", "thm:main convergence at the claimed order 1 (scheme any)", False,
      _stepper(_s_order_half(1.5), scheme="any", order=1),
      "x' = -x, x0 = 1, K = 400, 1600: measured order 0.5",
      "a nudge h^{3/2} after every step: converges, at order 1/2, claims 1", witness=lambda: _s_order_witness(1.5)),
    E("cells_geomean_when_ratio_gt_10", "stepper", f"{ITER} (step h_{{k+1}} = t_{{k+1}} - t_k)", False,
      _stepper(_s_ratio_geomean(True)), "F = 0, f(x) = -x, x0 = 1, t = (0, 0.01, 1)",
      "on a partition whose neighbouring cells differ by > 10×, steps with the geometric mean of neighbours",
      witness=lambda: _s_geomean_witness(True)),
    E("time_float32_above_5000", "stepper", f"{ITER} (F(t_{{k+1}}, ·))", False,
      _stepper(_s_time32(True)), "moving half-space x_1 ≥ t - 1/2, x0 = 0, K = 6000 uniform on [0, 1]",
      "above K = 5000 the node times are accumulated in float32", witness=lambda: _s_time32_witness(True)),
    E("input_own_gauss3_ignores_U", "stepper", f"{ITER} with ∫_{{t_k}}^{{t_{{k+1}}}} u (Section 6)", False,
      _stepper(_s_gauss3(True)), "F = 0, u = 1(t > 0.3), U = max(t - 0.3, 0), t = (0, 0.25, 0.5)",
      "∫u by its own 3-point Gauss rule, the stated primitive U ignored (wrong only where u jumps)",
      witness=lambda: _s_gauss3_witness(True)),
    E("field_on_float32_copy", "stepper", f"{ITER} (h f(x_k))", False, _stepper(_s_f32(True)),
      "F = 0, f(x) = -x, x0 = 1000/3, t = (0, 0.5, 1)", "f evaluated on a float32 copy of the state",
      witness=lambda: _s_f32_witness(True)),
    E("tiny_cell_skips_resolvent", "stepper", f"{ITER} (x_{{k+1}} = J(z_k) on every cell)", False,
      _stepper(_s_tiny_cell()), "moving half-space x_1 ≥ t - 1/2, x0 = 0, t = (0, 0.6, 0.6005)",
      "cells shorter than 10^-3 skip the resolvent", witness=_s_tiny_witness),
    E("states_transposed_when_n_eq_K1", "stepper", f"{ITER} (x_k the state at t_k; x_0 = x0)", False,
      _stepper(_s_shape_guess(True)), "F = 0, f(x) = -x, x0 = (1, 2, 3), t = (0, 0.5, 1)",
      "transposes its (K + 1, n) states whenever the second axis has the grid's length (n = K + 1)",
      witness=lambda: _s_shape_witness(True)),
    E("near_uniform_grid_snapped", "stepper", f"{ITER} on the caller's partition", False,
      _stepper(_s_snap(1e-3)), "F = 0, f(x) = -x, x0 = 1, t = (0, 0.5004, 1)",
      "a partition uniform within 10^-3 is replaced by linspace", witness=lambda: _s_snap_witness(1e-3)),
    E("field_heun_when_hL_gt_half", "stepper", f"{ITER} (h f(x_k), explicit)", False, _stepper(_s_heun()),
      "F = 0, f(x) = -x (L = 1), x0 = 1, t = (0, 1)",
      "where h·L > 1/2 (L the problem's stated constant) the drift is Heun's, not h f(x_k)",
      witness=_s_heun_witness),
    # ---------------- steppers: controls
    E("ctrl_order_one_claims_one", "stepper", "thm:main convergence at the claimed order 1", True,
      _stepper(_s_order_half(2.0), scheme="any", order=1), "x' = -x, K = 400, 1600",
      "none (a nudge h², order 1)", twin="order_half_claims_one", witness=lambda: _s_order_witness(2.0)),
    E("ctrl_cells_own", "stepper", ITER, True, _stepper(_s_ratio_geomean(False)),
      "t = (0, 0.01, 1)", "none (its own cells)", twin="cells_geomean_when_ratio_gt_10",
      witness=lambda: _s_geomean_witness(False)),
    E("ctrl_time_from_grid", "stepper", ITER, True, _stepper(_s_time32(False)), "K = 6000",
      "none (times from the grid)", twin="time_float32_above_5000", witness=lambda: _s_time32_witness(False)),
    E("ctrl_input_increments", "stepper", ITER, True, _stepper(_s_gauss3(False)),
      "u = 1(t > 0.3), t = (0, 0.25, 0.5)", "none (problem.input_increments)", twin="input_own_gauss3_ignores_U",
      witness=lambda: _s_gauss3_witness(False)),
    E("ctrl_field_on_state", "stepper", ITER, True, _stepper(_s_f32(False)), "x0 = 1000/3",
      "none (f on the float64 state)", twin="field_on_float32_copy", witness=lambda: _s_f32_witness(False)),
    E("ctrl_states_first_axis", "stepper", ITER, True, _stepper(_s_shape_guess(False)), "x0 = (1, 2, 3), K = 2",
      "none (transposes only when the first axis is not the grid's)", twin="states_transposed_when_n_eq_K1",
      witness=lambda: _s_shape_witness(False)),
    E("ctrl_grid_never_snapped", "stepper", ITER, True, _stepper(_s_snap(0.0)), "t = (0, 0.5004, 1)",
      "none (snap tolerance 0)", twin="near_uniform_grid_snapped", witness=lambda: _s_snap_witness(0.0)),
    # ---------------- problems with stated constants: plants, controls
    E("stated_lipschitz_of_inner_slope", "problem", "Section 6: f Lipschitz with the stated L (contraction e^{Lt})",
      False, lambda: _p_lipschitz_build(0.5, "ball r=5, f kinked (slopes 0.5, 3), lipschitz=0.5"),
      "x1 = (3, 0), x2 = (2.5, 0): |Δf| = 1.5 > 0.5·0.5",
      "the stated lipschitz is f's slope near x0 (0.5); beyond |x_i| = 2 it is 3",
      witness=lambda: _p_lipschitz_witness(0.5), run=_run_problem),
    E("stated_phi_right_until_kink", "problem", "(A3) sup_{z ∈ dom F(s)} dist(z, dom F(t)) ≤ φ(t) - φ(s)", False,
      lambda: _p_phi_build(1.0, "ball resting then moving at speed 2, phi(t) = t"),
      "s = 1/2, t = 1: the centre moves 1, φ grows 1/2",
      "φ(t) = t matches the motion (none) before t = 1/2, half the speed after", witness=lambda: _p_phi_witness(1.0),
      run=_run_problem),
    E("stated_exact_off_1e_7", "problem", "the stated exact solution solves eq:incGen", False,
      lambda: _p_exact_build(1e-7, "x' = -x in a ball, exact e^{-t}(1 + 1e-7 t)"),
      "t = 1/2: x' + x = 10^-7 e^{-t}", "the stated exact solution off by a relative 10^-7 t",
      witness=lambda: _p_exact_witness(1e-7), run=_run_problem),
    E("ctrl_stated_lipschitz_3", "problem", "Section 6 (L = 3)", True,
      lambda: _p_lipschitz_build(3.0, "ball r=5, f kinked (slopes 0.5, 3), lipschitz=3"),
      "x1 = (3, 0), x2 = (2.5, 0)", "none (L = 3)", twin="stated_lipschitz_of_inner_slope",
      witness=lambda: _p_lipschitz_witness(3.0), run=_run_problem),
    E("ctrl_stated_phi_kinked", "problem", "(A3)", True,
      lambda: _p_phi_build(2.0, "ball resting then moving at speed 2, phi = 2 max(t - 1/2, 0)"),
      "s = 1/2, t = 1", "none (φ the motion itself)", twin="stated_phi_right_until_kink",
      witness=lambda: _p_phi_witness(2.0), run=_run_problem),
    E("ctrl_stated_exact", "problem", "the stated exact solution", True,
      lambda: _p_exact_build(0.0, "x' = -x in a ball, exact e^{-t}"), "t = 1/2", "none",
      twin="stated_exact_off_1e_7", witness=lambda: _p_exact_witness(0.0), run=_run_problem),
    # ---------------- LCP / linear systems: plants, controls
    E("lcp_enum_rejects_degenerate", "operator", f"{RES} v (Y_λx ∈ F(J_λx)), F = Mx + N_R+^2 (e:lcp)", False,
      lambda: _l_lcp_build(True, "Mx + N_R+, LCP enumeration without degenerate pivots"),
      "x = (2, -1), λ = 1: pattern {0} has w_1 = 0 exactly; fallback (2, 0) has w = (2, -1)",
      "the LCP enumerator asks z_S > 0 and w_rest > 0 strictly; no pattern passes at a degenerate point and the "
      "fallback max(x, 0) is returned", witness=lambda: _l_lcp_witness(True)),
    E("rlc_resistor_regularised_below_zero", "lcs", "p:pass i (D ⪰ 0) / i:passivity-2", False,
      lambda: _l_rlc_build(True, name="RLC, D = R - 1e-3, R = 5e-4"), "R = 5·10^-4: D = -5·10^-4",
      "the builder subtracts 10^-3 from the resistance: D < 0 for R < 10^-3",
      witness=lambda: _l_rlc_witness(True), run=_run_lcs),
    E("v_table_zero_order_hold", "lcs", "e: linear case-comp iii (v ∈ AC)", False,
      lambda: _l_vtable_build(True, "x' = -x + z, w = x + v, v held at the knots"),
      "t = 0.1 ± 10^-9: v jumps by 0.13", "v read from a table with a zero-order hold (piecewise constant)",
      witness=lambda: _l_vtable_witness(True), run=_run_lcs),
    E("ctrl_lcp_enum_degenerate_ok", "operator", f"{RES} v", True,
      lambda: _l_lcp_build(False, "Mx + N_R+, LCP enumeration"), "x = (2, -1), λ = 1",
      "none (≥ -tol)", twin="lcp_enum_rejects_degenerate", witness=lambda: _l_lcp_witness(False)),
    E("ctrl_rlc_resistor_kept", "lcs", "p:pass i", True, lambda: _l_rlc_build(False, name="RLC, D = R = 5e-4"),
      "R = 5·10^-4", "none (D = R)", twin="rlc_resistor_regularised_below_zero",
      witness=lambda: _l_rlc_witness(False), run=_run_lcs),
    E("ctrl_v_table_interpolated", "lcs", "e: linear case-comp iii", True,
      lambda: _l_vtable_build(False, "x' = -x + z, w = x + v, v interpolated"), "t = 0.1 ± 10^-9",
      "none (linear interpolation)", twin="v_table_zero_order_hold", witness=lambda: _l_vtable_witness(False),
      run=_run_lcs),
    # ---------------- moving sets: plants, controls
    E("moving_ball_projection_one_call_late", "set", f"{RES} i at F(t,·) (J_λx ∈ cl dom F(t) = S(t))", False,
      lambda: LagBall(True, "unit ball at (t, 0), projected at the previous call's t"),
      "a call at t = 0, then x = (5, 0), t = 1: J = (1, 0), not (2, 0)",
      "the set's centre is read from the previous call's time", witness=lambda: _m_lag_witness(True), run=_run_set),
    E("triangle_projected_face_by_face", "set", f"{RES} ii (J_λ = proj_S, firmly nonexpansive)", False,
      lambda: Triangle(True, "growing triangle, one pass over the faces"),
      "x = (-3, 4), t = 0: one pass gives a point that is not the nearest",
      "projection onto a polygon by one pass of half-space projections", witness=lambda: _m_tri_witness(True),
      run=_run_set),
    E("ellipse_bisection_20_steps", "set", f"{RES} i/ii (J_λ = proj_S)", False,
      lambda: Ellipse(20, "ellipse b(t) = 1 + 19t, 20 bisection steps"),
      "x = (3, 30), t = 1: J off by ~1e-5", "the secular equation bisected 20 times",
      witness=lambda: _m_ellipse_witness(20), run=_run_set),
    E("ctrl_moving_ball_current_time", "set", f"{RES} i at F(t,·)", True,
      lambda: LagBall(False, "unit ball at (t, 0)"), "a call at t = 0, then x = (5, 0), t = 1",
      "none (the centre at the call's own t)", twin="moving_ball_projection_one_call_late",
      witness=lambda: _m_lag_witness(False), run=_run_set),
    E("ctrl_triangle_nearest_candidate", "set", f"{RES} ii", True,
      lambda: Triangle(False, "growing triangle, nearest candidate"), "x = (-3, 4), t = 0",
      "none (nearest feasible candidate)", twin="triangle_projected_face_by_face",
      witness=lambda: _m_tri_witness(False), run=_run_set),
    E("ctrl_ellipse_bisection_to_the_bit", "set", f"{RES} i/ii", True,
      lambda: Ellipse(None, "ellipse b(t) = 1 + 19t, bisection to the last bit"), "x = (3, 30), t = 1",
      "none (bisection until the bracket stops shrinking)", twin="ellipse_bisection_20_steps",
      witness=lambda: _m_ellipse_witness(None), run=_run_set),
]

BY_NAME = {e.name: e for e in ENTRIES}
