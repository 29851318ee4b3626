"""Targets of `verimono check ... --problem ... --only` (tests/checks/test_only_problems.py): a problem-specific
stepper that reads its parameters from ``problem.data`` (it cannot run any other problem: a KeyError), its
problems, and an explicit-Euler ODE integrator that declines set-valued operators with verimono.NotApplicable."""

import numpy as np

import verimono as vm


def _ball_problem(radius, name):
    # the ball of `radius` about (t, 0): x0 = (0, 0) inside; F its normal cone
    ball = vm.NormalCone(vm.sets.Ball(lambda t: np.array([t, 0.0]), radius))
    return vm.Problem(ball, x0=[0.0, 0.0], T=1.0, name=name, data={"radius": radius})


problems = [_ball_problem(0.5, "small ball"), _ball_problem(2.0, "large ball")]


def catching_up(problem, t_grid):
    """Catching-up with the projection onto the ball of its own stated radius: ``problem.data["radius"]``."""
    r = problem.data["radius"]                     # a KeyError on a problem that is not one of its own
    t = np.asarray(t_grid, dtype=float)
    x = [np.array(problem.x0, dtype=float)]
    for k in range(1, len(t)):
        c = np.array([t[k], 0.0])
        d = x[-1] - c
        x.append(c + d / max(1.0, float(np.linalg.norm(d)) / r))
    return np.array(x)


def euler(problem, t_grid):
    """Explicit Euler on x' = -F(t, x) + f(x) + u(t): an ODE integrator, for a single-valued F only."""
    if not isinstance(problem.operator, vm.Linear):
        raise vm.NotApplicable("an ODE integrator: F(t, ·) must be single-valued (a verimono.Linear operator), "
                               f"{problem.name} has a set-valued F")
    t = np.asarray(t_grid, dtype=float)
    x = [np.array(problem.x0, dtype=float)]
    dU = problem.input_increments(t)
    for k in range(1, len(t)):
        h = t[k] - t[k - 1]
        v = -np.asarray(problem.operator.min_norm(x[-1], t[k - 1]), dtype=float)
        if problem.f is not None:
            v = v + problem.f(x[-1])
        x.append(x[-1] + h * v + (dU[k - 1] if dU is not None else 0.0))
    return np.array(x)


ode_euler = vm.Stepper(euler, scheme="any", order=1, name="explicit Euler")
