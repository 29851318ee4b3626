"""Steppers broken only in a corner of the problem space (issue 42, "problems are searched too"): each is the
paper's scheme ``x_{k+1} = J_{h F(t_{k+1})}(x_k + h f(x_k) + ∫u)`` except on problems the references and the old
sample problems never had — ``n`` above a threshold with ``f`` present, ``n`` above a threshold with a moving
operator, ``x0`` on the boundary of a moving domain.  Each is a factory, so the tests move the corner
(another coordinate, another dimension), and ``lawful(...)`` is the same code with the fault switched off.
"""

from __future__ import annotations

import numpy as np

from verimono.core.grids import validate_grid


def _scheme(problem, t_grid, *, drop_f=None, lag_time=False, skip_first=False):
    t = validate_grid(t_grid, problem.T)
    h = np.diff(t)
    op, f = problem.operator, problem.f
    dU = problem.input_increments(t)
    x = np.empty((len(t),) + problem.x0.shape)
    x[0] = problem.x0
    for k in range(len(h)):
        z = np.array(x[k], dtype=float)
        if f is not None:
            fx = np.array(f(x[k]), dtype=float)
            if drop_f is not None:
                fx[..., drop_f] = 0.0
            z = z + h[k] * fx
        if dU is not None:
            z = z + dU[k]
        x[k + 1] = z if (skip_first and k == 0) else op.resolvent(z, h[k], t[k] if lag_time else t[k + 1])
    return x


def drops_f(coordinate: int = 1, from_dim: int = 2):
    """Forgets ``f`` on ``coordinate`` when ``n ≥ from_dim`` (an index bug in a vectorised drift)."""
    def stepper(problem, t_grid):
        return _scheme(problem, t_grid, drop_f=coordinate if problem.dim >= from_dim else None)
    stepper.__name__ = f"drops_f_{coordinate}_from_n{from_dim}"
    return stepper


def lags_time(from_dim: int = 4):
    """Evaluates the operator at ``t_k`` instead of ``t_{k+1}`` when ``n ≥ from_dim`` (a blocked code path)."""
    def stepper(problem, t_grid):
        return _scheme(problem, t_grid, lag_time=problem.dim >= from_dim)
    stepper.__name__ = f"lags_time_from_n{from_dim}"
    return stepper


def on_boundary(op, x0, t: float = 0.0, eps: float = 1e-7) -> bool:
    """Whether ``x0 ∈ dom F(t)`` lies on its boundary: some coordinate step of ``eps`` leaves the domain."""
    x0 = np.asarray(x0, dtype=float)
    if np.linalg.norm(np.asarray(op.project_domain(x0, t), float) - x0) > 1e-12 * (1 + np.linalg.norm(x0)):
        return False
    for i in range(x0.size):
        for s in (1.0, -1.0):
            z = x0.copy()
            z[i] += s * eps
            if np.linalg.norm(np.asarray(op.project_domain(z, t), float) - z) > 1e-3 * eps:
                return True
    return False


def skips_first_projection(when_on_boundary: bool = True):
    """Skips the resolvent in the first step when ``x0`` is on the boundary of ``dom F(0)`` (an "already
    feasible" shortcut); ``when_on_boundary=False`` is the lawful control (never skips)."""
    def stepper(problem, t_grid):
        skip = when_on_boundary and not problem.batched
        if skip:
            try:
                skip = on_boundary(problem.operator, problem.x0)
            except NotImplementedError:
                skip = False
        return _scheme(problem, t_grid, skip_first=skip)
    stepper.__name__ = "skips_first_projection_on_boundary" if when_on_boundary else "projects_first_step"
    return stepper


def lawful(problem, t_grid):
    """The same code with every fault off: the paper's scheme."""
    return _scheme(problem, t_grid)
