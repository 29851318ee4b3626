"""The analytic references: their exact solutions solve the inclusion, and the scheme's error obeys the
closed forms derived in their docstrings.

The inclusion is checked with a central difference ``(x(t+δ) - x(t-δ))/2δ`` whose error is
``O(δ²)·max|x'''|``; with ``δ = 1e-6`` and unit-size data that is far below ``FD_TOL = 1e-5``, while
round-off of the quotient is about ``ε/δ ≈ 1e-10``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import verimono as vm
from verimono.reference import catalog, get, linear, subdifferential, sweeping

FD_DELTA, FD_TOL = 1e-6, 1e-5
NAMES = [p.name for p in catalog()]


def test_catalog_is_complete_and_documented():
    assert len(NAMES) == len(set(NAMES)) >= 12
    for p in catalog():
        assert p.exact is not None and p.order is not None and len(p.order.source) > 20
        assert p.steps and len(p.steps) >= 3


@pytest.mark.parametrize("name", NAMES)
def test_exact_solution_solves_the_inclusion(name):
    p = get(name)
    rng = np.random.default_rng(7)
    times = rng.uniform(2 * FD_DELTA, p.T - 2 * FD_DELTA, 25)
    for t in times:
        x = p.exact(t)
        assert p.operator.in_domain(x, t, tol=1e-9)
        d = (p.exact(t + FD_DELTA) - p.exact(t - FD_DELTA)) / (2 * FD_DELTA)
        drift = np.zeros_like(x)
        if p.f is not None:
            drift = drift + p.f(x)
        if p.u is not None:
            drift = drift + p.u(t)
        y = drift - d                                   # x' = -y + f + u with y ∈ F(t, x)
        if np.max(np.abs(np.diff([p.exact(t + s) for s in (-2 * FD_DELTA, 0, 2 * FD_DELTA)], 2, axis=0))) > 1e-9:
            continue                                    # a kink of x within 2δ of t: derivative undefined
        assert p.operator.contains(x, y, t, tol=FD_TOL), (t, x, y)
    assert np.allclose(p.exact(0.0), p.x0) or p.initial_jump


def test_t_norm_error_is_h_t_over_two_before_extinction():
    """|x_k| = r - t_k²/2 - h t_k/2: the error at t_k is exactly h t_k/2 while the discrete |x_k| > 0."""
    p = subdifferential.t_norm((0.6, 0.8, 0.0), T=2.0)
    h = p.T / 200
    tr = vm.solve(p, vm.uniform_grid(p.T, h))
    for t, x in zip(tr.t, tr.x):
        if np.linalg.norm(x) > 0 and t * t / 2 + h * t / 2 < 1.0:
            assert np.linalg.norm(x - p.exact(t)) == pytest.approx(h * t / 2, rel=1e-9, abs=1e-15)
    errs = [np.max(np.linalg.norm(vm.solve(p, vm.uniform_grid(p.T, h)).x - np.array([p.exact(s) for s in
            vm.uniform_grid(p.T, h)]), axis=1)) / h for h in (p.T / 1000, p.T / 4000)]
    assert errs[-1] == pytest.approx(math.sqrt(0.5), rel=2e-3)  # h sqrt(r/2) + O(h²), r = 1
    assert abs(errs[-1] - math.sqrt(0.5)) < abs(errs[0] - math.sqrt(0.5)) + 1e-12


@pytest.mark.parametrize("c", [0.5, 2.0])
def test_log_barrier_error_is_exactly_sqrt2_minus_1_times_sqrt_ch(c):
    p = subdifferential.log_barrier(c)
    for K in (50, 400):
        t = vm.uniform_grid(p.T, steps=K)
        err = np.abs(vm.solve(p, t).x[:, 0] - np.sqrt(2 * c * t))
        h = p.T / K
        assert np.argmax(err) == 1
        assert err.max() == pytest.approx((math.sqrt(2) - 1) * math.sqrt(c * h), rel=1e-12)


def test_linear_error_bound_holds_at_every_node():
    p = linear.linear()
    M, x0 = p.operator.M(), p.x0
    for K in (50, 400):
        t = vm.uniform_grid(p.T, steps=K)
        h = p.T / K
        err = np.linalg.norm(vm.solve(p, t).x - np.array([p.exact(s) for s in t]), axis=1)
        bound = t * h * np.linalg.norm(M @ M @ x0) / 2
        assert np.all(err <= bound * (1 + 1e-9))
        assert err[1] > 0.5 * bound[1]  # the bound is tight over the first steps, not vacuous


def test_half_space_error_is_one_minus_cos_half_step_over_norm_a():
    p = sweeping.moving_half_space()
    for K in (41, 321):
        t = vm.uniform_grid(p.T, steps=K)
        h = p.T / K
        err = np.linalg.norm(vm.solve(p, t).x - np.array([p.exact(s) for s in t]), axis=1).max()
        assert err == pytest.approx((1 - math.cos(h / 2)) / math.sqrt(5.0), rel=1e-9)


@pytest.mark.parametrize("name", ["play operator, u = sin t", "moving box"])
def test_play_error_bounded_by_interpolation_error(name):
    """|play(u) - play(u_PL)| ≤ |u - u_PL|∞ ≤ h² max|u''|/8 (max|u''| ≤ 1 here)."""
    p = get(name)
    for K in (41, 161):
        t = vm.uniform_grid(p.T, steps=K)
        h = p.T / K
        err = np.abs(vm.solve(p, t).x - np.array([p.exact(s) for s in t])).max()
        assert err <= h * h / 8 * (1 + 1e-9)


def test_translating_ball_stays_on_the_moving_sphere_after_contact():
    p = sweeping.translating_ball()
    S = p.operator.S
    for t in np.linspace(1.5, p.T, 20):
        x = p.exact(t)
        assert np.linalg.norm(x - S.center(t)) == pytest.approx(S.radius(t), rel=1e-12)


def test_lipschitz_input_uses_both_terms():
    p = linear.lipschitz_input()
    without_u = vm.Problem(p.operator, p.x0, p.T, f=p.f)
    t = vm.uniform_grid(p.T, steps=300)
    assert np.abs(vm.solve(p, t).x - vm.solve(without_u, t).x).max() > 0.1


def test_the_linear_references_exact_solution_is_the_closed_form_of_its_2x2_exponential():
    """``e^{-Mt} x0`` for the default ``M`` (trace 2s, ``(M - sI)² = -ω² I``) is ``e^{-st}(cos ωt x0 - sin ωt/ω
    (M - sI) x0)``: the reference's fast form agrees to round-off (6e-16 here; scipy's expm is 3e-14 off)."""
    import math

    from verimono.reference.linear import M_DEFAULT, linear

    p = linear()
    s = float(np.trace(M_DEFAULT)) / 2
    N = M_DEFAULT - s * np.eye(2)
    w = math.sqrt(-(N @ N)[0, 0])
    x0 = np.array([1.0, 0.0])
    for t in np.linspace(0.0, p.T, 401):
        closed = math.exp(-s * t) * (math.cos(w * t) * x0 - math.sin(w * t) / w * (N @ x0))
        assert np.max(np.abs(p.exact(t) - closed)) <= 1e-14
