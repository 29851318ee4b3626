"""Catalog operators: resolvents against closed forms and against independent computations.

The independent computation is the proximal problem itself: for ``F = ∂g``,
``J_λ x = argmin_z g(z) + |z - x|²/(2λ)``, solved here by scipy's minimiser (or a scalar root-finder),
never by the code under test.  Tolerances: closed forms are compared at ``tolerance()`` (RTOL scaled to
the inputs); the generic minimiser is accurate to about 1e-6, which is the tolerance used with it.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq, minimize

import verimono as vm
from verimono.core.sets import Ball, Box, HalfSpace, Polyhedron, Translated
from verimono.core.tolerances import tolerance

RNG = np.random.default_rng(20261122)
MINIMIZER_TOL = 1e-5


def prox_by_minimisation(g, x, lam):
    res = minimize(lambda z: g(z) + np.sum((z - x) ** 2) / (2 * lam), x, method="Nelder-Mead",
                   options=dict(xatol=1e-10, fatol=1e-14, maxiter=20000, maxfev=40000))
    return res.x


@pytest.mark.parametrize("t", [0.0, 0.7, 2.5])
def test_norm_subdifferential_is_prox_of_c_norm(t):
    op = vm.NormSubdifferential(lambda s: 1.0 + s, dim=3)
    for _ in range(5):
        x, lam = RNG.normal(size=3) * 2, RNG.uniform(0.05, 1.5)
        J = op.resolvent(x, lam, t)
        ref = prox_by_minimisation(lambda z: (1 + t) * np.linalg.norm(z), x, lam)
        assert np.allclose(J, ref, atol=MINIMIZER_TOL)
        # closed form: block soft thresholding
        assert np.allclose(J, max(1 - lam * (1 + t) / np.linalg.norm(x), 0) * x, atol=tolerance(x))


def test_norm_subdifferential_min_norm_and_membership():
    op = vm.NormSubdifferential(2.0, dim=2)
    x = np.array([3.0, 4.0])
    assert np.allclose(op.min_norm(x), [1.2, 1.6])
    assert op.contains(x, [1.2, 1.6]) and not op.contains(x, [1.0, 1.6])
    assert op.contains(np.zeros(2), [1.0, -1.5]) and not op.contains(np.zeros(2), [2.0, 1.0])
    assert np.allclose(op.min_norm(np.zeros(2)), 0.0)


def test_l1_resolvent_is_soft_thresholding_and_prox():
    c = np.array([0.5, 1.0, 0.0])
    op = vm.L1Subdifferential(c, dim=3)
    x, lam = np.array([1.0, -0.3, 2.0]), 0.8
    J = op.resolvent(x, lam)
    assert np.allclose(J, [0.6, 0.0, 2.0])
    ref = prox_by_minimisation(lambda z: np.sum(c * np.abs(z)), x, lam)
    assert np.allclose(J, ref, atol=MINIMIZER_TOL)
    assert op.contains(J, (x - J) / lam)


def test_linear_resolvent_solves_the_linear_system_and_is_cached():
    M = np.array([[1.0, 2.0], [-2.0, 0.0]])  # M + Mᵀ = diag(2, 0) ⪰ 0, not symmetric
    op = vm.Linear(M)
    x, lam = np.array([1.0, -2.0]), 0.3
    J = op.resolvent(x, lam)
    assert np.allclose((np.eye(2) + lam * M) @ J, x, atol=tolerance(x))
    first = op._cache_inv
    op.resolvent(x, lam)
    assert op._cache_inv is first  # the factor is reused for the same step


def test_linear_time_dependent_and_batched():
    op = vm.Linear(lambda t: np.array([[t, 1.0], [-1.0, t]]))
    X = RNG.normal(size=(4, 2))
    for t in (0.0, 1.5):
        J = op.resolvent(X, 0.5, t)
        for xi, Ji in zip(X, J):
            assert np.allclose((np.eye(2) + 0.5 * op.M(t)) @ Ji, xi)


def test_linear_growth_is_the_spectral_norm_of_M_at_t():
    """``|M(t)x| ≤ ‖M(t)‖₂ |x|``: the largest singular value, kept once for a constant ``M`` and read at ``t`` for a
    moving one (closed forms: a nonsymmetric monotone ``M``, ``σ_max = √λ_max(MᵀM)``, and ``M(t) = diag(t, 2t)``)."""
    shear = vm.Linear(np.array([[1.0, 2.0], [-2.0, 0.0]]))
    sigma = np.sqrt(np.linalg.eigvalsh(np.array([[5.0, 2.0], [2.0, 4.0]]))[-1])   # sqrt(λmax(MᵀM))
    assert shear.growth() == pytest.approx(sigma, rel=1e-14)
    assert shear.growth(7.0) == shear.growth(0.0)
    moving = vm.Linear(lambda t: np.diag([t, 2.0 * t]))
    assert moving.growth(0.5) == pytest.approx(1.0, rel=1e-14)
    assert moving.growth(3.0) == pytest.approx(6.0, rel=1e-14)


def test_linear_rejects_non_monotone():
    with pytest.raises(vm.NotMonotone, match="positive semidefinite"):
        vm.Linear([[1.0, 0.0], [0.0, -0.5]])


def test_normal_cone_resolvent_is_projection_for_every_lambda():
    S = Ball([1.0, 0.0], 0.5)
    op = vm.NormalCone(S)
    x = np.array([3.0, 0.0])
    for lam in (0.01, 1.0, 100.0):
        assert np.allclose(op.resolvent(x, lam), [1.5, 0.0])
    assert op.contains([1.5, 0.0], [2.0, 0.0]) and not op.contains([1.5, 0.0], [0.0, 1.0])
    assert op.contains([1.2, 0.1], [0.0, 0.0]) and not op.contains([1.2, 0.1], [0.1, 0.0])
    with pytest.raises(vm.OutsideDomain):
        op.min_norm(np.array([5.0, 0.0]))


def test_shifted_resolvent_and_input_shift_identity():
    """G(t, x) = F(t, x + Φ(t)): J^G(x) = J^F(x + Φ) - Φ (lemma l:extinput)."""
    F = vm.NormSubdifferential(1.0, dim=2)
    Phi = lambda t: np.array([t, -2 * t])  # noqa: E731
    G = vm.Shifted(F, Phi)
    x, t = np.array([0.5, 0.5]), 0.8
    assert np.allclose(G.resolvent(x, 0.3, t), F.resolvent(x + Phi(t), 0.3, t) - Phi(t))
    y = G.yosida(x, 0.3, t)
    assert G.contains(G.resolvent(x, 0.3, t), y, t)


def test_log_barrier_resolvent_solves_quadratic_without_cancellation():
    op = vm.LogBarrier(2.0)
    for x in (-1e8, -3.0, 0.0, 0.5, 1e6):
        lam = 0.1
        z = op.resolvent(np.array([x]), lam)[0]
        assert z > 0
        root = brentq(lambda s: s - 2.0 * lam / s - x, 1e-300, max(abs(x), 1.0) * 4 + 10)
        assert z == pytest.approx(root, rel=1e-12)
    with pytest.raises(vm.OutsideDomain):
        op.min_norm(np.array([0.0]))


@pytest.mark.parametrize("make", [
    lambda: Ball([0.5, -0.5], 1.5),
    lambda: Box([-1.0, 0.0], [0.5, np.inf]),
    lambda: HalfSpace([1.0, 2.0], 0.5),
    lambda: Polyhedron([[1.0, 1.0], [-1.0, 0.0], [0.0, -1.0]], [1.0, 0.0, 0.0]),
    lambda: Polyhedron([[1.0, 1.0, 0.0]], [1.0], A=[[0.0, 0.0, 1.0]], b=[0.25]),
])
@pytest.mark.filterwarnings("ignore:delta_grad == 0.0:UserWarning")
def test_projections_match_a_generic_constrained_minimiser(make):
    """proj_S(x) = argmin |z - x|² over S, checked against SLSQP (independent of verimono's QP path)."""
    from scipy.optimize import LinearConstraint, NonlinearConstraint

    S = make()
    rng = np.random.default_rng(7)   # its own stream: the draws do not depend on which tests ran before
    for _ in range(6):
        x = rng.normal(size=S.dim) * 3
        p = S.project(x)
        assert S.contains(p)
        if isinstance(S, Ball):
            cons = [NonlinearConstraint(lambda z: np.sum((z - S.center()) ** 2), -np.inf, S.radius() ** 2)]
        elif isinstance(S, Box):
            lo, hi = np.broadcast_arrays(S.lower(), S.upper())
            cons = [LinearConstraint(np.eye(S.dim), lo, hi)]
        elif isinstance(S, HalfSpace):
            cons = [LinearConstraint(S.normal()[None, :], -np.inf, S.offset())]
        else:
            G, h, A, b = S.data()
            cons = [LinearConstraint(G, -np.inf, h)] + ([LinearConstraint(A, b, b)] if A is not None else [])
        ref = minimize(lambda z: np.sum((z - x) ** 2), x * 0, jac=lambda z: 2 * (z - x), constraints=cons,
                       method="SLSQP", options=dict(ftol=1e-14, maxiter=1000)).x
        assert np.allclose(p, ref, atol=1e-7), (x, p, ref)   # SLSQP at ftol 1e-14 is good to ~1e-8 here
        # variational inequality: <x - p, z - p> <= 0 for points z of S (sampled by projection)
        for _ in range(5):
            z = S.project(rng.normal(size=S.dim) * 3)
            assert (x - p) @ (z - p) <= tolerance(x, z)


def test_moving_sets_depend_on_time():
    S = Ball(lambda t: np.array([t, 0.0]), lambda t: 1.0 + t)
    assert np.allclose(S.project(np.array([5.0, 0.0]), t=2.0), [5.0, 0.0])
    assert np.allclose(S.project(np.array([5.0, 0.0]), t=0.0), [1.0, 0.0])
    H = HalfSpace([0.0, 1.0], lambda t: -t)
    assert np.allclose(H.project(np.array([1.0, 0.0]), t=1.0), [1.0, -1.0])
    B = Box(lambda t: np.array([t]), lambda t: np.array([t + 1]))
    assert B.project(np.array([0.0]), 3.0)[0] == 3.0


def test_batched_points_give_rowwise_results():
    X = RNG.normal(size=(7, 3))
    for op in (vm.NormSubdifferential(0.7, dim=3), vm.L1Subdifferential(0.3, dim=3),
               vm.NormalCone(Ball(np.zeros(3), 1.0)), vm.NormalCone(Box(-np.ones(3), np.ones(3))),
               vm.NormalCone(HalfSpace([1.0, 0.0, 1.0], 0.2)), vm.Linear(np.eye(3)),
               vm.NormalCone(Polyhedron(np.eye(3), np.ones(3) * 0.1)), vm.LogBarrier(1.0, dim=3)):
        J = op.resolvent(X, 0.4, 0.0)
        assert J.shape == X.shape
        assert np.allclose(J, np.stack([op.resolvent(x, 0.4, 0.0) for x in X]))


def test_a_batch_of_operators_needs_a_batch_of_points():
    """c of shape (B,) is B operators, one per row of a (B, n) batch; against one point (n,) it would
    broadcast silently when B = n (operators mixed with coordinates), so it is an InvalidProblem."""
    op = vm.NormSubdifferential(np.array([0.1, 0.2, 0.3]), dim=3)
    X = RNG.normal(size=(3, 3))
    rows = [vm.NormSubdifferential(c, dim=3).resolvent(x, 0.5) for c, x in zip([0.1, 0.2, 0.3], X)]
    np.testing.assert_array_equal(op.resolvent(X, 0.5), np.stack(rows))
    ball = Ball(np.zeros(2), np.array([1.0, 2.0]))
    for call in (lambda: op.resolvent(np.ones(3), 0.5), lambda: op.min_norm(np.ones(3)),
                 lambda: op.resolvent(np.ones((2, 3)), 0.5), lambda: ball.project(np.ones(2) * 3)):
        with pytest.raises(vm.InvalidProblem, match="batch of"):
            call()


def test_operator_from_resolvent_missing_members_raise_not_implemented():
    op = vm.operator_from_resolvent(lambda x, lam, t: x / (1 + lam), 2, name="identity flow")
    assert np.allclose(op.resolvent(np.array([2.0, 4.0]), 1.0), [1.0, 2.0])
    assert np.allclose(op.yosida(np.array([2.0, 4.0]), 1.0), [1.0, 2.0])
    for call in (lambda: op.min_norm(np.ones(2)), lambda: op.project_domain(np.ones(2)),
                 lambda: op.contains(np.ones(2), np.ones(2))):
        with pytest.raises(NotImplementedError):
            call()
    op2 = vm.operator_from_resolvent(lambda x, lam, t: x / (1 + lam), 2,
                                     contains=lambda x, y, t: np.allclose(x, y))
    assert op2.contains(np.ones(2), np.ones(2))


@pytest.mark.parametrize("t", [0.0, 1.3])
def test_time_dependent_l1_and_log_barrier_against_independent_solves(t):
    l1 = vm.L1Subdifferential(lambda s: np.array([0.2 + s, 1.0]), dim=2)
    x, lam = np.array([1.7, -0.4]), 0.6
    ref = prox_by_minimisation(lambda z: (0.2 + t) * abs(z[0]) + abs(z[1]), x, lam)
    assert np.allclose(l1.resolvent(x, lam, t), ref, atol=MINIMIZER_TOL)
    lb = vm.LogBarrier(lambda s: 1.0 + s * s)
    c = 1.0 + t * t
    root = brentq(lambda s: s - lam * c / s - 0.3, 1e-12, 10.0)
    assert lb.resolvent(np.array([0.3]), lam, t)[0] == pytest.approx(root, rel=1e-12)
    assert lb.contains(np.array([root]), np.array([-c / root]), t)


def test_membership_at_a_kink_reached_through_rounding():
    """Shifted twice, J lands on the kink x = 0 of |x| only up to the rounding of the shifts: the
    Yosida value must still be accepted (graph distance ≤ tol), and a wrong one still rejected."""
    F = vm.Shifted(vm.Shifted(vm.NormSubdifferential(1.0, dim=2), [0.1, 0.7]), [0.2, -0.3])
    x, lam = np.array([-0.25, -0.35]), 2.0            # |x + Φ| < λc: J^F lands on the kink
    J, Y = F.resolvent(x, lam), F.yosida(x, lam)
    assert F.contains(J, Y)
    assert not F.contains(J, Y * 40.0)                # |40 Y| = 1.41 > c = 1: outside the ball at the kink
    l1 = vm.Shifted(vm.L1Subdifferential(1.0, dim=2), [0.3, 0.1])
    J, Y = l1.resolvent(np.array([-0.1, 2.0]), 1.0), l1.yosida(np.array([-0.1, 2.0]), 1.0)
    assert l1.contains(J, Y) and not l1.contains(J, Y + np.array([0.0, 0.5]))


def test_resolvent_rows_batches_only_what_declares_it():
    """resolvent_rows: one vectorized call for a catalog operator (the same bits as row by row), one call per
    row for a user's operator — whose resolvent may treat a (B, n) array as one point — and for a catalog
    subclass that overrides the resolvent."""
    from verimono.core.operators import resolvent_rows

    X = RNG.normal(size=(5, 2))
    calls = []

    class Counting(vm.NormSubdifferential):
        def resolvent(self, x, lam, t=0.0):
            calls.append(np.shape(x))
            return super().resolvent(x, lam, t)

    for op in (vm.NormSubdifferential(0.7, dim=2), vm.Shifted(vm.L1Subdifferential(0.3, dim=2), [0.1, -0.2]),
               vm.NormalCone(Translated(Ball(np.zeros(2), 1.0), lambda t: np.array([t, 0.0])))):
        assert op._accepts_batches()
        np.testing.assert_array_equal(resolvent_rows(op, X, 0.4, 0.5), np.stack([op.resolvent(x, 0.4, 0.5) for x in X]))
    whole = vm.operator_from_resolvent(lambda x, lam, t: x * max(1 - lam / np.linalg.norm(x), 0.0), 2)
    assert not whole._accepts_batches()
    np.testing.assert_allclose(resolvent_rows(whole, X, 0.4), resolvent_rows(vm.NormSubdifferential(1.0, dim=2), X, 0.4),
                               rtol=1e-14)
    sub = Counting(0.7, dim=2)
    assert not sub._accepts_batches() and resolvent_rows(sub, X, 0.4).shape == X.shape and calls == [(2,)] * 5


def test_catalog_subdifferentials_state_their_function_and_pass_the_value_laws():
    """NormSubdifferential and L1Subdifferential are ∂g of known g, so the prox laws run on them (instead of
    being skipped); a value off by a factor 2 is caught by every value law."""
    import numpy as np
    import verimono as vm
    from verimono.checks.operator_battery import LAWS

    names = {name for name, decl in LAWS.items() if decl.evaluate.__module__ == "verimono.checks.prox_laws"}
    norm = vm.NormSubdifferential(lambda t: 1.0 + t, dim=3)
    l1 = vm.L1Subdifferential([1.0, 2.0, 0.5], dim=3)
    x = np.array([3.0, -4.0, 0.0])
    assert norm.value(x, 1.0) == 10.0 and l1.value(x) == 11.0
    for op in (norm, l1):
        rep = vm.check_operator(op, seed=0)
        assert rep.ok and all(r.status == "passed" for r in rep if r.check in names), rep.summary()

    class Doubled(vm.L1Subdifferential):
        def value(self, x, t=0.0):
            return 2.0 * super().value(x, t)

    failed = {r.check for r in vm.check_operator(Doubled(1.0, dim=3), seed=0).failures}
    assert failed == names


def _operators_with_kernels():
    from verimono.checks.sample_problems import sample_problems
    from verimono.reference import catalog

    return [(p.name, p) for p in list(catalog()) + list(sample_problems(0, 6))]


@pytest.mark.parametrize("name,problem", _operators_with_kernels(), ids=lambda v: v if isinstance(v, str) else "")
def test_the_resolvent_kernel_returns_exactly_the_resolvent(name, problem):
    """``resolvent_kernel`` (what ``solve`` steps with and the selections' witnesses are computed with) gives
    the operator's own ``resolvent`` bit for bit, at points near and far from ``x0``, steps across decades and
    times over ``[0, T]``; an instance whose ``resolvent`` is replaced gets the replacement."""
    op, x0 = problem.operator, np.asarray(problem.x0, dtype=float)
    step = vm.core.operators.resolvent_kernel(op, x0)
    rng = np.random.default_rng(7)
    # where kernels and resolvents part ways: the kink x = 0, far points, the domain's boundary (a far point
    # projected onto it), steps from 1e-12 to 1e3, the ends of [0, T]; then 300 draws across decades
    far = x0 + 1e6 * (1.0 + np.abs(x0).max()) * rng.normal(size=x0.shape)
    edges = [np.zeros_like(x0), x0, far]
    for t in (0.0, problem.T):
        try:
            edges.append(np.asarray(op.project_domain(far, t), dtype=float))
        except NotImplementedError:
            pass
    cases = [(x, lam, t) for x in edges for lam in (1e-12, 1e-6, 1.0, 1e3) for t in (0.0, problem.T)]
    for _ in range(300):
        x = x0 + rng.normal(size=x0.shape) * 10.0 ** rng.uniform(-4, 6)
        cases.append((x, 10.0 ** rng.uniform(-10, 3), float(rng.uniform(0.0, problem.T))))
    for x, lam, t in cases if step != op.resolvent else []:   # no kernel (the complementarity systems): none
        assert np.array_equal(np.asarray(step(x, lam, t), dtype=float), np.asarray(op.resolvent(x, lam, t), dtype=float)), \
            (x, lam, t)
    calls = []
    op.resolvent = lambda x, lam, t=0.0: calls.append(lam) or type(op).resolvent(op, x, lam, t)
    try:
        vm.core.operators.resolvent_kernel(op, x0)(x0, 0.5, 0.0)
    finally:
        del op.resolvent
    assert calls == [0.5]


@pytest.mark.parametrize("far", [4e154, 3e200, 1e300])
def test_far_points_beyond_the_square_root_of_the_largest_double(far):
    """The operator laws' step decades reach resolvent arguments of 1e154 and more (the resolvent identity at
    λ = 1e-153); there d·d overflows.  The ball's projection came back as its centre (d·(r/inf) = 0), the log
    barrier's resolvent warned of an overflow: both now compute without it; the ball's kernel (solve's path) gives
    the same point."""
    import warnings

    ball = vm.NormalCone(Ball(np.array([1.0, -2.0]), 2.0))
    x = np.array([0.6 * far, -0.8 * far])
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        p = ball.resolvent(x, 1.0, 0.0)
        np.testing.assert_allclose(p, [1.0 + 1.2, -2.0 - 1.6], rtol=1e-12)
        barrier = vm.LogBarrier(1.0, 2)
        y = barrier.resolvent(np.array([-far, far]), 10.0, 0.0)
        assert np.all(np.isfinite(y)) and y[1] == far and 0.0 < y[0] <= 2.0 * 10.0 / far
    step = ball._kernel(np.zeros(2))       # the per-step kernel: the same point (numpy may warn of its d·d)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        np.testing.assert_allclose(step(x, 1.0, 0.0), p, rtol=1e-15)
