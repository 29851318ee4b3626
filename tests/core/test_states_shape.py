"""A stepper's states of the wrong shape: a typed error naming the likely cause (docs/users.md).

probe8: solve_nivp (ERC-INJECT/solve_nivp c82f2bc) steps ``while t < tf: t += h`` on a fixed step, so on
``h = T/K`` whose sum falls short of ``T`` by round-off it takes one more step of ~1e-16 and returns ``K + 2``
states; the record said only "returned shape (12, 1), expected (11, 1)" (a ``ValueError`` in the laws on
partitions, an ``InvalidProblem`` in the convergence study).
"""

import numpy as np
import pytest

import verimono as vm
from verimono.checks import check_in_domain
from verimono.reference import subdifferential


def _past_the_end(problem, t_grid):
    """The fixed-step driver ``while t < T: t += h`` (solve_nivp's), with verimono's scheme as its step."""
    h, T = t_grid[1] - t_grid[0], t_grid[-1]
    t, x = float(t_grid[0]), [np.array(problem.x0, dtype=float)]
    while t < T:
        step = min(h, T - t)
        x.append(problem.operator.resolvent(x[-1], step, t + step))
        t += step
    return np.array(x)


def _flat(problem, t_grid):
    return vm.solve(problem, t_grid).x[:, 0]


def _transposed(problem, t_grid):
    return vm.solve(problem, t_grid).x.T


def _no_x0(problem, t_grid):
    return vm.solve(problem, t_grid).x[1:]


CASES = [(_past_the_end, "one state more than the 11 nodes"), (_flat, "a flat array for a problem of dimension 1"),
         (_transposed, "the transpose"), (_no_x0, "one state fewer than the 11 nodes")]


@pytest.mark.parametrize("stepper, cause", CASES, ids=[c[0].__name__ for c in CASES])
def test_a_wrong_shape_is_an_invalid_problem_naming_its_cause(stepper, cause):
    problem = subdifferential.t_norm()
    grid = vm.uniform_grid(problem.T, steps=10)
    if stepper is _past_the_end:        # the premise: h = T/10 sums to less than T, so the loop steps once more
        assert sum([grid[1] - grid[0]] * 10) < problem.T
    rec = check_in_domain(stepper, problem, grids=[grid])
    assert rec.status == "failed" and "InvalidProblem" in rec.message and cause in rec.message, rec
    assert "expected (11, 1)" in rec.message
    with pytest.raises(vm.InvalidProblem, match=cause.replace("11", r"\d+")):
        vm.convergence_study(stepper, problem, [problem.T / 10, problem.T / 20, problem.T / 40])


def test_the_correct_shape_passes_and_an_unexplained_one_is_still_named():
    problem = subdifferential.t_norm()
    grid = vm.uniform_grid(problem.T, steps=10)
    assert check_in_domain(lambda p, t: vm.solve(p, t).x, problem, grids=[grid]).status == "passed"
    rec = check_in_domain(lambda p, t: np.zeros((3, 2)), problem, grids=[grid])
    assert rec.status == "failed" and rec.message.endswith("returned shape (3, 2), expected (11, 1): one state per "
                                                           "node of t_grid, x_0 first"), rec
