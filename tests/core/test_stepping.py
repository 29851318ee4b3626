"""The proximal scheme: the defining inclusion, nonuniform grids, inputs, batches, interpolation."""

from __future__ import annotations

import math

import numpy as np
import pytest

import verimono as vm
from verimono.core.sets import Ball, Box
from verimono.core.tolerances import tolerance


def test_discrete_inclusion_holds_at_every_step():
    """(x_k - x_{k+1})/h_{k+1} ∈ F(t_{k+1}, x_{k+1}) (label eq:iteration), on a random grid."""
    op = vm.NormSubdifferential(lambda t: 1 + t, dim=2)
    p = vm.Problem(op, [1.5, -0.5], 1.0)
    tr = vm.solve(p, vm.random_grid(1.0, 60, seed=3))
    for k, y in enumerate(tr.selections):
        assert op.contains(tr.x[k + 1], y, tr.t[k + 1])


def test_t_norm_discrete_solution_in_closed_form_on_nonuniform_grid():
    """|x_{k+1}| = max(|x_k| - h_{k+1} t_{k+1}, 0) for g(t, x) = t|x|, on any partition."""
    x0 = np.array([0.6, 0.8])
    t = vm.graded_grid(2.0, 50, power=1.5)
    tr = vm.solve(vm.Problem(vm.NormSubdifferential(lambda s: s, dim=2), x0, 2.0), t)
    r = 1.0
    for k in range(50):
        r = max(r - (t[k + 1] - t[k]) * t[k + 1], 0.0)
        assert np.linalg.norm(tr.x[k + 1]) == pytest.approx(r, abs=1e-14)
        assert np.allclose(tr.x[k + 1], r * x0, atol=1e-14)


def test_catching_up_on_moving_set_projects_at_new_time():
    S = Ball(lambda t: np.array([t, 0.0]), 0.5)
    tr = vm.solve(vm.Problem(vm.NormalCone(S), [0.0, 0.0], 2.0), vm.uniform_grid(2.0, 0.5))
    for k in range(1, 5):
        assert S.contains(tr.x[k], tr.t[k])
        assert np.allclose(tr.x[k], S.project(tr.x[k - 1], tr.t[k]))


def test_input_enters_as_its_integral_and_f_explicitly():
    """x_{k+1} = J(x_k + h f(x_k) + ∫u): with F = 0 (Linear(0)) the scheme is explicit Euler plus exact ∫u."""
    p = vm.Problem(vm.Linear([[0.0]]), [1.0], 1.0, f=lambda x: -2.0 * x, u=lambda t: np.array([3 * t * t]))
    tr = vm.solve(p, vm.uniform_grid(1.0, 0.25))
    x = 1.0
    for k in range(4):
        a, b = 0.25 * k, 0.25 * (k + 1)
        x = x + 0.25 * (-2.0 * x) + (b ** 3 - a ** 3)
        assert tr.x[k + 1, 0] == pytest.approx(x, rel=1e-13)


def test_primitive_input_is_used_exactly():
    p = vm.Problem(vm.Linear([[1.0]]), [0.0], 1.0, U=lambda t: np.array([math.sin(t)]))
    tr = vm.solve(p, vm.uniform_grid(1.0, 0.5))
    x1 = (0.0 + math.sin(0.5)) / 1.5
    assert tr.x[1, 0] == pytest.approx(x1, rel=1e-14)


def test_batched_initial_points_match_separate_solves():
    op = vm.NormalCone(Box(lambda t: np.array([math.sin(t) - 0.3, -1.0]), lambda t: np.array([math.sin(t) + 0.3, 1.0])))
    X0 = np.array([[0.1, 0.5], [-0.2, -0.9], [0.0, 0.0]])
    grid = vm.random_grid(3.0, 40, seed=1)
    batch = vm.solve(vm.Problem(op, X0, 3.0), grid)
    assert batch.x.shape == (41, 3, 2)
    for b, x0 in enumerate(X0):
        single = vm.solve(vm.Problem(op, x0, 3.0), grid)
        assert np.array_equal(batch.x[:, b], single.x)


def test_trajectory_converts_and_interpolates():
    p = vm.Problem(vm.Linear([[1.0]]), [1.0], 1.0)
    tr = vm.solve(p, vm.uniform_grid(1.0, 0.5))
    assert np.asarray(tr).shape == (3, 1) and np.asarray(tr) is tr.x       # a view, as np.asarray promises
    copied = np.array(tr)                                                    # a copy, as np.array promises
    copied[:] = 99.0
    assert not np.any(tr.x == 99.0)
    mid = tr.interpolate(0.25)
    assert mid == pytest.approx(0.5 * (tr.x[0] + tr.x[1]))
    # ψ-interpolation (label e:x delta) with ψ(t) = t² puts τ = 0.25 at weight ψ-fraction 1/4
    val = tr.interpolate(0.25, kind="psi", psi=lambda s: s * s)
    assert val == pytest.approx(0.75 * tr.x[0] + 0.25 * tr.x[1])
    assert np.allclose(tr.interpolate(tr.t, kind="psi", psi=lambda s: s + s ** 3), tr.x)
    with pytest.raises(vm.InvalidProblem):
        tr.interpolate(2.0)
    with pytest.raises(vm.InvalidProblem, match="psi"):
        tr.interpolate(0.3, kind="psi")


def test_solve_is_a_stepper():
    p = vm.Problem(vm.NormSubdifferential(1.0), [1.0], 1.0)
    grid = vm.uniform_grid(1.0, 0.1)
    out = np.asarray(vm.solve(p, grid))
    assert out.shape == (len(grid), 1)
    assert np.all(np.abs(np.diff(out[:, 0])) <= 0.1 + tolerance(1.0))  # |x'| <= c = 1


def test_input_increments_integrate_quintics_exactly_with_the_nodes_computed_once():
    """3-point Gauss–Legendre is exact for polynomials of degree <= 5: the increments of u(t) = t^5 - 2t^2 are
    ∫ u = [t^6/6 - 2t^3/3] over every cell, to rounding (relative 1e-13 of the cell's |u| h: the data are O(1)).
    The nodes are computed once (``_GAUSS3``, read-only): a call cannot change another's."""
    from verimono.core import problem as problem_module
    from verimono.core.operators import Linear

    p = vm.Problem(Linear([[1.0]]), [0.0], 2.0, u=lambda s: np.array([s ** 5 - 2 * s ** 2]))
    t = np.array([0.0, 0.3, 0.35, 1.0, 1.7, 2.0])
    prim = t ** 6 / 6 - 2 * t ** 3 / 3
    for _ in range(2):
        got = p.input_increments(t)[:, 0]
        np.testing.assert_allclose(got, np.diff(prim), rtol=0, atol=1e-13 * 2.0 ** 5 * 2.0)
    nodes, weights = problem_module._GAUSS3
    assert not nodes.flags.writeable and not weights.flags.writeable
    assert np.array_equal(nodes, np.polynomial.legendre.leggauss(3)[0])
