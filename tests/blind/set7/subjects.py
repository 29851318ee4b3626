"""Blind set 7: planted violations of the paper's statements, of kinds the earlier set (tests/blind/plants.py)
does not hold, and lawful controls written beside them.

Written without reading verimono's checks (only the paper, README.md, docs/checks.md's list of what is checked
and the public API).  Every entry carries ``witness()``: a plain-NumPy evaluation of the entry's law at the
smallest input that shows it (the ``smallest`` field says which), returning the violation ratio (``> 1``:
violated; a control returns ``≤ 1``).  ``build()`` returns the subject as a user would hand it to verimono: an
operator, or a stepper (a function or a ``verimono.Stepper`` stating its claim).  ``twin`` names the entry
whose code differs from this one only in the arithmetic of the faulty branch: a check that fails both is a
false alarm.

Witnesses never import verimono; steppers are handed the duck-typed problem ``_P`` there.  Ratios of an
equality law are ``|a - b| / (EQ_TOL (1 + |scale|))``: round-off is ~1e-16, so a planted fault of 1e-6 is
10^3 over.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Callable

import numpy as np

EQ_TOL = 1e-9          # relative slack of an equality law in the witnesses (float64 round-off is ~1e-16)


@dataclasses.dataclass(frozen=True)
class Entry:
    name: str
    kind: str              # "operator" | "stepper"
    label: str             # the paper's statement it is about
    lawful: bool           # False: plant, True: control
    build: Callable[[], Any]
    witness: Callable[[], float]
    bug: str               # what is wrong (a control: what it is)
    smallest: str          # the smallest input that shows it
    twin: str | None = None


PROP = "prop:maxmon-resolvent-Yosida"


def _n(v):
    return float(np.linalg.norm(np.asarray(v, dtype=float)))


def _eq(a, b, scale=1.0):
    return _n(np.asarray(a, dtype=float) - np.asarray(b, dtype=float)) / (EQ_TOL * (1.0 + abs(scale)))


def _op(resolvent, dim, name, **members):
    import verimono as vm
    return vm.operator_from_resolvent(resolvent, dim, name=name, **members)


# ----------------------------------------------------------------------------------------------------
# closed forms used by the subjects and the witnesses
# ----------------------------------------------------------------------------------------------------

def _ball(x, r=1.0, c=0.0):
    """Projection onto the ball |x - c| ≤ r (the resolvent of its normal cone, every λ)."""
    d = np.asarray(x, dtype=float) - c
    nrm = float(np.linalg.norm(d))
    return c + d * (r / nrm if nrm > r else 1.0)


def _ball_contains(x, y, t=0.0, tol=None):
    """y ∈ N_B(x), B the unit ball."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    tol = 1e-9 * (1 + _n(x) + _n(y)) if tol is None else tol
    nx = _n(x)
    if nx > 1 + tol:
        return False
    if nx < 1 - tol:
        return _n(y) <= tol
    u = x / nx
    s = float(y @ u)
    return s >= -tol and _n(y - s * u) <= tol


def _soft(x, thr):
    x = np.asarray(x, dtype=float)
    return np.sign(x) * np.maximum(np.abs(x) - thr, 0.0)


def _l1_min_norm(x, t=0.0):
    return np.sign(np.asarray(x, dtype=float))


def _l1_contains(x, y, t=0.0, tol=None):
    """y ∈ ∂|x|_1: y_i = sign x_i where x_i ≠ 0, |y_i| ≤ 1 where x_i = 0."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    tol = 1e-9 * (1 + _n(x) + _n(y)) if tol is None else tol
    nz = np.abs(x) > tol
    return bool(np.all(np.abs(y[nz] - np.sign(x[nz])) <= tol) and np.all(np.abs(y[~nz]) <= 1 + tol))


def _yosida_ratio_l1(J, x, lam, t=0.0):
    """|Y_λx| ≤ |F^0 x| (prop vi) for F = ∂|·|_1: ratio |Y_λ x| / |sign x|."""
    x = np.asarray(x, dtype=float)
    Y = (x - J(x, lam, t)) / lam
    return _n(Y) / (_n(np.sign(x)) * (1 + 1e-12))


def _firm_ratio(J, x1, x2, lam, t=0.0):
    """|ΔJ|² ≤ ⟨ΔJ, Δx⟩ (prop ii, firm nonexpansiveness)."""
    a, b = np.asarray(J(np.asarray(x1, float), lam, t)), np.asarray(J(np.asarray(x2, float), lam, t))
    dj, d = a - b, np.asarray(x1, float) - np.asarray(x2, float)
    num, den = float(dj @ dj), float(dj @ d) * (1 + 1e-12)
    if num == 0.0:
        return 0.0
    return num / den if den > 0 else math.inf


def _outside_ball_ratio(p, r=1.0, c=0.0):
    """J_λx ∈ cl dom F (prop i/v): distance to the ball over the equality slack."""
    d = _n(np.asarray(p, dtype=float) - c)
    return max(d - r, 0.0) / (EQ_TOL * (1 + d))


# ---- P1 / C1: a ball projection wrong in one octant ------------------------------------------------

def _octant_factory(r_neg):
    def octant_ball(x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        if np.all(x < 0):                     # "the all-negative octant takes the cached radius"
            nrm = float(np.linalg.norm(x))
            return x * (r_neg / nrm if nrm > r_neg else 1.0)
        return _ball(x)
    return octant_ball


def _octant_build(r_neg, name):
    return lambda: _op(_octant_factory(r_neg), 3, name, project_domain=lambda x, t: _ball(x),
                       contains=_ball_contains)


def _w_octant(r_neg):
    return lambda: _outside_ball_ratio(_octant_factory(r_neg)(np.array([-2.0, -2.0, -2.0]), 1.0))


# ---- P2 / C2: soft threshold wrong in one decade of λ ------------------------------------------------

def _decade_factory(factor):
    def decade_soft(x, lam, t=0.0):
        thr = lam * factor if 1e-9 <= lam < 1e-8 else lam
        return _soft(x, thr)
    return decade_soft


def _decade_build(factor, name):
    return lambda: _op(_decade_factory(factor), 3, name, min_norm=_l1_min_norm, contains=_l1_contains)


def _w_decade(factor):
    return lambda: _yosida_ratio_l1(_decade_factory(factor), np.array([1.0, 0.0, 0.0]), 5e-9)


# ---- P3 / C3: a moving half-space whose resolvent lags in one window of t ----------------------------

def _b_half(t):
    return 0.5 * np.sin(2 * np.pi * t)


def _window_factory(lag):
    def window_halfspace(x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        s = t - lag if 0.61 <= t < 0.62 else t
        out = x.copy()
        out[0] = min(x[0], _b_half(s))
        return out
    return window_halfspace


def _hs_proj(x, t=0.0):
    x = np.asarray(x, dtype=float)
    out = x.copy()
    out[0] = min(x[0], _b_half(t))
    return out


def _hs_contains(x, y, t=0.0, tol=None):
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    tol = 1e-9 * (1 + _n(x) + _n(y)) if tol is None else tol
    b = _b_half(t)
    if x[0] > b + tol:
        return False
    if abs(y[1]) > tol:
        return False
    return y[0] >= -tol and (x[0] >= b - tol or abs(y[0]) <= tol)


def _window_build(lag, name):
    return lambda: _op(_window_factory(lag), 2, name, project_domain=_hs_proj, contains=_hs_contains)


def _w_window(lag):
    def w():
        p = _window_factory(lag)(np.array([5.0, 0.0]), 1.0, 0.615)
        return max(p[0] - _b_half(0.615), 0.0) / (EQ_TOL * 6)
    return w


# ---- P4 / C4: a ball projection with a "far away" shortcut -------------------------------------------

def _far_factory(correct):
    def far_ball(x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        nrm = float(np.linalg.norm(x))
        if nrm > 1e5:                          # "far away only the direction matters"
            s = x if correct else np.sign(x)
            return s * (1.0 / float(np.linalg.norm(s)))
        return _ball(x)
    return far_ball


def _far_build(correct, name):
    return lambda: _op(_far_factory(correct), 3, name, project_domain=lambda x, t: _ball(x),
                       contains=_ball_contains)


def _w_far(correct):
    def w():
        J = _far_factory(correct)
        u = np.array([0.8, 0.6, 0.0])
        x1, x2 = (1e5 - 1e-3) * u, (1e5 + 1e-3) * u                  # either side of |x| = 1e5
        return _firm_ratio(J, x1, x2, 1.0)
    return w


# ---- P5: integer input takes the box -----------------------------------------------------------------

def int_box(x, lam, t=0.0):
    x = np.asarray(x)
    if x.dtype.kind in "iu":                    # "integers: clip them, it is cheaper"
        return np.clip(x, -1, 1).astype(float)
    return _ball(x)


def _w_int_box():
    return _outside_ball_ratio(int_box(np.array([2, 2], dtype=np.int64), 1.0))


# ---- P6: strided input takes twice the step ----------------------------------------------------------

def strided_soft(x, lam, t=0.0):
    x = np.asarray(x)
    thr = lam if x.flags.c_contiguous else 2 * lam     # a "copy avoided" branch with the step doubled
    return _soft(x, thr)


def _w_strided():
    buf = np.array([3.0, 9.0, 0.5, 9.0, -2.0, 9.0])
    a, b = strided_soft(buf[::2], 1.0), strided_soft(np.ascontiguousarray(buf[::2]), 1.0)
    return _eq(a, b, _n(buf[::2]))


# ---- P7 / C7: a batched resolvent that takes the first row's step for every row -------------------------

def _batched_factory(rowwise):
    def batched_soft(X, lams, ts):
        X = np.asarray(X, dtype=float)
        lams = np.asarray(lams, dtype=float)
        thr = lams[:, None] if rowwise else lams[0]
        return np.sign(X) * np.maximum(np.abs(X) - thr, 0.0)
    return batched_soft


def _batched_build(rowwise, name):
    return lambda: _op(_batched_factory(rowwise), 3, name, min_norm=_l1_min_norm, contains=_l1_contains,
                       batched=True)


def _w_batched(rowwise):
    def w():
        X = np.array([[3.0, 0.0, 0.0], [3.0, 0.0, 0.0]])
        out = _batched_factory(rowwise)(X, np.array([1.0, 2.0]), np.zeros(2))
        return _eq(out[1], _soft(X[1], 2.0), 3.0)
    return w


# ---- P9 / C9: a skew matrix's Cayley transform instead of its resolvent --------------------------------

S_SKEW = np.array([[0.0, 1.0], [-1.0, 0.0]])


def cayley_skew(x, lam, t=0.0):
    x = np.asarray(x, dtype=float)
    I2 = np.eye(2)
    return (I2 - lam * S_SKEW) @ np.linalg.solve(I2 + lam * S_SKEW, x)   # 2J - I: an isometry


def skew_resolvent(x, lam, t=0.0):
    x = np.asarray(x, dtype=float)
    I2 = np.eye(2)
    return np.eye(2) @ np.linalg.solve(I2 + lam * S_SKEW, x)


def _skew_contains(x, y, t=0.0, tol=None):
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    tol = 1e-9 * (1 + _n(x) + _n(y)) if tol is None else tol
    return _n(y - S_SKEW @ x) <= tol


def _skew_build(J, name):
    return lambda: _op(J, 2, name, min_norm=lambda x, t: S_SKEW @ np.asarray(x, dtype=float),
                       contains=_skew_contains)


def _w_skew(J):
    return lambda: _firm_ratio(J, np.array([1.0, 0.0]), np.array([0.0, 0.0]), 1.0)


# ---- P10: a correct resolvent whose own yosida member is off by a factor 2 -------------------------------

def _yosida_override_build():
    import verimono as vm

    class HalfYosidaL1(vm.Operator):
        static = True
        full_domain = True

        def resolvent(self, x, lam, t=0.0):
            return _soft(x, lam)

        def yosida(self, x, lam, t=0.0):
            x = np.asarray(x, dtype=float)
            return (x - self.resolvent(x, lam, t)) / (2 * lam)       # the factor: Y_λ = (x - J_λx)/λ

        def min_norm(self, x, t=0.0):
            return _l1_min_norm(x)

        def contains(self, x, y, t=0.0, tol=None):
            return _l1_contains(x, y, t, tol)

    return HalfYosidaL1(3, name="yosida member halved")


def _w_yosida_override():
    x, lam = np.array([3.0, 0.0, 0.0]), 1.0
    Y = (x - _soft(x, lam)) / (2 * lam)         # what the member returns: (0.5, 0, 0) ∉ ∂|·|_1(J x) = {1}×[-1,1]²
    return abs(Y[0] - 1.0) / EQ_TOL


# ---- P11: a moving ball whose projection lags in t by 1e-3 --------------------------------------------

def _c_ball(t):
    return np.array([0.5 * np.cos(2 * t), 0.5 * np.sin(2 * t)])


def lagging_ball(x, lam, t=0.0):
    return _ball(x, 1.0, _c_ball(t - 1e-3))


def _moving_ball_proj(x, t=0.0):
    return _ball(x, 1.0, _c_ball(t))


def _w_lagging_ball():
    return _outside_ball_ratio(lagging_ball(np.array([3.0, 0.0]), 1.0, 0.5), 1.0, _c_ball(0.5))


# ---- P12 / C12: the minimal section of ∂|·|_1 with copysign (wrong at zero coordinates only) --------------

def copysign_min_norm(x, t=0.0):
    return np.copysign(1.0, np.asarray(x, dtype=float))


def _min_norm_build(mn, name):
    return lambda: _op(lambda x, lam, t=0.0: _soft(x, lam), 3, name, min_norm=mn, contains=_l1_contains)


def _w_min_norm(mn):
    # F^0 = proj(0, F(x)); at x = (1, 0, 0) the least element of ∂|x|_1 is (1, 0, 0)
    return lambda: _n(mn(np.array([1.0, 0.0, 0.0]))) / (1.0 * (1 + 1e-12))


# ---- P13 / C13: J_λ of F(x) = Mx + N_{R^2_+}(x), an LCP solved by enumeration, wrong in one pattern ---------

M_LCP = np.array([[2.0, 1.0], [-1.0, 1.0]])         # M + M^T = diag(4, 2) ≻ 0: F maximal monotone


def _lcp_factory(broken):
    def lcp_resolvent(x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        A = np.eye(2) + lam * M_LCP                   # z ≥ 0, w = A z - x ≥ 0, z ⊥ w
        tol = 1e-12 * (1 + float(np.abs(x).max()))
        for S in ((), (0,), (1,), (0, 1)):
            z = np.zeros(2)
            if S:
                idx = list(S)
                if broken and S == (0,):
                    z[0] = x[0]                       # the λM_00 term forgotten in this pattern only
                else:
                    z[idx] = np.linalg.solve(A[np.ix_(idx, idx)], x[idx])
            w = A @ z - x
            if np.all(z >= -tol) and np.all(w >= -tol):
                return np.maximum(z, 0.0)
        if broken:                                    # "no pattern fits: fall back to the careful solver", which
            return _lcp_factory(False)(x, lam, t)     # hides the broken pattern wherever its candidate is infeasible
        raise RuntimeError("no complementarity pattern fits")
    return lcp_resolvent


def _lcp_min_norm(x, t=0.0):
    x = np.asarray(x, dtype=float)
    m = M_LCP @ x
    return np.where(x > 0, m, np.minimum(m, 0.0))


def _lcp_contains(x, y, t=0.0, tol=None):
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    tol = 1e-9 * (1 + _n(x) + _n(y)) if tol is None else tol
    if np.any(x < -tol):
        return False
    r = y - M_LCP @ x
    pos = x > tol
    return bool(np.all(np.abs(r[pos]) <= tol) and np.all(r[~pos] <= tol))


def _lcp_build(broken, name):
    return lambda: _op(_lcp_factory(broken), 2, name, min_norm=_lcp_min_norm, contains=_lcp_contains,
                       project_domain=lambda x, t: np.maximum(np.asarray(x, dtype=float), 0.0))


def _w_lcp(broken):
    def w():
        x, lam = np.array([1.0, -5.0]), 1.0
        z = _lcp_factory(broken)(x, lam)
        y = (x - z) / lam
        r = y - M_LCP @ z                            # Y_λx ∈ F(J_λx): r_0 = 0 where z_0 > 0
        return abs(r[0]) / (EQ_TOL * (1 + _n(y))) if z[0] > 0 else 0.0
    return w


# ---- P14: soft threshold that skips "negligible" steps --------------------------------------------------

def tiny_step_soft(x, lam, t=0.0):
    x = np.asarray(x, dtype=float)
    if lam < 1e-12:                               # "the step is below round-off: nothing to do"
        return x.copy()
    return _soft(x, lam)


def _w_tiny_step():
    x, lam = np.array([1.0, 0.0, 0.0]), 1e-13
    Y = (x - tiny_step_soft(x, lam)) / lam         # 0, while ∂|·|_1(J x) ∋ only y_0 = 1
    return abs(Y[0] - 1.0) / 1e-3                  # (x - J)/λ carries eps|x|/λ ≈ 2e-3 of round-off here


# ---- P15 / C15: prox of λ|x|_2 (group shrinkage) ----------------------------------------------------------

def _shrink_factory(guarded):
    def group_shrink(x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        nrm = float(np.linalg.norm(x))
        if guarded:
            return x * (max(nrm - lam, 0.0) / nrm) if nrm > 0 else x * 0.0
        with np.errstate(invalid="ignore", divide="ignore"):
            return x / nrm * max(nrm - lam, 0.0)   # 0/0 at x = 0
    return group_shrink


def _shrink_min_norm(x, t=0.0):
    x = np.asarray(x, dtype=float)
    nrm = float(np.linalg.norm(x))
    return x / nrm if nrm > 0 else x * 0.0


def _shrink_contains(x, y, t=0.0, tol=None):
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    tol = 1e-9 * (1 + _n(x) + _n(y)) if tol is None else tol
    nrm = _n(x)
    if nrm <= tol:
        return _n(y) <= 1 + tol
    return _n(y - x / nrm) <= tol


def _shrink_build(guarded, name):
    return lambda: _op(_shrink_factory(guarded), 3, name, min_norm=_shrink_min_norm, contains=_shrink_contains)


def _w_shrink(guarded):
    def w():
        p = _shrink_factory(guarded)(np.zeros(3), 1.0)
        return math.inf if not np.all(np.isfinite(p)) else _n(p) / EQ_TOL
    return w


# ---- P16: a membership test that accepts everything ------------------------------------------------------

def _accepts_everything_build():
    return _op(lambda x, lam, t=0.0: _soft(x, lam), 3, "contains accepts everything",
               min_norm=_l1_min_norm, contains=lambda x, y, t=0.0: True)


def _w_accepts_everything():
    # the graph it declares is all of R^3 x R^3: (x, y) = (1,0,0), (5,5,5) and the graph point (0, 0) of ∂|·|_1
    # are not monotone: ⟨y - 0, x - 0⟩ ≥ 0 holds, but with (x', y') = (2,0,0), (-5,-5,-5): ⟨y - y', x - x'⟩ = -10
    x, y, x2, y2 = np.array([1.0, 0, 0]), np.array([5.0, 5, 5]), np.array([2.0, 0, 0]), np.array([-5.0, -5, -5])
    return -float((y - y2) @ (x - x2)) / EQ_TOL


# ---- P17: a box whose project_domain is the radial retraction ----------------------------------------------

def _box_radial_build():
    return _op(lambda x, lam, t=0.0: np.clip(np.asarray(x, dtype=float), -1.0, 1.0), 3,
               "box with a radial project_domain",
               project_domain=lambda x, t: np.asarray(x, dtype=float) / max(float(np.abs(x).max()), 1.0))


def _w_box_radial():
    x = np.array([2.0, 0.5, 0.0])
    P, J = x / max(np.abs(x).max(), 1.0), np.clip(x, -1, 1)     # J ∈ dom F, so |x - Px| ≤ |x - Jx| must hold
    return _n(x - P) / (_n(x - J) * (1 + 1e-12))


# ---- P18: a prox whose declared g is halved far out ---------------------------------------------------------

def _l1_far_halved(x):
    x = np.asarray(x, dtype=float)
    s = float(np.abs(x).sum())
    return s if float(np.abs(x).max()) <= 10.0 else 0.5 * s


def _value_far_build():
    import verimono as vm
    return vm.operator_from_prox(lambda x, lam: _soft(x, lam), value=_l1_far_halved, shape=3,
                                 name="l1 prox, g halved beyond 10")


def _w_value_far():
    x, lam, z = np.array([1.0, 0, 0]), 1.0, np.array([20.0, 0, 0])
    p = _soft(x, lam)                         # ⟨x - p, z - p⟩ ≤ λ (g(z) - g(p))
    return float((x - p) @ (z - p)) / (lam * (_l1_far_halved(z) - _l1_far_halved(p)))


# ---- P19: ∂(c(t)|x|_2) whose min_norm forgets t ----------------------------------------------------------

def _c_t(t):
    return 1.0 + t


def _ct_resolvent(x, lam, t=0.0):
    return _shrink_factory(True)(x, lam * _c_t(t))


def _ct_contains(x, y, t=0.0, tol=None):
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    tol = 1e-9 * (1 + _n(x) + _n(y)) if tol is None else tol
    nrm = _n(x)
    if nrm <= tol:
        return _n(y) <= _c_t(t) + tol
    return _n(y - _c_t(t) * x / nrm) <= tol


def _min_norm_t_build():
    return _op(_ct_resolvent, 2, "min_norm of c(t)|x| at t = 0", min_norm=lambda x, t: _shrink_min_norm(x),
               contains=_ct_contains)


def _w_min_norm_t():
    x, t = np.array([1.0, 0.0]), 1.0
    return _n(_shrink_min_norm(x) - _c_t(t) * x) / EQ_TOL


# ----------------------------------------------------------------------------------------------------
# steppers
# ----------------------------------------------------------------------------------------------------

def _z(problem, x, h, dU, k):
    z = x + (h * np.asarray(problem.f(x), dtype=float) if problem.f is not None else 0.0)
    if dU is not None:
        z = z + dU[k - 1]
    return z


def proximal(problem, t_grid):
    """The paper's scheme eq:iteration, correct (the reference of every stepper witness)."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        x.append(problem.operator.resolvent(_z(problem, x[-1], h, dU, k), h, t_grid[k]))
    return np.array(x)


def h_next_cell(problem, t_grid):
    """The step of cell k taken as the width of cell k + 1 (the last cell its own)."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    hs = np.diff(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = hs[min(k, len(hs) - 1)]
        x.append(problem.operator.resolvent(_z(problem, x[-1], h, dU, k), h, t_grid[k]))
    return np.array(x)


def ctrl_h_this_cell(problem, t_grid):
    """The same structure as h_next_cell, indexing the step of cell k correctly."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    hs = np.diff(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = hs[min(k - 1, len(hs) - 1)]
        x.append(problem.operator.resolvent(_z(problem, x[-1], h, dU, k), h, t_grid[k]))
    return np.array(x)


def _input_steps(last_too):
    def stepper(problem, t_grid):
        t_grid = np.asarray(t_grid, dtype=float)
        dU = problem.input_increments(t_grid)
        K = len(t_grid) - 1
        x = [np.asarray(problem.x0, dtype=float)]
        for k in range(1, K + 1):
            h = t_grid[k] - t_grid[k - 1]
            z = x[-1] + (h * np.asarray(problem.f(x[-1]), dtype=float) if problem.f is not None else 0.0)
            if dU is not None and (k < K or last_too):
                z = z + dU[k - 1]
            x.append(problem.operator.resolvent(z, h, t_grid[k]))
        return np.array(x)
    return stepper


input_lost_last_step = _input_steps(False)
input_lost_last_step.__name__ = "input_lost_last_step"
input_lost_last_step.__doc__ = "∫u skipped on the last cell only (a loop bound off by one for the input)."
ctrl_input_every_step = _input_steps(True)
ctrl_input_every_step.__name__ = "ctrl_input_every_step"


def field_rolled(problem, t_grid):
    """f evaluated at np.roll(x, 1): right for n = 1 only."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        z = x[-1] + (h * np.asarray(problem.f(np.roll(x[-1], 1)), dtype=float) if problem.f is not None else 0.0)
        if dU is not None:
            z = z + dU[k - 1]
        x.append(problem.operator.resolvent(z, h, t_grid[k]))
    return np.array(x)


def float32_states(problem, t_grid):
    """Keeps its states in float32 (returns them as float64: the precision is not the one it claims)."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        nxt = problem.operator.resolvent(_z(problem, x[-1], h, dU, k), h, t_grid[k])
        x.append(np.asarray(nxt, dtype=np.float32).astype(np.float64))
    return np.array(x)


def float32_times(problem, t_grid):
    """Reads the partition as float32: the times and steps it uses are rounded to 24 bits."""
    t32 = np.asarray(t_grid, dtype=np.float32).astype(np.float64)
    dU = problem.input_increments(np.asarray(t_grid, dtype=float))
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t32)):
        h = t32[k] - t32[k - 1]
        x.append(problem.operator.resolvent(_z(problem, x[-1], h, dU, k), h, t32[k]))
    return np.array(x)


def input_only_with_field(problem, t_grid):
    """∫u added only inside the branch of f: a problem with an input and no field loses the input."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        z = x[-1]
        if problem.f is not None:
            z = z + h * np.asarray(problem.f(x[-1]), dtype=float)
            if dU is not None:
                z = z + dU[k - 1]
        x.append(problem.operator.resolvent(z, h, t_grid[k]))
    return np.array(x)


def zero_start_shortcut(problem, t_grid):
    """Returns zeros when x0 = 0 ("the origin is an equilibrium")."""
    t_grid = np.asarray(t_grid, dtype=float)
    x0 = np.asarray(problem.x0, dtype=float)
    if not np.any(x0):
        return np.zeros((len(t_grid),) + x0.shape)
    return proximal(problem, t_grid)


def first_step_no_field(problem, t_grid):
    """The field f skipped on the first cell (the loop's f starts "after the initial projection")."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        z = x[-1] + (h * np.asarray(problem.f(x[-1]), dtype=float) if (problem.f is not None and k > 1) else 0.0)
        if dU is not None:
            z = z + dU[k - 1]
        x.append(problem.operator.resolvent(z, h, t_grid[k]))
    return np.array(x)


def _uniform_h(true_h):
    def stepper(problem, t_grid):
        t_grid = np.asarray(t_grid, dtype=float)
        dU = problem.input_increments(t_grid)
        K = len(t_grid) - 1
        x = [np.asarray(problem.x0, dtype=float)]
        for k in range(1, K + 1):
            h = (t_grid[k] - t_grid[k - 1]) if true_h else (t_grid[-1] - t_grid[0]) / K
            x.append(problem.operator.resolvent(_z(problem, x[-1], h, dU, k), h, t_grid[k]))
        return np.array(x)
    return stepper


any_uniform_h = _uniform_h(False)
any_uniform_h.__name__ = "any_uniform_h"
any_uniform_h.__doc__ = "Claims scheme='any', order 1; every step is the mean step T/K whatever the partition."
ctrl_any_true_h = _uniform_h(True)
ctrl_any_true_h.__name__ = "ctrl_any_true_h"


def rounded_time(problem, t_grid):
    """The operator taken at t_{k+1} rounded to 3 decimals (a cache key)."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        x.append(problem.operator.resolvent(_z(problem, x[-1], h, dU, k), h, round(float(t_grid[k]), 3)))
    return np.array(x)


def _stepper_build(fn, **claim):
    def build():
        import verimono as vm
        return vm.Stepper(fn, name=fn.__name__, **claim) if claim else fn
    return build


# ---- the duck-typed problems of the stepper witnesses ---------------------------------------------------

class _Op:
    def __init__(self, dim, J):
        self.dim, self._J, self.name = dim, J, "witness operator"

    def resolvent(self, x, lam, t=0.0):
        return np.asarray(self._J(np.asarray(x, dtype=float), lam, t), dtype=float)


class _P:
    def __init__(self, operator, x0, T, f=None, U=None):
        self.operator, self.x0, self.T, self.f, self.U = operator, np.asarray(x0, dtype=float), float(T), f, U
        self.dim = operator.dim

    def input_increments(self, t):
        if self.U is None:
            return None
        return np.diff(np.array([np.asarray(self.U(s), dtype=float) for s in t]), axis=0)


_BALL2 = _Op(2, lambda x, lam, t: _ball(x, 1.0, _c_ball(t)))
_FREE2 = _Op(2, lambda x, lam, t: x)
_TX = _Op(1, lambda x, lam, t: _shrink_factory(True)(x, lam * t))     # ∂(t|x|), n = 1


def _f_lin(x):
    return np.array([-0.5 * x[0] + 0.3 * x[1], 0.2 * x[0] - x[1]])[: len(x)]


def _U2(t):
    return np.array([np.sin(t), 1 - np.cos(2 * t)])


def _residual(stepper, prob, t_grid):
    """eq:iteration on t_grid: the stepper's iterates against the scheme's own, worst relative gap."""
    X, R = np.asarray(stepper(prob, t_grid), dtype=float), proximal(prob, t_grid)
    if X.shape != R.shape:
        return math.inf
    return max(_eq(a, b, _n(b)) for a, b in zip(X, R))


_GRADED = 2.0 * (np.arange(9) / 8) ** 2
_UNIF = np.linspace(0.0, 2.0, 9)


def _w_step(fn, prob, grid):
    return lambda: _residual(fn, prob, grid)


def _w_any_uniform(fn):
    def w():
        # x' = -x (F = 0, f = -x) from 1: the error at T on graded partitions must fall at order 1
        prob = _P(_Op(1, lambda x, lam, t: x), [1.0], 1.0, f=lambda x: -x)
        errs = []
        for K in (16, 64):
            g = (np.arange(K + 1) / K) ** 2
            X = np.asarray(fn(prob, g))
            errs.append(float(np.max(np.abs(X[:, 0] - np.exp(-g)))))
        return errs[1] / (errs[0] / 2)                   # order 1 over a 4x refinement: errs[1] ≈ errs[0]/4
    return w


# ----------------------------------------------------------------------------------------------------
# the set
# ----------------------------------------------------------------------------------------------------

_P_FU = _P(_BALL2, [0.5, 0.0], 2.0, f=_f_lin, U=_U2)
_P_U = _P(_BALL2, [0.5, 0.0], 2.0, U=_U2)
_P_ZERO = _P(_FREE2, [0.0, 0.0], 2.0, U=_U2)
_P_TX = _P(_TX, [1.0], 2.0)

ENTRIES = [
    # ---- operators: plants
    Entry("octant_radius_1_02", "operator", f"{PROP} i/v (J_λx ∈ cl dom F)", False, _octant_build(1.02, "octant radius 1.02"),
          _w_octant(1.02), "ball projection with radius 1.02 when every coordinate is negative",
          "x = (-2, -2, -2), any λ", "ctrl_octant_radius_1"),
    Entry("soft_threshold_decade_1e-9", "operator", f"{PROP} vi (|Y_λx| ≤ |F^0x|) / v", False,
          _decade_build(1.5, "soft threshold 1.5λ on [1e-9, 1e-8)"), _w_decade(1.5),
          "threshold 1.5λ for λ in [1e-9, 1e-8) only", "x = (1, 0, 0), λ = 5e-9", "ctrl_soft_threshold_decade"),
    Entry("halfspace_lag_in_t_window", "operator", f"{PROP} i/v (J_λx ∈ cl dom F(t))", False,
          _window_build(0.05, "half-space lagging on [0.61, 0.62)"), _w_window(0.05),
          "moving half-space x1 ≤ sin(2πt)/2 projected at t - 0.05 for t in [0.61, 0.62) only",
          "x = (5, 0), t = 0.615", "ctrl_halfspace_window"),
    Entry("ball_far_sign_shortcut", "operator", f"{PROP} ii/v (firm, Y_λx ∈ F(J_λx))", False,
          _far_build(False, "ball, sign shortcut beyond 1e5"), _w_far(False),
          "for |x| > 1e5 returns sign(x)/|sign(x)| (on the sphere, not the projection)",
          "x = (1e5 ∓ 1e-3)(0.8, 0.6, 0), λ = 1", "ctrl_ball_far_branch"),
    Entry("int_input_box_clip", "operator", f"{PROP} i/v (J_λx ∈ cl dom F), input form", False,
          lambda: _op(int_box, 2, "integer input clipped to the box", project_domain=lambda x, t: _ball(x),
                      contains=_ball_contains), _w_int_box,
          "integer arrays are clipped to [-1, 1]^2 instead of projected on the unit disc", "x = (2, 2) as int64"),
    Entry("strided_input_double_step", "operator", f"{PROP} ii (J_λ a function of x's values)", False,
          lambda: _op(strided_soft, 3, "soft threshold 2λ on strided input"), _w_strided,
          "non-contiguous input thresholded at 2λ", "x = (3, 0.5, -2) as a stride-2 view, λ = 1"),
    Entry("batched_first_row_step", "operator", f"{PROP} ii/v (J_λ at each row's λ)", False,
          _batched_build(False, "batched soft threshold, row 0's λ"), _w_batched(False),
          "batched=True resolvent thresholds every row at lams[0]", "rows (3,0,0),(3,0,0) at λ = 1, 2",
          "ctrl_batched_rowwise"),
    Entry("cayley_transform_of_skew", "operator", f"{PROP} ii (firmly nonexpansive) / iv (Y_λ monotone)", False,
          _skew_build(cayley_skew, "Cayley transform of a skew matrix"), _w_skew(cayley_skew),
          "returns (I - λS)(I + λS)^{-1}x = 2J_λx - x: an isometry, nonexpansive, not firmly",
          "x1 = (1, 0), x2 = 0, λ = 1", "ctrl_skew_resolvent"),
    Entry("yosida_member_halved", "operator", f"{PROP} v (Y_λx = (x - J_λx)/λ ∈ F(J_λx))", False,
          _yosida_override_build, _w_yosida_override,
          "an Operator subclass whose own yosida() divides by 2λ (resolvent, min_norm, contains right)",
          "x = (3, 0, 0), λ = 1"),
    Entry("moving_ball_lags_1e-3", "operator", f"{PROP} i/v (J_λx ∈ cl dom F(t))", False,
          lambda: _op(lagging_ball, 2, "moving ball projected at t - 1e-3", project_domain=_moving_ball_proj),
          _w_lagging_ball, "ball centred at c(t) = (cos 2t, sin 2t)/2 projected onto at c(t - 1e-3)",
          "x = (3, 0), t = 0.5"),
    Entry("l1_min_norm_copysign", "operator", "minimal section F^0 = proj(0, F(x)) (min_norm_least)", False,
          _min_norm_build(copysign_min_norm, "l1, min_norm by copysign"), _w_min_norm(copysign_min_norm),
          "F^0 of ∂|·|_1 as copysign(1, x): ±1 instead of 0 at zero coordinates (in F(x), not least)",
          "x = (1, 0, 0)", "ctrl_l1_min_norm_sign"),
    Entry("lcp_pattern_0_forgets_M", "operator", f"{PROP} v (Y_λx ∈ F(J_λx)) for F = Mx + N_R+^2 (e:lcp)", False,
          _lcp_build(True, "LCP resolvent, pattern {0} wrong"), _w_lcp(True),
          "enumerated LCP: in the pattern z0 > 0, z1 = 0 it takes z0 = x0 (λM_00 forgotten); where that candidate is infeasible a correct fallback answers, so it is wrong exactly on x0 > 0, x1 ≤ -λx0, and never raises",
          "x = (1, -5), λ = 1", "ctrl_lcp_enumerated"),
    Entry("soft_threshold_skips_tiny_steps", "operator", f"{PROP} v/vi (Y_λx ∈ F(J_λx), |Y_λx| → |F^0x|)", False,
          lambda: _op(tiny_step_soft, 3, "soft threshold, identity for λ < 1e-12", min_norm=_l1_min_norm,
                      contains=_l1_contains), _w_tiny_step,
          "returns x unchanged when λ < 1e-12 (the shift λ is representable: |x| = 1 has eps 2e-16)",
          "x = (1, 0, 0), λ = 1e-13"),
    Entry("group_shrink_nan_at_zero", "operator", f"{PROP} i (dom J_λ = R^n)", False,
          _shrink_build(False, "group shrinkage, 0/0 at 0"), _w_shrink(False),
          "prox of λ|x|_2 as x/|x|·max(|x| - λ, 0): NaN at x = 0", "x = 0", "ctrl_group_shrink_guarded"),
    Entry("contains_accepts_everything", "operator", "(A1) graph of F(t,·) monotone (the declared membership)", False,
          _accepts_everything_build, _w_accepts_everything,
          "correct soft threshold and min_norm; contains(x, y) is True for every pair",
          "(1,0,0),(5,5,5) and (2,0,0),(-5,-5,-5) both declared in the graph"),
    Entry("box_project_domain_radial", "operator", "projection onto cl dom F (e:hausdorff conseq, (A3))", False,
          _box_radial_build, _w_box_radial,
          "box [-1,1]^3: resolvent clips (right); project_domain retracts radially (in the box, not nearest)",
          "x = (2, 0.5, 0)"),
    Entry("prox_value_halved_far", "operator", "prox: p minimises g(z) + |z - x|²/(2λ) (prox_inequality)", False,
          _value_far_build, _w_value_far,
          "soft threshold declared with g = |x|_1 inside |x|_∞ ≤ 10 and |x|_1/2 beyond (not convex)",
          "x = (1, 0, 0), λ = 1, z = (20, 0, 0)"),
    Entry("min_norm_forgets_time", "operator", "minimal section F^0(t,x) ∈ F(t,x) (min_norm_in_graph)", False,
          _min_norm_t_build, _w_min_norm_t,
          "F = ∂((1+t)|x|_2): resolvent and contains take c(t), min_norm returns x/|x| (c(0))",
          "x = (1, 0), t = 1"),
    # ---- steppers: plants
    Entry("h_of_next_cell", "stepper", "eq:iteration (step h_{k+1} = t_{k+1} - t_k)", False,
          _stepper_build(h_next_cell), _w_step(h_next_cell, _P_FU, _GRADED),
          "cell k stepped with the width of cell k+1", "graded 8-cell grid on [0, 2], moving disc with f, u",
          "ctrl_h_this_cell"),
    Entry("input_lost_last_step", "stepper", "eq:iteration with ∫_{t_K-1}^{t_K} u (Section 6)", False,
          _stepper_build(input_lost_last_step), _w_step(input_lost_last_step, _P_U, _UNIF),
          "∫u skipped on the last cell only", "uniform 8-cell grid, moving disc with u", "ctrl_input_every_step"),
    Entry("field_rolled_n_ge_2", "stepper", "eq:iteration (f(x_k))", False,
          _stepper_build(field_rolled), _w_step(field_rolled, _P_FU, _UNIF),
          "f evaluated at np.roll(x_k, 1): right for n = 1 only", "n = 2, f = linear non-symmetric"),
    Entry("float32_states", "stepper", "eq:iteration (iterates at the precision returned)", False,
          _stepper_build(float32_states), _w_step(float32_states, _P_FU, _UNIF),
          "iterates rounded to float32 and returned as float64", "any step with a non-float32 state"),
    Entry("float32_times", "stepper", "eq:iteration (F(t_{k+1}), step h_{k+1})", False,
          _stepper_build(float32_times), _w_step(float32_times, _P_TX, np.linspace(0, 2.0, 11) + 0.0),
          "times and steps read through float32", "∂(t|x|), n = 1, x0 = 1, uniform 10 cells on [0, 2]"),
    Entry("input_only_with_field", "stepper", "eq:iteration with ∫u (Section 6, l:extinput)", False,
          _stepper_build(input_only_with_field), _w_step(input_only_with_field, _P_U, _UNIF),
          "∫u added inside the f branch: lost when the problem has u but no f", "moving disc with u, no f"),
    Entry("zero_start_shortcut", "stepper", "eq:iteration from x0 = 0", False,
          _stepper_build(zero_start_shortcut), _w_step(zero_start_shortcut, _P_ZERO, _UNIF),
          "returns zeros whenever x0 = 0", "F = 0, u = (cos t, 2 sin 2t), x0 = 0"),
    Entry("first_step_no_field", "stepper", "eq:iteration (f(x_0) on the first cell)", False,
          _stepper_build(first_step_no_field), _w_step(first_step_no_field, _P_FU, _UNIF),
          "f skipped on the first cell only", "moving disc with f, first cell"),
    Entry("any_order1_mean_step", "stepper", "thm:main (convergence on every partition as |Δ| → 0), order 1",
          False, _stepper_build(any_uniform_h, scheme="any", order=1), _w_any_uniform(any_uniform_h),
          "claims scheme='any', order 1; steps every cell with T/K", "x' = -x, graded grids K = 16, 64",
          "ctrl_any_true_h"),
    Entry("time_rounded_3_decimals", "stepper", "eq:iteration (F(t_{k+1}, ·))", False,
          _stepper_build(rounded_time), _w_step(rounded_time, _P_FU, _GRADED),
          "the operator at round(t_{k+1}, 3)", "graded 8-cell grid (t_1 = 0.03125)"),
    # ---- controls
    Entry("ctrl_octant_radius_1", "operator", f"{PROP} i/v", True, _octant_build(1.0, "octant radius 1"),
          _w_octant(1.0), "the octant branch with radius 1 (a lawful projection)", "x = (-2, -2, -2)",
          "octant_radius_1_02"),
    Entry("ctrl_soft_threshold_decade", "operator", f"{PROP} vi", True,
          _decade_build(1.0, "soft threshold, decade branch 1.0λ"), _w_decade(1.0),
          "the decade branch with the threshold λ", "x = (1, 0, 0), λ = 5e-9", "soft_threshold_decade_1e-9"),
    Entry("ctrl_halfspace_window", "operator", f"{PROP} i/v", True, _window_build(0.0, "half-space window, no lag"),
          _w_window(0.0), "the window branch at t itself", "x = (5, 0), t = 0.615", "halfspace_lag_in_t_window"),
    Entry("ctrl_ball_far_branch", "operator", f"{PROP} ii/v", True, _far_build(True, "ball, far branch x/|x|"),
          _w_far(True), "the far branch returns x/|x| (the projection)", "x1, x2 either side of 1e5",
          "ball_far_sign_shortcut"),
    Entry("ctrl_batched_rowwise", "operator", f"{PROP} ii/v", True, _batched_build(True, "batched soft threshold"),
          _w_batched(True), "batched=True, each row at its own λ", "rows at λ = 1, 2", "batched_first_row_step"),
    Entry("ctrl_skew_resolvent", "operator", f"{PROP} ii/iv", True, _skew_build(skew_resolvent, "skew resolvent"),
          _w_skew(skew_resolvent), "(I + λS)^{-1}x: the resolvent of the skew (monotone) matrix",
          "x1 = (1, 0), x2 = 0, λ = 1", "cayley_transform_of_skew"),
    Entry("ctrl_l1_min_norm_sign", "operator", "minimal section", True,
          _min_norm_build(_l1_min_norm, "l1, min_norm by sign"), _w_min_norm(_l1_min_norm),
          "F^0 = sign(x)", "x = (1, 0, 0)", "l1_min_norm_copysign"),
    Entry("ctrl_lcp_enumerated", "operator", f"{PROP} v", True, _lcp_build(False, "LCP resolvent"), _w_lcp(False),
          "every pattern solved with A_SS", "x = (1, -5), λ = 1", "lcp_pattern_0_forgets_M"),
    Entry("ctrl_group_shrink_guarded", "operator", f"{PROP} i", True, _shrink_build(True, "group shrinkage"),
          _w_shrink(True), "x·max(|x| - λ, 0)/|x|, 0 at 0", "x = 0", "group_shrink_nan_at_zero"),
    Entry("ctrl_h_this_cell", "stepper", "eq:iteration", True, _stepper_build(ctrl_h_this_cell),
          _w_step(ctrl_h_this_cell, _P_FU, _GRADED), "the step of cell k indexed right", "graded grid",
          "h_of_next_cell"),
    Entry("ctrl_input_every_step", "stepper", "eq:iteration", True, _stepper_build(ctrl_input_every_step),
          _w_step(ctrl_input_every_step, _P_U, _UNIF), "the same loop, ∫u on every cell", "uniform grid",
          "input_lost_last_step"),
    Entry("ctrl_any_true_h", "stepper", "thm:main, order 1", True,
          _stepper_build(ctrl_any_true_h, scheme="any", order=1), _w_any_uniform(ctrl_any_true_h),
          "claims scheme='any', order 1; the true step of every cell", "graded grids", "any_order1_mean_step"),
]

BY_NAME = {e.name: e for e in ENTRIES}
