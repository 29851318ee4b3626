"""Hand-written integrator wrappers, correct and with planted bugs, for the ODE references (``x' = -F(x) +
f(x) + u(t)`` with single-valued ``F``): Heun's method on a given grid, and the Heun–Euler pair with a step
controller (``verimono.Adaptive``).

Planted bugs: an input evaluated at the wrong time (the second stage reads ``u`` at the start of the step,
or the adaptive wrapper reads it shifted by ``shift``), a stage with ``h/2`` (the second stage at
``x + (h/2) k1``), and a controller that ignores its error estimate (the step grows by a fixed factor).
"""

from __future__ import annotations

import numpy as np

import verimono as vm
from verimono.core.recipes import ode_field


def _rhs(problem, shift=0.0):
    """The right-hand side, its input read at ``t + shift``."""
    op, f, u = problem.operator, problem.f, problem.u

    def rhs(t, x, t_input=None):
        v = -np.asarray(op.min_norm(x, t), dtype=float)
        if f is not None:
            v = v + f(x)
        if u is not None:
            v = v + u((t if t_input is None else t_input) + shift)
        return v
    return rhs


def heun_on_grid(problem, t_grid, *, bug=None):
    rhs = _rhs(problem)
    x = np.array(problem.x0, dtype=float)
    out = [x]
    for k in range(len(t_grid) - 1):
        t, h = t_grid[k], t_grid[k + 1] - t_grid[k]
        k1 = rhs(t, x)
        if bug == "stage_half":
            k2 = rhs(t + h, x + 0.5 * h * k1)
        elif bug == "input_time":
            k2 = rhs(t + h, x + h * k1, t_input=t)        # u read at the start of the step
        else:
            k2 = rhs(t + h, x + h * k1)
        x = x + 0.5 * h * (k1 + k2)
        out.append(x)
    return np.array(out)


def explicit_rk_on_grid(problem, t_grid, A, b, c):
    """The explicit Runge–Kutta scheme of Butcher tableau ``(A, b, c)`` (``A`` strictly lower triangular, as rows),
    one step per cell, on the single-valued right-hand side as :func:`heun_on_grid`."""
    rhs = _rhs(problem)
    x = np.array(problem.x0, dtype=float)
    out = [x]
    for k in range(len(t_grid) - 1):
        t, h = t_grid[k], t_grid[k + 1] - t_grid[k]
        stages = []
        for ci, ai in zip(c, A):
            y = x + h * sum(aij * kj for aij, kj in zip(ai, stages)) if ai else x
            stages.append(rhs(t + ci * h, y))
        x = x + h * sum(bi * ki for bi, ki in zip(b, stages))
        out.append(x)
    return np.array(out)


def bosh3_on_grid(problem, t_grid):
    """Bogacki–Shampine's three-stage explicit scheme of order 3 (its propagated solution, without the embedded
    order-2 estimate): P. Bogacki, L. F. Shampine, Appl. Math. Lett. 2 (1989) 321–325."""
    return explicit_rk_on_grid(problem, t_grid, [[], [0.5], [0.0, 0.75]], [2 / 9, 1 / 3, 4 / 9], [0.0, 0.5, 0.75])


def rk4_on_grid(problem, t_grid):
    """The classical four-stage Runge–Kutta scheme of order 4."""
    return explicit_rk_on_grid(problem, t_grid, [[], [0.5], [0.0, 0.5], [0.0, 0.0, 1.0]],
                               [1 / 6, 1 / 3, 1 / 3, 1 / 6], [0.0, 0.5, 0.5, 1.0])


def euler_on_grid(problem, t_grid):
    """Explicit Euler, order 1."""
    return explicit_rk_on_grid(problem, t_grid, [[]], [1.0], [0.0])


heun = vm.Stepper(heun_on_grid, scheme="any", order=2, name="heun")
heun_stage_half = vm.Stepper(lambda p, t: heun_on_grid(p, t, bug="stage_half"), scheme="any", order=2,
                             name="heun (stage with h/2)")
heun_input_time = vm.Stepper(lambda p, t: heun_on_grid(p, t, bug="input_time"), scheme="any", order=2,
                             name="heun (input at the step's start)")


def heun_euler(problem, T, tol, *, bug=None, shift=0.0):
    """The Heun–Euler pair: Heun propagated, ``h/2 |k2 - k1|`` (Heun minus Euler) its error estimate, accepted
    when at most ``tol (1 + |x|)``."""
    rhs = _rhs(problem, shift)
    t, x, h = 0.0, np.array(problem.x0, dtype=float), T / 100
    ts, xs = [0.0], [x]
    while t < T:
        h = min(h, T - t)
        k1 = rhs(t, x)
        k2 = rhs(t + h, x + h * k1)
        err = 0.5 * h * float(np.max(np.abs(k2 - k1)))
        allowed = tol * (1.0 + float(np.max(np.abs(x))))
        if err <= allowed or bug == "ignores_estimate":
            t = T if h >= T - t else t + h
            x = x + 0.5 * h * (k1 + k2)
            ts.append(t)
            xs.append(x)
        if bug == "ignores_estimate":
            h = min(1.5 * h, T / 20)                # the estimate is computed, then ignored
        else:
            h *= min(5.0, max(0.2, 0.9 * (allowed / err) ** 0.5)) if err > 0 else 5.0
    return np.array(ts), np.array(xs)


TOLERANCES = (1e-3, 10 ** -3.5, 1e-4, 10 ** -4.5, 1e-5)
heun_pid = vm.Adaptive(heun_euler, rate=1.0, order=2, name="heun-euler", tolerances=TOLERANCES)
heun_pid_ignores = vm.Adaptive(lambda p, T, tol: heun_euler(p, T, tol, bug="ignores_estimate"), rate=1.0, order=2,
                               name="heun-euler (controller ignores its estimate)", tolerances=TOLERANCES)
heun_pid_input_shift = vm.Adaptive(lambda p, T, tol: heun_euler(p, T, tol, shift=0.05), rate=1.0, order=2,
                                   name="heun-euler (input at t + 0.05)", tolerances=TOLERANCES)

__all__ = ["heun", "heun_stage_half", "heun_input_time", "heun_pid", "heun_pid_ignores", "heun_pid_input_shift",
           "ode_field"]
