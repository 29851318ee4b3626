"""Manufactured solutions (:mod:`verimono.reference.manufactured`): the identity ``y* ∈ F(t, x*)``, ``x* = J_{μF}(z)``, the
input and its primitive against independent computations, the kinks against their closed forms, and the
proximal scheme's order on the three examples — truth, not a self-comparison — with the broken steppers
it must expose seen failing."""

from __future__ import annotations

import math

import cloudpickle
import numpy as np
import pytest
from scipy.integrate import quad_vec
from scipy.optimize import brentq

import verimono as vm
from verimono import manufactured as mf
from verimono.checks.orders import check_convergence_order
from zoo_steppers import _scheme, drops_input, wrong_time

T = 2 * math.pi


@pytest.fixture(scope="module")
def disc():
    """The README's problem: the unit disc centred at ``(cos(t)/2, 0)``, ``f = -x/2``."""
    F = vm.NormalCone(vm.sets.Ball(lambda t: np.array([0.5 * math.cos(t), 0.0]), 1.0))
    return vm.manufactured_problem(F, T=T, f=lambda x: -0.5 * x, lipschitz=0.5, name="disc")


EXAMPLES = ["box", "norm", "lcs"]
ALL = EXAMPLES + ["disc"]


def drops_field(problem, t_grid):
    """Forgets the field ``h f(x_k)`` (keeps ``∫u``)."""
    return _scheme(problem.replace(f=None), t_grid)


def closed_form(name, p, t):
    """``J_{μF(t)}(z(t))`` computed without the operator's resolvent (``None`` where only ``contains`` checks)."""
    sol = p.exact
    z = sol.z(t)
    if name == "box":
        return np.clip(z, [-1 + 0.3 * math.sin(t), -0.8], [1 + 0.3 * math.sin(t), 0.8 + 0.2 * math.cos(t)])
    if name == "norm":
        c = 1 + 0.5 * math.sin(t)
        return max(1 - sol.mu * c / np.linalg.norm(z), 0.0) * z
    if name == "disc":
        c = np.array([0.5 * math.cos(t), 0.0])
        return c + (z - c) / max(np.linalg.norm(z - c), 1.0)
    return None


def lcs_multiplier(p, t):
    """``λ`` with ``y* = -Ax* - Bλ`` (``B = Cᵀ`` invertible) and ``w = Cx* + Dλ + v(t)``."""
    A, C, D = (np.array(mf.LCS_DATA[k]) for k in ("A", "C", "D"))
    x, y = p.exact(t), p.exact.y(t)
    lam = np.linalg.solve(C.T, -(y + A @ x))
    v = np.array([0.6 + 0.2 * math.sin(t), 0.8 + 0.3 * math.cos(2 * t)])
    return lam, C @ x + D @ lam + v


def sample_times(p, k=40, seed=3):
    """Random times plus each kink and points ``1e-7`` either side of it."""
    rng = np.random.default_rng(seed)
    ks = np.array(p.exact.kinks)
    return np.concatenate([rng.uniform(0, p.T, k), ks, ks - 1e-7, ks + 1e-7, [0.0, p.T]])


# -- the identity ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ALL)
def test_y_star_is_in_F_and_x_star_is_the_resolvent(name, request):
    p = request.getfixturevalue(name)
    sol = p.exact
    for t in sample_times(p):
        x, y, z = sol(t), sol.y(t), sol.z(t)
        assert np.allclose(x + sol.mu * y, z, rtol=0, atol=1e-14)
        assert p.operator.contains(x, y, t), (name, t, x, y)
        assert p.operator.in_domain(x, t, tol=1e-9)
        ref = closed_form(name, p, t)
        if ref is not None:
            assert np.allclose(x, ref, rtol=0, atol=1e-14), (t, x, ref)
        if name == "lcs":                         # complementarity, checked from its definition
            lam, w = lcs_multiplier(p, t)
            assert lam.min() >= -1e-12 and w.min() >= -1e-12 and abs(lam @ w) <= 1e-12, (t, lam, w)
    assert np.array_equal(p.x0, sol(0.0))


@pytest.mark.parametrize("name", ALL)
def test_the_nonsmooth_part_is_active_part_of_the_time(name, request):
    """The default path switches the resolvent's regime: a constraint engages and releases (y* ≠ 0 on part of
    [0, T] for the sets, a contact force for the LCS), the soft threshold sticks at 0 part of the time."""
    p = request.getfixturevalue(name)
    ts = np.linspace(0, p.T, 601)
    if name == "norm":
        active = [np.linalg.norm(p.exact(t)) == 0.0 for t in ts]
    elif name == "lcs":
        active = [lcs_multiplier(p, t)[0].max() > 1e-9 for t in ts]
    else:
        active = [np.linalg.norm(p.exact.y(t)) > 1e-12 for t in ts]
    assert 0.1 < np.mean(active) < 0.9
    assert len(p.exact.kinks) >= 4


def _roots(fn, T, n=4000):
    ts = np.linspace(0, T, n + 1)
    vals = np.array([fn(t) for t in ts])
    return [brentq(fn, a, b, xtol=1e-15) for a, b, va, vb in zip(ts[:-1], ts[1:], vals[:-1], vals[1:]) if va * vb < 0]


#: the accuracy the module documents for the kinks it locates (about 1e-10 T; measured 1e-15 T on these)
KINK_ACCURACY = 1e-10


def test_kinks_are_the_switching_times(box, norm, disc, lcs):
    """The detected kinks are where the path crosses a face (box), the circle (disc), |z| = μc (norm), or a contact
    engages or releases (lcs: where λ_i - w_i changes sign), to the documented accuracy."""
    z = box.exact.z
    switches = sorted(
        _roots(lambda t: z(t)[0] - 1 - 0.3 * math.sin(t), T) + _roots(lambda t: z(t)[0] + 1 - 0.3 * math.sin(t), T)
        + _roots(lambda t: z(t)[1] - 0.8 - 0.2 * math.cos(t), T) + _roots(lambda t: z(t)[1] + 0.8, T))
    circle = _roots(lambda t: np.linalg.norm(disc.exact.z(t) - [0.5 * math.cos(t), 0]) - 1.0, T)
    threshold = _roots(lambda t: np.linalg.norm(norm.exact.z(t)) - norm.exact.mu * (1 + 0.5 * math.sin(t)), T)
    contacts = sorted(sum((_roots(lambda t, i=i: float(np.subtract(*lcs_multiplier(lcs, t))[i]), T, n=1500)
                           for i in range(2)), []))
    for p, exact in ((box, switches), (disc, circle), (norm, threshold), (lcs, contacts)):
        assert len(p.exact.kinks) == len(exact) >= 4
        assert np.max(np.abs(np.array(p.exact.kinks) - exact)) < KINK_ACCURACY * T


@pytest.mark.parametrize("c0, mu, freq", [(0.6, 0.5, 3.0), (0.55, 0.3, 5.0), (0.7, 0.4, 7.0)])
def test_two_kinks_a_short_stretch_apart_are_each_located(c0, mu, freq):
    """∂(c(t)|·|) with a fast weight: the path's |z| dips below μc for a short stretch (0.03 long at c0 = 0.6), two
    kinks in one run of deeply halved cells.  They were located at cell edges, 4e-6 off (7e-7 T where 1e-10 T is
    documented); each is its own local maximum of the halving depth now, located on its side of the other."""
    def c(t):
        return c0 + 0.5 * math.sin(freq * t)

    p = vm.manufactured_problem(vm.NormSubdifferential(c, dim=2), T=T, mu=mu)
    exact = _roots(lambda t: np.linalg.norm(p.exact.z(t)) - mu * c(t), T, n=20000)
    gaps = np.diff(exact)
    assert gaps.min() < 0.05                      # the configuration holds a close pair
    assert len(p.exact.kinks) == len(exact)
    assert np.max(np.abs(np.array(p.exact.kinks) - exact)) < KINK_ACCURACY * T


def test_velocity_is_one_sided_at_kinks(box):
    """x*' from the finite differences against the box's closed form (z' inside, the face's velocity on it),
    the right limit at a kink."""
    sol = box.exact

    def exact_velocity(t):
        z, dz = sol.z(t), np.array([-1.5 * math.sin(t), 3.0 * math.cos(2 * t)])
        lo, hi = np.array([-1 + 0.3 * math.sin(t), -0.8]), np.array([1 + 0.3 * math.sin(t), 0.8 + 0.2 * math.cos(t)])
        dlo, dhi = np.array([0.3 * math.cos(t), 0.0]), np.array([0.3 * math.cos(t), -0.2 * math.sin(t)])
        return np.where(z < lo, dlo, np.where(z > hi, dhi, dz))

    for t in np.random.default_rng(5).uniform(0, T, 30):
        v, err = sol.velocity_with_error(t)
        assert np.allclose(v, exact_velocity(t), rtol=0, atol=1e-7) and err < 1e-6
    for k in sol.kinks:
        right = exact_velocity(k + 1e-7)
        assert not np.allclose(right, exact_velocity(k - 1e-7), atol=1e-3)     # a kink indeed
        assert np.allclose(sol.velocity(k), right, rtol=0, atol=1e-5)
        assert np.allclose(sol.velocity(k + 1e-6), right, rtol=0, atol=1e-5)


# -- the input --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ALL)
def test_primitive_matches_an_independent_quadrature(name, request):
    """U(b) - U(a) - (x*(b) - x*(a)) = ∫_a^b (y* - f(x*)), by SciPy's adaptive Gauss–Kronrod with the kinks as
    break points; and the table's own estimate is below 1e-12."""
    p = request.getfixturevalue(name)
    sol = p.exact
    assert sol.quadrature_error < 1e-12

    def g(s):
        x, y = sol(s), sol.y(s)
        return y - (p.f(x) if p.f is not None else 0.0)

    rng = np.random.default_rng(11)
    for a, b in [(0.0, p.T), *np.sort(rng.uniform(0, p.T, (3, 2)), axis=1)]:
        inside = [k for k in sol.kinks if a < k < b]
        ref, err = quad_vec(g, a, b, epsabs=1e-13, epsrel=1e-13, points=inside or None)
        got = p.U(b) - p.U(a) - (sol(b) - sol(a))
        assert np.max(np.abs(got - ref)) < 1e-11, (a, b, got - ref, err)


@pytest.mark.parametrize("name", ALL)
def test_exact_solution_solves_the_inclusion(name, request):
    """As tests/reference/test_reference.py checks the references: x*' by a central difference (δ = 1e-6), then
    f(x*) + u - x*' ∈ F(t, x*); and ∫u over a cell (the pointwise u, Gauss–Kronrod) is the increment of U."""
    p = request.getfixturevalue(name)
    sol = p.exact
    d = 1e-6
    for t in np.random.default_rng(7).uniform(2 * d, p.T - 2 * d, 25):
        if min(abs(t - k) for k in sol.kinks) < 1e-4:
            continue
        dx = (sol(t + d) - sol(t - d)) / (2 * d)
        y = p.f(sol(t)) + p.u(t) - dx
        assert p.operator.contains(sol(t), y, t, tol=1e-5), (t, y, sol.y(t))
    a, b = 0.3, 1.7
    inside = [k for k in sol.kinks if a < k < b]
    ref, _ = quad_vec(p.u, a, b, epsabs=1e-10, points=inside or None)
    assert np.max(np.abs(p.U(b) - p.U(a) - ref)) < 1e-7


# -- the scheme ---------------------------------------------------------------------------------------------------


def _study(rec):
    return rec.details["study"]


@pytest.mark.parametrize("name", EXAMPLES)
def test_proximal_scheme_reaches_the_stated_order_against_the_exact_solution(name, request):
    p = request.getfixturevalue(name)
    rec = check_convergence_order(vm.solve, p)
    study = _study(rec)
    assert rec.status == "passed", rec.message
    assert study.reference == "exact solution"
    fit = study.order
    assert fit.contains(p.order.value), str(fit)           # measured, not merely reached: the stated order
    # the derived error bounds hold at every grid (with the measured Lipschitz constants)
    for h, e in zip(study.mesh, study.errors["sup"]):
        assert e <= p.exact.error_bound(h, p.lipschitz)
        if name == "box":
            assert e <= len(p.exact.kinks) * p.exact.lipschitz_y * h * h / 2


@pytest.mark.parametrize("name", EXAMPLES)
@pytest.mark.parametrize("broken", [drops_field, drops_input], ids=["drops_f", "drops_u"])
def test_a_stepper_dropping_f_or_u_fails(name, broken, request):
    p = request.getfixturevalue(name)
    rec = check_convergence_order(broken, p)
    assert rec.status == "failed"
    assert _study(rec).order.high < 0.1 and min(_study(rec).errors["sup"]) > 0.3   # a wrong limit: order 0


def test_an_operator_at_the_wrong_time_fails_the_order_two_problem(box):
    rec = check_convergence_order(wrong_time, box)
    assert rec.status == "failed"
    assert _study(rec).order.contains(1.0) and not _study(rec).order.contains(2.0)


@pytest.mark.parametrize("name", ["norm", "lcs"])
def test_an_operator_at_the_wrong_time_converges_with_order_one_but_leaves_the_graph(name, request):
    """At order 1 the lag is an O(h) perturbation (module docstring): the wrong-time stepper *passes* the order
    check here — a limit of order checks, stated, not hidden.  What exposes it is its discrete velocity:
    y_{k+1} = (x_k + h f(x_k) + ∫u - x_{k+1})/h lies in F(t_k, x_{k+1}), not in F(t_{k+1}, x_{k+1})."""
    p = request.getfixturevalue(name)
    assert check_convergence_order(wrong_time, p).status == "passed"
    t = vm.uniform_grid(p.T, steps=100)
    dU = p.input_increments(t)

    def outside(x):
        h = np.diff(t)
        y = (x[:-1] + h[:, None] * np.array([p.f(xk) for xk in x[:-1]]) + dU - x[1:]) / h[:, None]
        return [k for k in range(len(h)) if not p.operator.contains(x[k + 1], y[k], t[k + 1])]

    assert outside(vm.solve(p, t).x) == []
    assert len(outside(wrong_time(p, t))) >= 5


# -- construction ------------------------------------------------------------------------------------------------


def test_a_jump_of_x_star_is_refused():
    F = vm.NormalCone(vm.sets.Ball([0.0, 0.0], 1.0))
    with pytest.raises(vm.InvalidProblem, match="jumps near t = 0.5"):
        vm.manufactured_problem(F, T=1.0, path=lambda t: np.array([2.0 if t < 0.5 else -2.0, 0.0]))


def test_bad_arguments_are_refused(disc):
    F = disc.operator
    for kw in ({"mu": 0.0}, {"mu": -1.0}, {"T": 0.0}, {"x0": [0.0, 0.0]}, {"exact": None},
               {"path": lambda t: np.zeros(3)}):
        with pytest.raises(vm.InvalidProblem):
            vm.manufactured_problem(F, **{"T": 1.0, **kw})
    with pytest.raises(vm.InvalidProblem, match="tabulated on"):
        disc.U(disc.T + 1.0)
    with pytest.raises(vm.InvalidProblem, match="Lipschitz constant of f"):
        disc.exact.error_bound(0.1)


def test_default_path_and_a_given_velocity():
    path = mf.lissajous(3, amplitude=2.0, center=[1.0, 0.0, 0.0])
    assert np.allclose(path(0.0), [3.0, 0.0, 2.0]) and np.allclose(path(math.pi / 2), [1.0, 0.0, 0.0])
    assert np.allclose(path(math.pi / 4), [1.0 + math.sqrt(2), 2.0, -math.sqrt(2)])
    F = vm.L1Subdifferential(lambda t: 1.0 + 0.2 * t, dim=1)

    def xdot(t):                       # x* = sgn(z) max(|z| - μc, 0), z = 2 sin t, c = 1 + t/5, μ = 1
        z = 2 * math.sin(t)
        return np.array([2 * math.cos(t) - 0.2 * math.copysign(1.0, z) if abs(z) > 1 + 0.2 * t else 0.0])

    given = vm.manufactured_problem(F, T=3.0, path=lambda t: np.array([2 * math.sin(t)]), velocity=xdot)
    fd = vm.manufactured_problem(F, T=3.0, path=lambda t: np.array([2 * math.sin(t)]))
    for t in (0.2, 1.0, 2.5):
        assert np.allclose(given.u(t), fd.u(t), atol=1e-7)
    assert len(fd.exact.kinks) == 2                       # |2 sin t| = 1 + 0.2t twice on [0, 3]


def test_a_problem_travels_by_value(disc):
    """A module holding ``problem = manufactured_problem(...)`` is shipped to workers by cloudpickle."""
    copy = cloudpickle.loads(cloudpickle.dumps(disc))
    t = vm.uniform_grid(disc.T, steps=64)
    assert np.array_equal(vm.solve(copy, t).x, vm.solve(disc, t).x)
    assert copy.exact.kinks == disc.exact.kinks and copy.notes == disc.notes


def test_the_stepper_battery_takes_manufactured_problems(box, norm, lcs):
    """The public battery runs on them: the paper's scheme passes every law it runs (the skips are the bounds
    lemmas, which cover f = 0), and the wrong-time stepper breaks ``selections`` on each of the three."""
    good = vm.check_stepper(vm.solve, problems=[box, norm, lcs], generated=0)
    assert good.ok and not good.failures and len([r for r in good if r.status == "passed"]) >= 15
    bad = vm.check_stepper(wrong_time, problems=[box, norm, lcs], generated=0, orders=False, laws=["selections"])
    assert [r.check for r in bad.failures] == ["selections"] * 3


# -- regularity, derived from the construction ---------------------------------------------------------------------

M_SMOOTH = np.array([[1.0, 2.0], [-2.0, 0.5]])


def test_regularity_is_that_of_the_construction(norm):
    """Smooth where the path and the operator are: a Linear operator, or a set the path never leaves, gives a smooth
    solution (regularity inf: a scheme claiming order 5 is held to 5); a kink of x* caps it at 1; a field that is only
    Lipschitz along x* (a kink of the input, none of x*) at 2; a stated smoothness of the data caps it there.  Before,
    every manufactured problem stated 1 ("0 kinks detected: order 1 at most") and an order-1 bug claimed as order 5
    passed on a smooth one."""
    linear = vm.manufactured_problem(vm.Linear(M_SMOOTH), T=T)
    inside = vm.manufactured_problem(vm.NormalCone(vm.sets.Ball(np.zeros(2), 3.0)), T=T)   # |z| <= 1.5 * sqrt(2) < 3
    for p in (linear, inside):
        assert p.exact.kinks == () and p.exact.input_kinks == ()
        assert p.order.regularity == math.inf and p.order.value == 1.0
        assert "no kink" in p.order.regularity_source
    assert norm.order.regularity == 1.0 and "4 kinks" in norm.order.regularity_source
    stated = vm.manufactured_problem(vm.Linear(M_SMOOTH), T=3.0, smoothness=3)
    assert stated.order.regularity == 3.0
    with pytest.raises(vm.InvalidProblem):
        vm.manufactured_problem(vm.Linear(M_SMOOTH), T=3.0, smoothness=0.5)


@pytest.mark.parametrize("amplitude", [1.5, 0.8])
def test_a_field_lipschitz_along_the_solution_kinks_the_input_only(amplitude):
    """``f(x) = -|x|/2`` (componentwise) with ``x* = (I + μM)^{-1} z(t)``: ``x*`` is smooth, ``u`` kinks where a
    component of ``x*`` crosses 0 — located there (against the closed form; at ``t = π/2`` both cross at a cell edge
    of the tabulation) and the regularity is 2."""
    A = np.linalg.inv(np.eye(2) + M_SMOOTH)
    path = mf.lissajous(2, amplitude=amplitude)
    p = vm.manufactured_problem(vm.Linear(M_SMOOTH), T=T, path=path, f=lambda x: -0.5 * np.abs(x), lipschitz=0.5)
    crossings = sorted(sum((_roots(lambda t, i=i: float((A @ path(t))[i]), T) for i in range(2)), []))
    crossings = [c for i, c in enumerate(crossings) if i == 0 or c - crossings[i - 1] > 1e-9]   # both at once at z = 0
    assert p.exact.kinks == ()
    assert len(p.exact.input_kinks) == len(crossings) >= 4
    assert np.max(np.abs(np.array(p.exact.input_kinks) - crossings)) < KINK_ACCURACY * T
    assert p.order.regularity == 2.0 and "order 2 at most" in p.order.regularity_source
