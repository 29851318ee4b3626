"""Classical integrators wrapped as steppers, one step per cell: for the smooth references, where ``F(t,·)`` is
single-valued along the solution and ``x' = -F^0(t, x) + f(x) + u(t)`` is an ODE with a smooth right-hand side.

* :func:`scipy_stepper` — SciPy's ``RK45`` (Dormand–Prince, order 5) and ``DOP853`` (order 8), forced to take
  exactly one step per cell (``first_step = max_step = h``, tolerances too loose to reject a step);
* :func:`butcher5` — Butcher's six-stage explicit scheme of order 5, written here from its tableau;
* :func:`euler` — explicit Euler, order 1 (claimed as order 5 it must fail, naming the order it measures).

Each is correct: claimed at its order (``verimono.Stepper(..., scheme="any", order=p)``) it must pass every
smooth reference, never fail.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import DOP853, RK45

from verimono.core.grids import validate_grid
from verimono.core.recipes import ode_field


def one_step_per_cell(advance, name):
    """A stepper taking one step of ``advance(g, t0, t1, x0) -> x1`` per cell of the grid, ``g`` the right-hand
    side ``-F^0(t, x) + f(x) + u(t)`` (:func:`verimono.core.recipes.ode_field`)."""
    def step(problem, t_grid):
        t = validate_grid(t_grid, problem.T)
        g = ode_field(problem)
        x = np.empty((len(t),) + problem.x0.shape)
        x[0] = problem.x0
        for k in range(len(t) - 1):
            x[k + 1] = advance(g, t[k], t[k + 1], x[k])
        return x
    step.__name__ = name
    return step


def scipy_stepper(cls):
    """SciPy's explicit Runge–Kutta ``cls`` (``RK45``, ``DOP853``), one step per cell of the grid."""
    def advance(g, t0, t1, x0):
        solver = cls(g, t0, x0, t1, first_step=t1 - t0, max_step=t1 - t0, rtol=1e3, atol=1e3)
        solver.step()
        if solver.t != t1:
            raise RuntimeError(f"{cls.__name__} took a step to {solver.t}, not to {t1}")
        return solver.y
    return one_step_per_cell(advance, f"scipy {cls.__name__}")


rk45 = scipy_stepper(RK45)
dop853 = scipy_stepper(DOP853)

#: Butcher's fifth-order tableau (six stages): J. C. Butcher, Numerical Methods for ODEs, 2008, eq. (236a)
_C = np.array([0.0, 0.25, 0.25, 0.5, 0.75, 1.0])
_A = [[], [0.25], [0.125, 0.125], [0.0, -0.5, 1.0], [3 / 16, 0.0, 0.0, 9 / 16],
      [-3 / 7, 2 / 7, 12 / 7, -12 / 7, 8 / 7]]
_B = np.array([7.0, 0.0, 32.0, 12.0, 32.0, 7.0]) / 90.0


def _butcher5_step(g, t0, t1, x0):
    h, stages = t1 - t0, []
    for c, a in zip(_C, _A):
        y = x0 + h * sum(aj * kj for aj, kj in zip(a, stages)) if a else x0
        stages.append(g(t0 + c * h, y))
    return x0 + h * sum(b * s for b, s in zip(_B, stages))


#: Butcher's explicit six-stage scheme of order 5, one step per cell
butcher5 = one_step_per_cell(_butcher5_step, "butcher5")
#: explicit Euler ``x_{k+1} = x_k + h g(t_k, x_k)``: order 1
euler = one_step_per_cell(lambda g, t0, t1, x0: x0 + (t1 - t0) * g(t0, x0), "euler")
