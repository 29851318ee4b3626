"""Targets for the adaptive stage's time budget and `verimono compare`'s work ranges
(tests/integrators/test_adaptive_budget.py): explicit Euler as an adaptive stepper (its step is the tolerance)
with a sleep standing for a slow solver, and two fixed-grid steppers whose work ranges do not overlap."""

import time

import numpy as np

import verimono as vm
from verimono.reference import linear

problem = linear.linear()
#: the same problem with three step sizes: a short `verimono compare`
coarse = problem.replace(steps=[problem.T / 25, problem.T / 50, problem.T / 100])


def _euler(problem, t):
    x = [np.array(problem.x0, dtype=float)]
    for k in range(len(t) - 1):
        x.append(x[-1] - (t[k + 1] - t[k]) * np.asarray(problem.operator.min_norm(x[-1], t[k]), dtype=float))
    return np.array(x)


def slow_euler(problem, T, tol):
    """An RK45-like solver reduced to its cost: 0.2 s a call, then explicit Euler with the step ``tol``."""
    time.sleep(0.2)
    t = np.linspace(0.0, T, max(2, int(np.ceil(T / tol))) + 1)
    return t, _euler(problem, t)


slow = vm.Adaptive(slow_euler, rate=1.0, order=1.0, name="slow euler",
                   tolerances=[1e-2, 5e-3, 2.5e-3, 1.25e-3, 6.25e-4])


def cheap(problem, t_grid):
    """Explicit Euler: cheap runs on coarse grids."""
    return _euler(problem, np.asarray(t_grid, dtype=float))


def costly(problem, t_grid):
    """The proximal scheme, made to cost 20 ms of CPU a run more: its runs all cost more than the cheap one's."""
    end = time.thread_time() + 0.02
    while time.thread_time() < end:
        pass
    return vm.solve(problem, t_grid)


euler = vm.Stepper(cheap, scheme="any", order=1, name="euler")
proximal = vm.Stepper(costly, name="slow proximal")
