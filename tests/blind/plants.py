"""A blind set of planted violations (and lawful controls) of the paper's statements.

Written apart from verimono's checks: every entry carries ``measure()``, a plain-NumPy witness search that
returns the violation ratio of the law the entry is about (``> 1``: violated; a control returns ``≤ 1``).
``build()`` returns the subject as a user would hand it to verimono: an operator, or for a stepper a pair
``(stepper, extra_problems)`` (``extra_problems`` is ``None`` or a list of :class:`verimono.Problem`, to
be checked besides the reference catalog).

The measures never import verimono; the steppers are handed a small duck-typed problem (``_P``) there.
Ratios of an *equality* law (``a = b``) are ``|a - b| / (EQ_TOL (1 + |scale|))``.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Callable

import numpy as np

EQ_TOL = 1e-9          # relative slack of an equality law in the measures (round-off is ~1e-15)


@dataclasses.dataclass(frozen=True)
class Entry:
    name: str
    kind: str              # "operator" | "stepper"
    label: str             # the paper's statement
    lawful: bool           # False: plant, True: control
    build: Callable[[], Any]
    measure: Callable[[], float]
    bug: str


# ----------------------------------------------------------------------------------------------------
# plain-numpy helpers
# ----------------------------------------------------------------------------------------------------

def _n(v):
    return float(np.linalg.norm(np.asarray(v, dtype=float)))


def _eq_ratio(a, b, scale=1.0):
    return _n(np.asarray(a) - np.asarray(b)) / (EQ_TOL * (1.0 + abs(scale)))


def _firm_ratio(J, x1, x2, lam, t=0.0):
    """Firm nonexpansiveness |ΔJ|² + |Δx - ΔJ|² ≤ |Δx|² (Prop. prop:maxmon-resolvent-Yosida ii)."""
    a, b = np.asarray(J(x1, lam, t)), np.asarray(J(x2, lam, t))
    d, dj = np.asarray(x1) - np.asarray(x2), a - b
    return (dj @ dj + (d - dj) @ (d - dj)) / ((d @ d) * (1 + 1e-12))


def _nonexp_ratio(J, x1, x2, lam, t=0.0):
    return _n(np.asarray(J(x1, lam, t)) - np.asarray(J(x2, lam, t))) / (_n(np.asarray(x1) - np.asarray(x2)) * (1 + 1e-12))


def _search(fn, n, lams, trials=200, seed=0, scale=3.0, t=0.0):
    """max of fn(x1, x2, lam) over seeded random pairs and the given steps."""
    rng = np.random.default_rng(seed)
    worst = -np.inf
    for lam in lams:
        for _ in range(trials):
            x1 = scale * rng.standard_normal(n)
            x2 = x1 + rng.standard_normal(n) * 10 ** rng.uniform(-3, 0.5)
            worst = max(worst, fn(x1, x2, lam))
    return worst


def _ball_proj(x, c, r):
    d = np.asarray(x, dtype=float) - c
    return c + d * min(1.0, r / max(np.linalg.norm(d), 1e-300))


class _Op:
    """A duck-typed operator for the measures (resolvent(x, lam, t), dim)."""

    def __init__(self, dim, resolvent, project_domain=None):
        self.dim, self._J, self._P = dim, resolvent, project_domain
        self.name = "measure operator"

    def resolvent(self, x, lam, t=0.0):
        return np.asarray(self._J(np.asarray(x, dtype=float), lam, t), dtype=float)

    def project_domain(self, x, t=0.0):
        return np.asarray(self._P(np.asarray(x, dtype=float), t), dtype=float)


class _P:
    """A duck-typed problem for the measures: what a stepper reads from a verimono.Problem."""

    def __init__(self, operator, x0, T, f=None, u=None, U=None, lipschitz=None, name="measure problem"):
        self.operator, self.x0, self.T = operator, np.asarray(x0, dtype=float), float(T)
        self.f, self.u, self.U, self.lipschitz, self.name = f, u, U, lipschitz, name
        self.dim = operator.dim

    def input_increments(self, t):
        if self.U is None:
            return None
        Ut = np.array([np.asarray(self.U(s), dtype=float) for s in t])
        return np.diff(Ut, axis=0)


def _residual_ratio(stepper, prob, t_grid, J):
    """eq:iteration: x_{k+1} = J_{h F(t_{k+1})}(x_k + h f(x_k) + ∫u), worst relative residual."""
    t_grid = np.asarray(t_grid, dtype=float)
    X = np.asarray(stepper(prob, t_grid), dtype=float)
    if X.shape != (len(t_grid), prob.dim):
        return math.inf
    dU = prob.input_increments(t_grid)
    worst = 0.0
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        z = X[k - 1] + (h * np.asarray(prob.f(X[k - 1])) if prob.f is not None else 0.0)
        if dU is not None:
            z = z + dU[k - 1]
        worst = max(worst, _eq_ratio(X[k], J(z, h, t_grid[k]), _n(X[k])))
    return worst


def _graded(T, K, p=2.0):
    return T * (np.arange(K + 1) / K) ** p


# ----------------------------------------------------------------------------------------------------
# the correct scheme (README's my_stepper) and the data of the stepper measures
# ----------------------------------------------------------------------------------------------------

def proximal(problem, t_grid):
    """x_{k+1} = J_{h F(t_{k+1})}(x_k + h f(x_k) + ∫u): the paper's scheme, correct."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        z = x[-1] + (h * np.asarray(problem.f(x[-1])) if problem.f is not None else 0.0)
        if dU is not None:
            z = z + dU[k - 1]
        x.append(np.asarray(problem.operator.resolvent(z, h, t_grid[k]), dtype=float))
    return np.array(x)


M2 = np.array([[1.0, 0.5], [-0.5, 1.0]])
M3 = np.array([[1.0, 0.4, 0.0], [-0.4, 0.8, 0.3], [0.0, -0.3, 0.6]])


def _lin_J(M):
    return lambda x, lam, t=0.0: np.linalg.solve(np.eye(len(M)) + lam * M, x)


def _f2(x):
    return 0.5 * np.array([np.sin(x[1]), np.cos(x[0])])


def _u2(t):
    return np.array([np.cos(3 * t), np.sin(2 * t)])


def _U2(t):
    return np.array([np.sin(3 * t) / 3, (1 - np.cos(2 * t)) / 2])


def _f3(x):
    return 0.4 * np.array([np.sin(x[1]), np.cos(x[2]), -x[0]])


def _u3(t):
    return np.array([np.cos(2 * t), np.sin(3 * t), 1.0 + t])


def _U3(t):
    return np.array([np.sin(2 * t) / 2, (1 - np.cos(3 * t)) / 3, t + t * t / 2])


def _ball_c(t):
    return np.array([t, 0.0])


def _ball_J(x, lam, t=0.0):
    return _ball_proj(x, _ball_c(t), 1.0)


def _fball(x):
    return 0.5 * np.asarray(x)


def _mp_lin2(x0=(1.0, -0.5)):
    return _P(_Op(2, _lin_J(M2)), x0, 1.0, f=_f2, u=_u2, U=_U2, lipschitz=0.5)


def _mp_lin3():
    return _P(_Op(3, _lin_J(M3)), [0.5, -1.0, 0.3], 1.0, f=_f3, u=_u3, U=_U3, lipschitz=0.4)


def _mp_ball():
    return _P(_Op(2, _ball_J, lambda x, t: _ball_J(x, 1.0, t)), [-1.0, 0.0], 1.0, f=_fball, lipschitz=0.5)


def _vm_problems():
    """The same measure problems as verimono Problems (built only in build())."""
    import verimono as vm

    lin2 = vm.Problem(vm.Linear(M2), x0=[1.0, -0.5], T=1.0, f=_f2, lipschitz=0.5, u=_u2, U=_U2,
                      name="blind linear n=2 with f and u")
    lin2neg = vm.Problem(vm.Linear(M2), x0=[0.5, -1.5], T=1.0, f=_f2, lipschitz=0.5, u=_u2, U=_U2,
                         name="blind linear n=2, negative sum")
    lin3 = vm.Problem(vm.Linear(M3), x0=[0.5, -1.0, 0.3], T=1.0, f=_f3, lipschitz=0.4, u=_u3, U=_U3,
                      name="blind linear n=3 with f and u")
    ball = vm.Problem(vm.NormalCone(vm.sets.Ball(_ball_c, 1.0)), x0=[-1.0, 0.0], T=1.0, f=_fball,
                      lipschitz=0.5, name="blind translating ball with f")
    return [lin2, lin2neg, lin3, ball]


def _stepper_build(fn, **claim):
    def build():
        import verimono as vm

        s = vm.Stepper(fn, name=fn.__name__, **claim) if claim else fn
        return s, _vm_problems()
    return build


# ----------------------------------------------------------------------------------------------------
# operator plants and controls
# ----------------------------------------------------------------------------------------------------

def _op(resolvent, dim, name, **members):
    def build():
        import verimono as vm

        return vm.operator_from_resolvent(resolvent, dim, name=name, **members)
    return build


# O1 box normal cone, resolvent = radial scaling by the ∞-norm instead of the coordinate clip
def _radial_box(x, lam, t=0.0):
    x = np.asarray(x, dtype=float)
    return x / max(np.max(np.abs(x)), 1.0)


def _m_radial_box():
    return max(_firm_ratio(_radial_box, np.array([1.0, 1.0]), np.array([3.0, 1.0]), 1.0),
               _search(lambda a, b, l: _firm_ratio(_radial_box, a, b, l), 2, [1.0], 300))


# O2 soft thresholding with the wrong sign in the negative branch
def _soft_bad(x, lam, t=0.0):
    x = np.asarray(x, dtype=float)
    return np.where(x > lam, x - lam, np.where(x < -lam, x - lam, 0.0))


def _soft_good(x, lam, t=0.0):
    x = np.asarray(x, dtype=float)
    return np.where(x > lam, x - lam, np.where(x < -lam, x + lam, 0.0))


def _l1(x, t=0.0):
    return float(np.abs(np.asarray(x)).sum())


def _m_soft(J):
    def m():
        w = _nonexp_ratio(J, np.array([-0.49, 0.2, 1.0]), np.array([-0.51, 0.2, 1.0]), 0.5)
        return max(w, _search(lambda a, b, l: _nonexp_ratio(J, a, b, l), 3, [0.1, 0.5, 2.0], 100))
    return m


# O3 linear operator, transposed matrix used when the coordinate sum is negative
M_sum = np.array([[1.0, 1.0], [-1.0, 1.0]])


def _sumneg_J(x, lam, t=0.0):
    x = np.asarray(x, dtype=float)
    M = M_sum if x.sum() >= 0 else M_sum.T
    return np.linalg.solve(np.eye(2) + lam * M, x)


def _m_sumneg():
    e = 1e-6
    return _nonexp_ratio(_sumneg_J, np.array([1.0, -1.0 + e]), np.array([1.0, -1.0 - e]), 1.0)


# O4 / C6 norm shrinkage F = ∂(c|x|): a factory whose threshold is off for odd dimensions
C_NORM = 0.8


def _shrink_factory(n):
    def J(x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        thresh = lam * C_NORM * ((1.0 + 1.0 / x.size) if x.size % 2 else 1.0)
        r = np.linalg.norm(x)
        return x * max(0.0, 1.0 - thresh / r) if r > 0 else x * 0.0

    def min_norm(x, t=0.0):
        x = np.asarray(x, dtype=float)
        r = np.linalg.norm(x)
        return C_NORM * x / r if r > 0 else 0.0 * x

    def contains(x, y, t=0.0, tol=None):
        tol = 1e-9 if tol is None else tol
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        r = np.linalg.norm(x)
        if r > tol:
            return bool(np.linalg.norm(y - C_NORM * x / r) <= tol * (1 + np.linalg.norm(y)))
        return bool(np.linalg.norm(y) <= C_NORM + tol)

    return J, min_norm, contains


def _m_shrink(n):
    def m():
        J, _, _ = _shrink_factory(n)
        rng = np.random.default_rng(1)
        worst = 0.0
        for lam in (0.1, 0.5, 1.0):
            for _ in range(50):
                x = 3 * rng.standard_normal(n)
                j = J(x, lam)
                y = (x - j) / lam                      # Y_λ x must lie in F(J_λ x) = {c J/|J|} (J ≠ 0)
                if np.linalg.norm(j) > 1e-6:
                    worst = max(worst, _eq_ratio(y, C_NORM * j / np.linalg.norm(j), _n(y)))
        return worst
    return m


def _shrink_build(n, name):
    def build():
        import verimono as vm

        J, mn, ct = _shrink_factory(n)
        return vm.operator_from_resolvent(J, n, name=name, min_norm=mn, contains=ct,
                                          value=lambda x: C_NORM * float(np.linalg.norm(x)))
    return build


# O5 / C3 ball projection, wrong (outside by a relative 1e-3) only far from the centre
C_FAR = np.array([0.5, -0.5, 0.25])


def _far_bad(x, lam, t=0.0):
    d = np.asarray(x, dtype=float) - C_FAR
    r = np.linalg.norm(d)
    if r > 1e3:
        return C_FAR + d / r * (1.0 + 1e-3)
    return C_FAR + d / max(r, 1.0)


def _far_good(x, lam, t=0.0):
    d = np.asarray(x, dtype=float) - C_FAR
    r = np.linalg.norm(d)
    if r > 1e3:
        return C_FAR + d / r
    return C_FAR + d / max(r, 1.0)


def _far_proj(x, t=0.0):
    return _far_good(x, 1.0, t)


def _m_far(J):
    def m():
        e = np.array([1.0, 2.0, 2.0]) / 3.0
        w1 = _nonexp_ratio(J, C_FAR + (1e3 - 1e-6) * e, C_FAR + (1e3 + 1e-6) * e, 1.0)
        x = C_FAR + 5e3 * e                                   # J_λ x ∈ dom F = the ball
        jx = J(x, 1.0)
        w2 = max(0.0, np.linalg.norm(jx - C_FAR) - 1.0) / (EQ_TOL * 2.0)
        return max(w1, w2)
    return m


# O6 warm-started iterative resolvent: a few Richardson sweeps from the previous call's answer
M_ws = np.array([[2.0, 0.3], [0.3, 1.0]])


def _warm_start_factory():
    state = {"y": np.zeros(2)}

    def J(x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        A = np.eye(2) + lam * M_ws
        w = 1.0 / (1.0 + lam * 2.1)
        y = state["y"]
        for _ in range(4):
            y = y - w * (A @ y - x)
        state["y"] = y
        return y.copy()
    return J


def _m_warm():
    J = _warm_start_factory()
    x = np.array([1.0, -2.0])
    J(np.array([10.0, 10.0]), 1.0)
    a = J(x, 1.0)
    J(np.array([-10.0, 3.0]), 1.0)
    b = J(x, 1.0)                                              # single-valued: J_λ x the same both times
    return _eq_ratio(a, b, _n(x))


def _warm_build():
    import verimono as vm

    return vm.operator_from_resolvent(_warm_start_factory(), 2, name="warm-started resolvent",
                                      min_norm=lambda x, t: M_ws @ np.asarray(x))


# O7 resolvent with unseeded noise of relative size 1e-6
_NOISE = np.random.default_rng()


def _noisy_J(x, lam, t=0.0):
    x = np.asarray(x, dtype=float)
    return np.linalg.solve(np.eye(2) + lam * M2, x) + 1e-6 * (1 + np.linalg.norm(x)) * _NOISE.standard_normal(2)


def _m_noisy():
    x = np.array([0.3, -1.2])
    return max(_eq_ratio(_noisy_J(x, 0.5), _noisy_J(x, 0.5), _n(x)) for _ in range(20))


# O8 linear resolvent with λ replaced by λ + λ²/10 (each J_λ a resolvent, of another operator)
def _lam2_J(x, lam, t=0.0):
    return np.linalg.solve(np.eye(2) + (lam + 0.1 * lam * lam) * M2, np.asarray(x, dtype=float))


def _m_identity(J):
    def m():
        rng = np.random.default_rng(2)
        worst = 0.0
        for lam, mu in ((1.0, 0.3), (2.0, 0.5), (0.5, 0.05)):
            for _ in range(20):
                x = 2 * rng.standard_normal(2)
                jl = J(x, lam)
                worst = max(worst, _eq_ratio(jl, J(mu / lam * x + (1 - mu / lam) * jl, mu), _n(x)))
        return worst
    return m


# O9 L1 subdifferential whose minimal section treats |x_i| ≤ 1e-3 as zero
def _mn_l1_bad(x, t=0.0):
    x = np.asarray(x, dtype=float)
    return np.sign(x) * (np.abs(x) > 1e-3)


def _mn_l1_good(x, t=0.0):
    return np.sign(np.asarray(x, dtype=float))


def _m_l1_minnorm(mn):
    def m():
        worst = 0.0
        for x in (np.array([1e-4, 1.0, 0.0]), np.array([-5e-4, 0.0, 2.0]), np.array([0.3, -1.0, 0.0])):
            lam = 1e-6
            y = (x - _soft_good(x, lam)) / lam                # |Y_λ x| ≤ |F^0 x| (Prop. vi)
            worst = max(worst, _n(y) / (_n(mn(x)) + 1e-12))
        return worst
    return m


# O10 / C7 time-dependent linear operator A(t) = [[1, 0], [κ t, 1]] (monotone iff |κ t| ≤ 2)
def _At(kappa):
    def A(t):
        return np.array([[1.0, 0.0], [kappa * t, 1.0]])

    def J(x, lam, t=0.0):
        return np.linalg.solve(np.eye(2) + lam * A(t), np.asarray(x, dtype=float))
    return A, J


def _m_At(kappa):
    def m():
        _, J = _At(kappa)
        worst = 0.0
        for t in (0.0, 0.5, 0.9, 1.0):
            for lam in (0.1, 1.0, 10.0, 100.0):
                for th in np.linspace(0, np.pi, 37):
                    d = np.array([np.cos(th), np.sin(th)])
                    worst = max(worst, _firm_ratio(lambda x, l, s: J(x, l, t), d, 0 * d, lam))
        return worst
    return m


def _At_build(kappa, name):
    def build():
        import verimono as vm

        A, J = _At(kappa)
        return vm.operator_from_resolvent(J, 2, name=name, min_norm=lambda x, t: A(t) @ np.asarray(x))
    return build


# O11 / C1 linear operator, resolvent step scaled by 1.03 (exact: 1.0)
M11 = np.array([[2.0, 1.0], [-1.0, 1.0]])


def _scaled_J(s):
    return lambda x, lam, t=0.0: np.linalg.solve(np.eye(2) + s * lam * M11, np.asarray(x, dtype=float))


def _lin_contains(M):
    def contains(x, y, t=0.0, tol=None):
        tol = 1e-9 if tol is None else tol
        return bool(np.max(np.abs(np.asarray(y) - M @ np.asarray(x))) <= tol * (1 + np.linalg.norm(y)))
    return contains


def _m_scaled(s):
    def m():
        rng = np.random.default_rng(3)
        J = _scaled_J(s)
        worst = 0.0
        for lam in (1e-4, 1e-2, 0.3, 3.0):
            for _ in range(40):
                x = rng.standard_normal(2)
                y = (x - J(x, lam)) / lam                     # |Y_λ x| ≤ |F^0 x| = |M x| (Prop. vi)
                worst = max(worst, _n(y) / (_n(M11 @ x) * (1 + 1e-12)))
        return worst
    return m


# O12 explicit (forward) step x - λ M x in place of the resolvent
M12 = np.diag([1.0, 0.3])


def _forward_J(x, lam, t=0.0):
    x = np.asarray(x, dtype=float)
    return x - lam * (M12 @ x)


def _m_forward():
    return _search(lambda a, b, l: _firm_ratio(_forward_J, a, b, l), 2, [0.5, 1.5, 3.0], 50)


# O13 ℓ2-ball normal cone, resolvent scales radially by the ℓ1 norm
def _l1_radial(x, lam, t=0.0):
    x = np.asarray(x, dtype=float)
    return x / max(np.abs(x).sum(), 1.0)


def _l2_ball_proj(x, t=0.0):
    return _ball_proj(x, np.zeros(len(x)), 1.0)


def _m_l1_radial():
    worst = 0.0
    for x in (np.array([0.6, 0.6]), np.array([0.9, -0.3]), np.array([0.1, 0.2])):
        # x ∈ dom F: lim_{λ→0} J_λ x = x (Prop. iii); a normal cone's resolvent does not depend on λ
        worst = max(worst, _eq_ratio(_l1_radial(x, 1e-9), x, _n(x)))
    return worst


# O14 / C4 moving half-space {a·x ≤ b(t)}, b(t) = 0.5 - t, with |b| in the resolvent
A_HS = np.array([1.0, 2.0]) / np.sqrt(5.0)


def _b_hs(t):
    return 0.5 - t


def _hs_J(bad):
    def J(x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        b = abs(_b_hs(t)) if bad else _b_hs(t)
        return x - max(A_HS @ x - b, 0.0) * A_HS
    return J


def _hs_proj(x, t=0.0):
    return _hs_J(False)(x, 1.0, t)


def _m_hs(bad):
    def m():
        J = _hs_J(bad)
        rng = np.random.default_rng(4)
        worst = 0.0
        for t in np.linspace(0, 1, 11):
            for _ in range(20):
                x = 2 * rng.standard_normal(2)
                j = J(x, 1.0, t)
                # J_λ x ∈ dom F(t) (Prop. v)
                worst = max(worst, max(0.0, A_HS @ j - _b_hs(t)) / (EQ_TOL * (1 + _n(x))))
        return worst
    return m


# O15 / C5 box projection, loop over coordinates off by one
LO, HI = np.array([-1.0, -0.5, 0.0]), np.array([1.0, 0.5, 2.0])


def _box_J(bad):
    def J(x, lam, t=0.0):
        y = np.array(x, dtype=float)
        for i in range(len(y) - 1 if bad else len(y)):
            y[i] = min(max(y[i], LO[i]), HI[i])
        return y
    return J


def _box_proj(x, t=0.0):
    return np.clip(np.asarray(x, dtype=float), LO, HI)


def _m_box(bad):
    def m():
        J = _box_J(bad)
        rng = np.random.default_rng(5)
        worst = 0.0
        for _ in range(100):
            x = 3 * rng.standard_normal(3)
            j = J(x, 1.0)
            worst = max(worst, _n(j - np.clip(j, LO, HI)) / (EQ_TOL * (1 + _n(x))))   # J_λ x ∈ dom F
        return worst
    return m


# O16 ball normal cone whose minimal section is the outward normal on the sphere (not 0)
def _ball_resolvent(x, lam, t=0.0):
    return _l2_ball_proj(x)


def _mn_ball_bad(x, t=0.0):
    x = np.asarray(x, dtype=float)
    r = np.linalg.norm(x)
    return x / r if r >= 1.0 - 1e-12 else 0.0 * x


def _m_ball_normal():
    worst = 0.0
    for th in np.linspace(0, 2 * np.pi, 9):
        x = np.array([np.cos(th), np.sin(th)])
        lam = 1e-8
        y = (x - _l2_ball_proj(x)) / lam                  # lim_{λ→0}|Y_λ x| = |F^0 x| (Prop. vi)
        worst = max(worst, abs(_n(y) - _n(_mn_ball_bad(x))) / 1e-6)
    return worst


# ----------------------------------------------------------------------------------------------------
# stepper plants
# ----------------------------------------------------------------------------------------------------

def uniform_assumed(problem, t_grid):
    """Takes h = T/K and t_k = k h whatever the grid."""
    t_grid = np.asarray(t_grid, dtype=float)
    K = len(t_grid) - 1
    h = problem.T / K
    ts = h * np.arange(K + 1)
    dU = problem.input_increments(ts)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, K + 1):
        z = x[-1] + (h * np.asarray(problem.f(x[-1])) if problem.f is not None else 0.0)
        if dU is not None:
            z = z + dU[k - 1]
        x.append(np.asarray(problem.operator.resolvent(z, h, ts[k]), dtype=float))
    return np.array(x)


def floor_steps(problem, t_grid):
    """K = int(T/h) steps of the first cell's width; pads with the last state when it stops short of T."""
    t_grid = np.asarray(t_grid, dtype=float)
    h = t_grid[1] - t_grid[0]
    K = int(problem.T / h)
    ts = h * np.arange(K + 1)
    dU = problem.input_increments(ts)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, min(K, len(t_grid) - 1) + 1):
        z = x[-1] + (h * np.asarray(problem.f(x[-1])) if problem.f is not None else 0.0)
        if dU is not None:
            z = z + dU[k - 1]
        x.append(np.asarray(problem.operator.resolvent(z, h, ts[k]), dtype=float))
    while len(x) < len(t_grid):
        x.append(x[-1])
    return np.array(x)


def operator_at_t_k(problem, t_grid):
    """Uses F(t_k) instead of F(t_{k+1})."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        z = x[-1] + (h * np.asarray(problem.f(x[-1])) if problem.f is not None else 0.0)
        if dU is not None:
            z = z + dU[k - 1]
        x.append(np.asarray(problem.operator.resolvent(z, h, t_grid[k - 1]), dtype=float))
    return np.array(x)


def left_endpoint_input(problem, t_grid):
    """∫_{t_k}^{t_{k+1}} u replaced by h u(t_k)."""
    t_grid = np.asarray(t_grid, dtype=float)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        z = x[-1] + (h * np.asarray(problem.f(x[-1])) if problem.f is not None else 0.0)
        if problem.u is not None:
            z = z + h * np.asarray(problem.u(t_grid[k - 1]), dtype=float)
        x.append(np.asarray(problem.operator.resolvent(z, h, t_grid[k]), dtype=float))
    return np.array(x)


def f_after_projection(problem, t_grid):
    """x_{k+1} = J(x_k + ∫u) + h f(x_k): the Lipschitz field added after the resolvent."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        z = x[-1] + (dU[k - 1] if dU is not None else 0.0)
        nxt = np.asarray(problem.operator.resolvent(z, h, t_grid[k]), dtype=float)
        if problem.f is not None:
            nxt = nxt + h * np.asarray(problem.f(x[-1]))
        x.append(nxt)
    return np.array(x)


def last_step_lags(problem, t_grid):
    """The last step only takes the operator at t_{K-1} (an index off by one at the end)."""
    t_grid = np.asarray(t_grid, dtype=float)
    K = len(t_grid) - 1
    dU = problem.input_increments(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, K + 1):
        h = t_grid[k] - t_grid[k - 1]
        z = x[-1] + (h * np.asarray(problem.f(x[-1])) if problem.f is not None else 0.0)
        if dU is not None:
            z = z + dU[k - 1]
        tk = t_grid[k] if k < K else t_grid[k - 1]
        x.append(np.asarray(problem.operator.resolvent(z, h, tk), dtype=float))
    return np.array(x)


def drops_f_negative_sum(problem, t_grid):
    """Skips the field f whenever the coordinates of x_k sum to a negative number."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        z = x[-1].copy()
        if problem.f is not None and x[-1].sum() >= 0:
            z = z + h * np.asarray(problem.f(x[-1]))
        if dU is not None:
            z = z + dU[k - 1]
        x.append(np.asarray(problem.operator.resolvent(z, h, t_grid[k]), dtype=float))
    return np.array(x)


def odd_n_input_shift(problem, t_grid):
    """For odd n the input of the next cell is used (dU[k] for dU[k-1], the last clamped)."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    K = len(t_grid) - 1
    odd = problem.dim % 2 == 1
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, K + 1):
        h = t_grid[k] - t_grid[k - 1]
        z = x[-1] + (h * np.asarray(problem.f(x[-1])) if problem.f is not None else 0.0)
        if dU is not None:
            z = z + dU[min(k, K - 1) if odd else k - 1]
        x.append(np.asarray(problem.operator.resolvent(z, h, t_grid[k]), dtype=float))
    return np.array(x)


_CACHE: dict = {}


def cached_by_length(problem, t_grid):
    """Memoises its answer by (x0, T, number of nodes): a second grid of the same size gets the first's."""
    t_grid = np.asarray(t_grid, dtype=float)
    key = (np.asarray(problem.x0, dtype=float).tobytes(), float(problem.T), len(t_grid), problem.dim)
    if key not in _CACHE:
        _CACHE[key] = proximal(problem, t_grid)
    return _CACHE[key].copy()


def double_h_field(problem, t_grid):
    """The explicit field is taken with 2h (z = x + 2h f(x))."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        z = x[-1] + (2 * h * np.asarray(problem.f(x[-1])) if problem.f is not None else 0.0)
        if dU is not None:
            z = z + dU[k - 1]
        x.append(np.asarray(problem.operator.resolvent(z, h, t_grid[k]), dtype=float))
    return np.array(x)


_JIT = np.random.default_rng()


def jittered_step(problem, t_grid):
    """The resolvent's step is h(1 + 1e-3 ξ), ξ from an unseeded generator."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        z = x[-1] + (h * np.asarray(problem.f(x[-1])) if problem.f is not None else 0.0)
        if dU is not None:
            z = z + dU[k - 1]
        lam = h * (1.0 + 1e-3 * _JIT.standard_normal())
        x.append(np.asarray(problem.operator.resolvent(z, lam, t_grid[k]), dtype=float))
    return np.array(x)


def two_substeps(problem, t_grid):
    """Claims the proximal scheme, but applies J_{h/2} twice (two half prox steps at t_{k+1})."""
    t_grid = np.asarray(t_grid, dtype=float)
    dU = problem.input_increments(t_grid)
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        z = x[-1] + (h * np.asarray(problem.f(x[-1])) if problem.f is not None else 0.0)
        if dU is not None:
            z = z + dU[k - 1]
        half = np.asarray(problem.operator.resolvent(z, h / 2, t_grid[k]), dtype=float)
        x.append(np.asarray(problem.operator.resolvent(half, h / 2, t_grid[k]), dtype=float))
    return np.array(x)


def _m_residual(stepper, mk=_mp_lin2, grid=lambda: np.linspace(0, 1, 51), J=None):
    def m():
        prob = mk()
        return _residual_ratio(stepper, prob, grid(), J or prob.operator.resolvent)
    return m


def _m_floor():
    prob = _mp_lin2()
    prob.T = 0.3                         # linspace(0, 0.3, 28): T/h = 26.999999999999996, int → 26 steps of 27
    return _residual_ratio(floor_steps, prob, np.linspace(0, 0.3, 28), prob.operator.resolvent)


def _m_cache():
    _CACHE.clear()
    prob = _mp_lin2()
    cached_by_length(prob, np.linspace(0, 1, 41))
    r = _residual_ratio(cached_by_length, prob, _graded(1.0, 40), prob.operator.resolvent)
    _CACHE.clear()
    return r


def _m_contraction(stepper):
    """|x_K - x'_K| ≤ e^{L T}|x_0 - x'_0| (uniqueness argument, Section 6), f(x) = L x, F = 0.1 I."""
    def m():
        L, T = 1.0, 1.0
        op = _Op(2, lambda x, lam, t=0.0: np.asarray(x) / (1 + 0.1 * lam))
        p1 = _P(op, [1.0, 0.0], T, f=lambda x: L * np.asarray(x), lipschitz=L)
        p2 = _P(op, [1.1, 0.05], T, f=lambda x: L * np.asarray(x), lipschitz=L)
        t = np.linspace(0, T, 101)
        X1, X2 = stepper(p1, t), stepper(p2, t)
        d = np.linalg.norm(X1 - X2, axis=1)
        return float(np.max(d / (np.exp(L * t) * d[0])))
    return m


def _m_order(claimed):
    """Observed order of the stepper on x' = -x (T=1) vs the claimed order less a 0.25 margin."""
    def m():
        op = _Op(1, lambda x, lam, t=0.0: np.asarray(x) / (1 + lam))
        p = _P(op, [1.0], 1.0)
        errs = []
        for K in (50, 100, 200):
            X = proximal(p, np.linspace(0, 1, K + 1))
            errs.append(abs(X[-1, 0] - np.exp(-1.0)))
        obs = np.log2(errs[-2] / errs[-1])
        return (claimed - 0.25) / obs
    return m


# ----------------------------------------------------------------------------------------------------
# problem-claim plants (a correct stepper handed a problem whose stated φ / σ is wrong)
# ----------------------------------------------------------------------------------------------------

M_LG = np.array([[1.5, 1.0], [-1.0, 1.2]])
SIG_TRUE = float(np.linalg.norm(M_LG, 2))


def _lg_build(sigma):
    def build():
        import verimono as vm

        p = vm.Problem(vm.Linear(M_LG), x0=[3.0, -2.0], T=2.0, sigma=lambda t: sigma,
                       name=f"linear with stated sigma {sigma:.3g}")
        return proximal, [p]
    return build


def _m_lg(sigma):
    def m():
        worst = 0.0
        for th in np.linspace(0, np.pi, 181):
            for r in (0.0, 1.0, 10.0, 100.0, 1e4):
                x = r * np.array([np.cos(th), np.sin(th)])
                worst = max(worst, _n(M_LG @ x) / (sigma * (1 + _n(x))))   # (LG)
        return worst
    return m


def _r_shrink(t):
    return 1.0 - 0.4 * t


def _a3_build(phi, name):
    def build():
        import verimono as vm

        p = vm.Problem(vm.NormalCone(vm.sets.Ball(np.zeros(2), _r_shrink)), x0=[0.9, 0.0], T=1.0, phi=phi,
                       name=name)
        return proximal, [p]
    return build


def _m_a3(phi):
    def m():
        worst = 0.0
        ts = np.linspace(0, 1, 21)
        for i, s in enumerate(ts):
            for t in ts[i + 1:]:
                lhs = _r_shrink(s) - _r_shrink(t)          # sup_{z ∈ dom F(s)} dist(z, dom F(t)) for nested balls
                worst = max(worst, lhs / (phi(t) - phi(s) + 1e-9))
        return worst
    return m


def _phi_zero(t):
    return 0.0


def _phi_true(t):
    return 0.4 * t


# ----------------------------------------------------------------------------------------------------
# the set
# ----------------------------------------------------------------------------------------------------

PROP = "prop:maxmon-resolvent-Yosida"

PLANTS: list[Entry] = [
    # -- operators ---------------------------------------------------------------------------------
    Entry("radial_box_projection", "operator", f"{PROP} ii (firm nonexpansiveness)", False,
          _op(_radial_box, 2, "radial box projection", project_domain=lambda x, t: np.clip(x, -1, 1)),
          _m_radial_box, "normal cone of [-1,1]^2 whose resolvent scales x radially by max|x_i| instead of clipping"),
    Entry("soft_threshold_sign_flip", "operator", f"{PROP} ii (nonexpansive)", False,
          _op(_soft_bad, 3, "soft threshold, bad negative branch", value=_l1),
          _m_soft(_soft_bad), "prox of λ|x|_1 returns x - λ (not x + λ) in the x < -λ branch"),
    Entry("transpose_when_sum_negative", "operator", f"{PROP} ii (nonexpansive, single-valued)", False,
          _op(_sumneg_J, 2, "linear, transposed for negative sums", min_norm=lambda x, t: M_sum @ np.asarray(x)),
          _m_sumneg, "(I + λM)^{-1}x, but with Mᵀ when sum(x) < 0: a jump across the hyperplane sum(x) = 0"),
    Entry("norm_shrink_odd_n", "operator", f"{PROP} v (Y_λx ∈ F(J_λx))", False,
          _shrink_build(3, "norm shrink n=3"), _m_shrink(3),
          "prox of c|x| whose threshold is λc(1 + 1/n) when n is odd (n = 3 here)"),
    Entry("ball_outside_far_away", "operator", f"{PROP} ii / v (J_λx ∈ dom F, nonexpansive)", False,
          _op(_far_bad, 3, "ball projection, far branch", project_domain=_far_proj),
          _m_far(_far_bad), "ball projection returns a point 1e-3 outside the ball when |x - c| > 1e3"),
    Entry("warm_started_resolvent", "operator", f"{PROP} ii (single-valued)", False,
          _warm_build, _m_warm, "4 Richardson sweeps warm-started from the previous call's answer: J_λx depends on history"),
    Entry("noisy_resolvent", "operator", f"{PROP} ii (single-valued)", False,
          _op(_noisy_J, 2, "noisy linear resolvent", min_norm=lambda x, t: M2 @ np.asarray(x)),
          _m_noisy, "(I + λM)^{-1}x plus unseeded noise of relative size 1e-6"),
    Entry("lambda_plus_lambda2", "operator", "resolvent identity J_λ = J_μ(μ/λ x + (1-μ/λ)J_λ x)", False,
          _op(_lam2_J, 2, "linear, step λ + λ²/10", min_norm=lambda x, t: M2 @ np.asarray(x)),
          _m_identity(_lam2_J), "linear resolvent with step λ + λ²/10: each J_λ a resolvent, but of (1 + λ/10)M"),
    Entry("l1_min_norm_cutoff", "operator", f"{PROP} vi (|Y_λx| ≤ |F^0x|)", False,
          _op(_soft_good, 3, "l1 with cut-off min_norm", min_norm=_mn_l1_bad, value=_l1),
          _m_l1_minnorm(_mn_l1_bad), "minimal section of ∂|x|_1 treats 0 < |x_i| ≤ 1e-3 as zero coordinates"),
    Entry("nonmonotone_after_t08", "operator", "(A1) monotonicity of F(t,·) / prop ii firm nonexpansive", False,
          _At_build(2.5, "A(t) = [[1,0],[2.5t,1]]"), _m_At(2.5),
          "linear A(t) with off-diagonal 2.5t: A + Aᵀ indefinite for t > 0.8"),
    Entry("linear_step_times_1_03", "operator", f"{PROP} v/vi (Y_λx ∈ F(J_λx), |Y_λx| ≤ |F^0x|)", False,
          _op(_scaled_J(1.03), 2, "linear, step 1.03λ", min_norm=lambda x, t: M11 @ np.asarray(x),
              contains=_lin_contains(M11)),
          _m_scaled(1.03), "linear resolvent (I + 1.03λM)^{-1}: the exact resolvent of 1.03M, not of M"),
    Entry("forward_step_resolvent", "operator", f"{PROP} ii/iv (firm nonexpansive, Y_λ 1/λ-Lipschitz)", False,
          _op(_forward_J, 2, "forward step", min_norm=lambda x, t: M12 @ np.asarray(x)),
          _m_forward, "explicit step x - λMx in place of (I + λM)^{-1}x"),
    Entry("l1_radial_for_l2_ball", "operator", f"{PROP} iii (J_λx → x on dom F)", False,
          _op(_l1_radial, 2, "l1-radial for l2 ball", project_domain=_l2_ball_proj),
          _m_l1_radial, "normal cone of the Euclidean unit ball, resolvent divides by max(|x|_1, 1) (wrong norm)"),
    Entry("halfspace_abs_b", "operator", f"{PROP} v / e:x k+1 props.1 (J_λx ∈ dom F(t))", False,
          _op(_hs_J(True), 2, "half-space with |b|", project_domain=_hs_proj),
          _m_hs(True), "half-space {a·x ≤ b(t)}, b = 0.5 - t, resolvent uses |b|: wrong once b(t) < 0"),
    Entry("box_off_by_one", "operator", f"{PROP} v / e:x k+1 props.1 (J_λx ∈ dom F)", False,
          _op(_box_J(True), 3, "box, last coordinate unclipped", project_domain=_box_proj),
          _m_box(True), "box projection loops over range(n - 1): the last coordinate is never clipped"),
    Entry("ball_min_norm_is_normal", "operator", f"{PROP} vi (lim |Y_λx| = |F^0x|)", False,
          _op(_ball_resolvent, 2, "ball, min_norm = normal",
              project_domain=_l2_ball_proj, min_norm=_mn_ball_bad),
          _m_ball_normal, "minimal section of the ball's normal cone returns the unit normal on the sphere, not 0"),
    # -- steppers ----------------------------------------------------------------------------------
    Entry("uniform_grid_assumed", "stepper", "eq:iteration (nonuniform partitions)", False,
          _stepper_build(uniform_assumed), _m_residual(uniform_assumed, grid=lambda: _graded(1.0, 40)),
          "takes h = T/K and t_k = kh whatever the grid: right only on uniform grids"),
    Entry("floor_T_over_h", "stepper", "eq:iteration (x_K at t_K = T)", False,
          _stepper_build(floor_steps), _m_floor,
          "K = int(T/h) steps of the first cell (T=0.3, 27 cells → 26), the missing final states padded with the last one"),
    Entry("operator_at_t_k", "stepper", "eq:iteration (F(t_{k+1}, ·))", False,
          _stepper_build(operator_at_t_k), _m_residual(operator_at_t_k, mk=_mp_ball),
          "uses J_{hF(t_k)} instead of J_{hF(t_{k+1})}"),
    Entry("left_endpoint_input", "stepper", "eq:iteration with ∫_{t_k}^{t_{k+1}} u (Section 6)", False,
          _stepper_build(left_endpoint_input), _m_residual(left_endpoint_input),
          "∫u over the cell replaced by h u(t_k) (left rectangle rule)"),
    Entry("f_after_projection", "stepper", "eq:iteration / e:x k+1 props.1", False,
          _stepper_build(f_after_projection), _m_residual(f_after_projection, mk=_mp_ball),
          "x_{k+1} = J(x_k + ∫u) + h f(x_k): the field added after the resolvent"),
    Entry("last_step_lags", "stepper", "eq:iteration (last step)", False,
          _stepper_build(last_step_lags), _m_residual(last_step_lags, mk=_mp_ball),
          "only the final step takes the operator at t_{K-1}"),
    Entry("drops_f_when_sum_negative", "stepper", "eq:iteration (f(x_k) term)", False,
          _stepper_build(drops_f_negative_sum),
          _m_residual(drops_f_negative_sum, mk=lambda: _mp_lin2((0.5, -1.5))),
          "skips h f(x_k) whenever sum(x_k) < 0"),
    Entry("odd_n_next_cell_input", "stepper", "eq:iteration (∫ over the current cell)", False,
          _stepper_build(odd_n_input_shift), _m_residual(odd_n_input_shift, mk=_mp_lin3),
          "for odd n adds ∫u over the next cell (dU[k] for dU[k-1])"),
    Entry("cached_by_grid_length", "stepper", "eq:iteration (any partition)", False,
          _stepper_build(cached_by_length), _m_cache,
          "memoises by (x0, T, len(t_grid)): a second grid of the same size gets the first grid's states"),
    Entry("field_with_2h", "stepper", "contraction |x1(t)-x2(t)| ≤ e^{Lt}|x1(0)-x2(0)| (Section 6)", False,
          _stepper_build(double_h_field), _m_contraction(double_h_field),
          "z = x_k + 2h f(x_k): the explicit field doubled"),
    Entry("jittered_step", "stepper", "eq:iteration (step h_{k+1})", False,
          _stepper_build(jittered_step), _m_residual(jittered_step),
          "resolvent step h(1 + 1e-3 ξ) with ξ from an unseeded generator"),
    Entry("two_half_prox_steps", "stepper", "eq:iteration (one resolvent of step h)", False,
          _stepper_build(two_substeps), _m_residual(two_substeps),
          "applies J_{h/2} twice and claims the proximal scheme"),
    Entry("proximal_claims_order_2", "stepper", "thm:main convergence order (1 on smooth references)", False,
          _stepper_build(proximal, scheme="any", order=2), _m_order(2.0),
          "the (correct) proximal scheme wrapped as Stepper(scheme='any', order=2)"),
    Entry("stated_sigma_too_small", "stepper", "(LG) |F^0(t,x)| ≤ σ(t)(1+|x|)", False,
          _lg_build(0.5), _m_lg(0.5), "problem states σ ≡ 0.5 for F = Mx with |M|_2 ≈ 1.83"),
    Entry("stated_phi_zero_shrinking_ball", "stepper", "(A3) sup dist(z, dom F(t)) ≤ φ(t) - φ(s)", False,
          _a3_build(_phi_zero, "shrinking ball, stated phi = 0"), _m_a3(_phi_zero),
          "problem states φ ≡ 0 for a ball whose radius shrinks as 1 - 0.4t"),
    # -- controls ----------------------------------------------------------------------------------
    Entry("ctrl_linear_exact", "operator", f"{PROP} (all items)", True,
          _op(_scaled_J(1.0), 2, "linear exact", min_norm=lambda x, t: M11 @ np.asarray(x),
              contains=_lin_contains(M11)),
          _m_scaled(1.0), "exact (I + λM)^{-1} (twin of linear_step_times_1_03)"),
    Entry("ctrl_soft_threshold", "operator", f"{PROP} ii", True,
          _op(_soft_good, 3, "soft threshold", value=_l1), _m_soft(_soft_good),
          "correct soft thresholding (twin of soft_threshold_sign_flip)"),
    Entry("ctrl_ball_far_exact", "operator", f"{PROP} ii / v", True,
          _op(_far_good, 3, "ball projection, exact far branch", project_domain=_far_proj), _m_far(_far_good),
          "correct ball projection with the same far branch (twin of ball_outside_far_away)"),
    Entry("ctrl_halfspace", "operator", f"{PROP} v", True,
          _op(_hs_J(False), 2, "half-space", project_domain=_hs_proj), _m_hs(False),
          "correct moving half-space projection (twin of halfspace_abs_b)"),
    Entry("ctrl_box", "operator", f"{PROP} v", True,
          _op(_box_J(False), 3, "box", project_domain=_box_proj), _m_box(False),
          "box projection over every coordinate (twin of box_off_by_one)"),
    Entry("ctrl_norm_shrink_even_n", "operator", f"{PROP} v", True,
          _shrink_build(2, "norm shrink n=2"), _m_shrink(2),
          "the odd-n factory at n = 2, where it is exact (twin of norm_shrink_odd_n)"),
    Entry("ctrl_monotone_1_96", "operator", "(A1) monotonicity of F(t,·)", True,
          _At_build(1.96, "A(t) = [[1,0],[1.96t,1]]"), _m_At(1.96),
          "A(t) with off-diagonal 1.96t: monotone on [0, 1] (twin of nonmonotone_after_t08)"),
    Entry("ctrl_proximal", "stepper", "eq:iteration", True,
          _stepper_build(proximal), _m_residual(proximal, grid=lambda: _graded(1.0, 40)),
          "the paper's scheme, README's my_stepper (twin of every stepper plant)"),
    Entry("ctrl_proximal_any_order_1", "stepper", "thm:main convergence order", True,
          _stepper_build(proximal, scheme="any", order=1), _m_order(1.0),
          "the proximal scheme claiming scheme='any', order=1 (twin of proximal_claims_order_2)"),
    Entry("ctrl_stated_sigma", "stepper", "(LG)", True,
          _lg_build(SIG_TRUE * 1.0001), _m_lg(SIG_TRUE * 1.0001), "σ ≡ |M|_2 (twin of stated_sigma_too_small)"),
    Entry("ctrl_stated_phi", "stepper", "(A3)", True,
          _a3_build(_phi_true, "shrinking ball, stated phi = 0.4t"), _m_a3(_phi_true),
          "φ(t) = 0.4t for the shrinking ball (twin of stated_phi_zero_shrinking_ball)"),
]

BY_NAME = {e.name: e for e in PLANTS}
