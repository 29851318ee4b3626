"""The limit agreement says why its refinement stopped (probe8).

A user's moving box at n = 10^5 (given by its projection, no exact solution, the stepper verimono's own scheme)
was undecided after the levels K = 10, 40, 160, "the levels up to K = 160 cannot separate them": the next level
was not run because its (K + 1)·n numbers exceed MAX_LEVEL_NUMBERS (256 MB), which the record did not say.  Here
the same at n = 1000 with the cap lowered to stop at K = 160; with the cap as shipped the same problem passes.
"""

import numpy as np

import verimono as vm
from verimono.checks import agreement, check_convergence_order

N = 1000


def _moving_box():
    def proj(x, lam, t):
        return np.clip(x, -1.0 + np.sin(t), 1.0 + np.sin(t))
    op = vm.operator_from_resolvent(proj, N, name=f"moving box n={N}", project_domain=lambda x, t: proj(x, 1.0, t))
    x0 = np.clip(np.random.default_rng(0).standard_normal(N), -1.0, 1.0)
    return vm.Problem(op, x0=x0, T=2.0, name=f"moving box n={N}")


def _catching_up(problem, t_grid):
    x = [np.array(problem.x0, dtype=float)]
    for k in range(1, len(t_grid)):
        x.append(problem.operator.resolvent(x[-1], t_grid[k] - t_grid[k - 1], t_grid[k]))
    return np.array(x)


def test_a_level_not_run_for_its_size_is_named_in_the_undecided_record(monkeypatch):
    problem = _moving_box()
    monkeypatch.setattr(agreement, "MAX_LEVEL_NUMBERS", 161 * N)
    rec = check_convergence_order(_catching_up, problem)
    assert rec.status == "undecided", rec.message
    assert "the next level, K = 640, was not run" in rec.message and "MAX_LEVEL_NUMBERS" in rec.message, rec.message
    assert "a limit of the harness" in rec.message


def test_the_same_problem_with_the_cap_as_shipped_is_decided():
    rec = check_convergence_order(_catching_up, _moving_box())
    assert rec.status == "passed" and "agrees with verimono.solve's" in rec.message, rec.message
