"""Recipes: other people's integrators as verimono steppers (docs/integrators.md).

* :func:`solve_ivp_stepper` — SciPy's ``solve_ivp`` (``Radau``, ``BDF``, ``RK45``, ...) as a
  :class:`verimono.Adaptive` stepper ``fn(problem, T, tol)``: ``rtol = tol``, ``atol = atol_ratio·tol``, its
  own partition (``sol.t``) and, with ``t_out``, its dense output (``sol.sol``).
* :func:`diffrax_stepper` — a diffrax solver: on a given grid (``adaptive=False``: a
  :class:`verimono.Stepper` claiming ``scheme="any"`` with the solver's order) or with ``PIDController(rtol=tol,
  atol=atol_ratio·tol)`` (``adaptive=True``: an :class:`verimono.Adaptive`).  The vector field is yours, in
  ``jax.numpy`` (``field(t, y, args)``, diffrax's convention): verimono's problems hold NumPy callables.  It
  runs in float64 (inside ``jax.enable_x64``, the global setting untouched) unless ``x64=False``; it is
  compiled once per solver and state shape: the time step, the horizon and the tolerance are traced, so a
  sweep recompiles nothing (a uniform grid is stepped with ``ConstantStepSize``; any other grid with
  ``StepTo``, compiled once per number of nodes).
* :func:`ode_field` — ``x' = -F⁰(t, x) + f(x) + u(t)`` in NumPy for a problem whose ``F(t,·)`` is single-valued
  (``Linear``): the right-hand side ``solve_ivp`` integrates.

JAX, diffrax and SciPy's integrators are imported when a stepper first runs, never by ``import verimono``.
"""

from __future__ import annotations

import dataclasses
from typing import Any, Callable

import numpy as np

from .adaptive import Adaptive
from .claims import Stepper
from .errors import InvalidProblem, MissingOptionalDependency, SolverFailure
from .problem import Problem

#: the convergence orders of diffrax's solvers (their documentation), claimed by their fixed-step steppers
DIFFRAX_ORDERS = {"Euler": 1, "Heun": 2, "Midpoint": 2, "Ralston": 2, "Bosh3": 3, "Tsit5": 5, "Dopri5": 5,
                  "Dopri8": 8, "ImplicitEuler": 1, "Kvaerno3": 3, "Kvaerno4": 4, "Kvaerno5": 5}
#: steps a diffrax run may take (the compiled buffer's length; a run needing more is refused)
DIFFRAX_MAX_STEPS = 16_384


def ode_field(problem: Problem) -> Callable[[float, np.ndarray], np.ndarray]:
    """``rhs(t, x) = -F⁰(t, x) + f(x) + u(t)`` (``F⁰`` the operator's ``min_norm``: ``F`` itself when it is
    single-valued, as for :class:`verimono.Linear`)."""
    op, f, u = problem.operator, problem.f, problem.u
    if not hasattr(op, "min_norm"):
        raise InvalidProblem(f"{problem.name}: an ODE integrator needs F(t, x) itself (the operator's min_norm)")

    def rhs(t: float, x: np.ndarray) -> np.ndarray:
        v = -np.asarray(op.min_norm(x, t), dtype=float)
        if f is not None:
            v = v + np.asarray(f(x), dtype=float)
        if u is not None:
            v = v + np.asarray(u(t), dtype=float)
        return v

    return rhs


def solve_ivp_stepper(method: str = "Radau", *, rate: float = 1.0, order: float | None = None,
                      atol_ratio: float = 1.0, name: str | None = None, jac: Any = None,
                      tolerances: Any = None) -> Adaptive:
    """``scipy.integrate.solve_ivp(method=...)`` as an :class:`verimono.Adaptive` stepper with dense output
    (module docstring); ``jac``: the Jacobian of the right-hand side (``Radau``/``BDF``), a matrix or a callable
    ``jac(t, x)``; by default ``-M`` for a :class:`verimono.Linear` operator without ``f``, else SciPy's
    finite differences."""

    def fn(problem: Problem, T: float, tol: float, t_out: Any = None) -> Any:
        from scipy.integrate import solve_ivp

        rhs = ode_field(problem)
        J = jac
        if J is None and method in ("Radau", "BDF", "LSODA") and problem.f is None and hasattr(problem.operator, "M"):
            J = lambda t, x: -problem.operator.M(t)  # noqa: E731 - the linear operator's own Jacobian
        kw = {"jac": J} if J is not None and method in ("Radau", "BDF", "LSODA") else {}
        sol = solve_ivp(rhs, (0.0, float(T)), np.asarray(problem.x0, dtype=float), method=method, rtol=tol,
                        atol=atol_ratio * tol, dense_output=t_out is not None, **kw)
        if not sol.success:
            raise SolverFailure(f"solve_ivp({method}) failed at tol = {tol:g}: {sol.message}")
        if t_out is not None:
            return sol.sol(np.asarray(t_out, dtype=float)).T
        return sol.t, sol.y.T

    return Adaptive(fn, rate=rate, order=order, dense=True, name=name or f"solve_ivp {method}",
                    tolerances=tolerances)


def _diffrax():
    try:
        import diffrax
        import jax
        import jax.numpy as jnp
    except ImportError as exc:
        raise MissingOptionalDependency(f"diffrax and JAX are needed for this stepper ({exc}): "
                                        "pip install 'verimono[integrators]'") from None
    return jax, jnp, diffrax


class _DiffraxRuns:
    """The compiled diffrax runs of one solver and field: one per (controller kind, state shape)."""

    def __init__(self, solver: Any, field: Callable, x64: bool, max_steps: int, atol_ratio: float) -> None:
        self.solver, self.field, self.x64, self.max_steps, self.atol_ratio = solver, field, x64, max_steps, atol_ratio
        self._compiled: dict[Any, Callable] = {}

    def _context(self):
        import contextlib

        jax, _, _ = _diffrax()
        return jax.enable_x64(True) if self.x64 else contextlib.nullcontext()

    def _run(self, kind: str, key: Any) -> Callable:
        if (kind, key) in self._compiled:
            return self._compiled[kind, key]
        jax, jnp, diffrax = _diffrax()
        term = diffrax.ODETerm(self.field)
        solver, max_steps = self.solver, self.max_steps
        saveat = diffrax.SaveAt(t0=True, steps=True)

        if kind == "constant":
            def run(y0, T, dt0):
                return diffrax.diffeqsolve(term, solver, 0.0, T, dt0, y0, saveat=saveat, max_steps=max_steps,
                                           stepsize_controller=diffrax.ConstantStepSize(), throw=False)
        elif kind == "grid":
            def run(y0, ts):
                return diffrax.diffeqsolve(term, solver, ts[0], ts[-1], None, y0, saveat=diffrax.SaveAt(ts=ts),
                                           stepsize_controller=diffrax.StepTo(ts=ts), max_steps=max_steps,
                                           throw=False)
        else:
            ratio = self.atol_ratio

            def run(y0, T, tol):
                ctrl = diffrax.PIDController(rtol=tol, atol=ratio * tol)
                return diffrax.diffeqsolve(term, solver, 0.0, T, None, y0, saveat=saveat, max_steps=max_steps,
                                           stepsize_controller=ctrl, throw=False)
        fn = self._compiled[kind, key] = jax.jit(run)
        return fn

    def on_grid(self, problem: Problem, t_grid: np.ndarray) -> np.ndarray:
        _, jnp, diffrax = _diffrax()
        t = np.asarray(t_grid, dtype=float)
        K = len(t) - 1
        with self._context():
            y0 = jnp.asarray(problem.x0)
            h = np.diff(t)
            if np.all(np.abs(h - t[-1] / K) <= 1e-12 * t[-1]) and K <= self.max_steps:
                sol = self._run("constant", y0.shape)(y0, jnp.asarray(t[-1]), jnp.asarray(t[-1] / K))
                self._check(sol, diffrax)
                ts, ys = np.asarray(sol.ts), np.asarray(sol.ys)
                n = int(np.sum(np.isfinite(ts)))
                if n != K + 1 or np.max(np.abs(ts[:n] - t)) > 1e-12 * t[-1] * K:
                    raise SolverFailure(f"diffrax stepped {n - 1} times on the uniform grid of {K} cells")
                return ys[:n]
            sol = self._run("grid", (y0.shape, K))(y0, jnp.asarray(t))
            self._check(sol, diffrax)
            return np.asarray(sol.ys)

    def adaptive(self, problem: Problem, T: float, tol: float) -> tuple[np.ndarray, np.ndarray]:
        _, jnp, diffrax = _diffrax()
        with self._context():
            y0 = jnp.asarray(problem.x0)
            sol = self._run("pid", y0.shape)(y0, jnp.asarray(float(T)), jnp.asarray(float(tol)))
            self._check(sol, diffrax)
            ts, ys = np.asarray(sol.ts), np.asarray(sol.ys)
        keep = np.isfinite(ts)
        return ts[keep], ys[keep]

    @staticmethod
    def _check(sol: Any, diffrax: Any) -> None:
        if not diffrax.is_okay(sol.result):
            raise SolverFailure(f"diffrax failed: {sol.result}")


def diffrax_stepper(solver: Any, field: Callable, *, adaptive: bool = False, order: float | None = None,
                    rate: float = 1.0, atol_ratio: float = 1.0, x64: bool = True, name: str | None = None,
                    max_steps: int = DIFFRAX_MAX_STEPS, tolerances: Any = None, solve_tol: float = 1e-12) -> Any:
    """A diffrax ``solver`` on the vector field ``field(t, y, args)`` (module docstring).

    ``adaptive=False``: a :class:`verimono.Stepper` ``(problem, t_grid) -> states`` claiming ``scheme="any"``
    and ``order`` (default: the solver's, :data:`DIFFRAX_ORDERS`).  ``adaptive=True``: a
    :class:`verimono.Adaptive` ``(problem, T, tol) -> (t, x)`` under ``PIDController``, claiming ``rate`` in the
    tolerance and ``order`` against its number of steps.  An implicit solver (``ImplicitEuler``, ``Kvaerno5``) on
    a fixed step solves its stages with ``VeryChord(rtol=solve_tol, atol=solve_tol)`` (diffrax states no
    tolerance for them without a controller), and the stepper states that ``solve_tol`` (its errors' floor)."""
    kind = type(solver).__name__
    order = DIFFRAX_ORDERS.get(kind) if order is None else order
    implicit = hasattr(solver, "root_finder")
    if implicit and not adaptive:    # a fixed step gives the implicit stages no tolerance: state one
        _, _, diffrax = _diffrax()
        import optimistix

        solver = dataclasses.replace(solver, root_finder=diffrax.VeryChord(rtol=solve_tol, atol=solve_tol,
                                                                          norm=optimistix.max_norm))
    runs = _DiffraxRuns(solver, field, x64, max_steps, atol_ratio)
    if adaptive:
        def pid(problem: Problem, T: float, tol: float) -> tuple[np.ndarray, np.ndarray]:
            return runs.adaptive(problem, T, tol)

        return Adaptive(pid, rate=rate, order=order, name=name or f"diffrax {kind} PID", tolerances=tolerances)

    def fixed(problem: Problem, t_grid: Any) -> np.ndarray:
        return runs.on_grid(problem, t_grid)

    if order is None:
        raise InvalidProblem(f"state the order of the diffrax solver {kind} (order=...)")
    return Stepper(fixed, scheme="any", order=order, name=name or f"diffrax {kind}",
                   solve_tol=solve_tol if implicit else None)


__all__ = ["ode_field", "solve_ivp_stepper", "diffrax_stepper", "DIFFRAX_ORDERS"]
