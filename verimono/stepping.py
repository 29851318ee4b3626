"""The proximal ("catching-up", implicit Euler) scheme and its trajectories.

On a partition ``0 = t_0 < ... < t_K = T`` with steps ``h_{k+1} = t_{k+1} - t_k`` the paper's scheme
(Section 5.1, labels ``eq:iteration`` and ``e:discrete-yosida``) is

    x_{k+1} = (I + h_{k+1} F(t_{k+1}, ·))^{-1}(x_k),

i.e. ``(x_k - x_{k+1})/h_{k+1} ∈ F(t_{k+1}, x_{k+1})``.  The Lipschitz field ``f`` and the input ``u`` of
Section 6 enter explicitly before the resolvent (the ``G(t, ξ) = F(t, ξ + ∫u)`` shift of lemma
``l:extinput`` and the Picard iteration of the Lipschitz theorem, discretised):

    x_{k+1} = J_{h_{k+1} F(t_{k+1},·)}(x_k + h_{k+1} f(x_k) + ∫_{t_k}^{t_{k+1}} u).

A *stepper* is any callable ``stepper(problem, t_grid)`` returning the values at the grid points, an
array of shape ``(len(t_grid), n)``; :func:`solve` is one and returns a :class:`Trajectory`, which
converts with ``np.asarray``.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from .errors import InvalidProblem, SolverFailure
from .grids import validate_grid
from .problem import Problem


class Trajectory:
    """Discrete solution ``x_0, ..., x_K`` on the grid ``t_0, ..., t_K``.

    ``x`` has shape ``(K+1, n)`` (or ``(K+1, B, n)`` for a batch).  ``selections`` are the elements
    ``(z_k - x_{k+1})/h_{k+1} ∈ F(t_{k+1}, x_{k+1})`` with ``z_k = x_k + h f(x_k) + ∫u`` (so
    ``(x_k - x_{k+1})/h_{k+1}`` without ``f`` and ``u``).  ``extras`` carries per-step data of
    specialised steppers (multipliers and outputs of complementarity systems).
    """

    def __init__(self, t: np.ndarray, x: np.ndarray, problem: Problem | None = None,
                 extras: dict[str, np.ndarray] | None = None) -> None:
        self.t = np.asarray(t, dtype=float)
        self.x = np.asarray(x, dtype=float)
        if self.x.shape[0] != self.t.shape[0]:
            raise InvalidProblem(f"trajectory has {self.x.shape[0]} states for {self.t.shape[0]} times")
        self.problem = problem
        self.extras = dict(extras or {})

    def __array__(self, dtype=None, copy=None):
        return self.x if dtype is None else self.x.astype(dtype)

    def __len__(self) -> int:
        return self.t.shape[0]

    @property
    def h(self) -> np.ndarray:
        return np.diff(self.t)

    @property
    def selections(self) -> np.ndarray:
        """``y_{k+1} ∈ F(t_{k+1}, x_{k+1})`` for ``k = 0..K-1``: the scheme's discrete velocities."""
        h = self.h.reshape((-1,) + (1,) * (self.x.ndim - 1))
        z = self.x[:-1].copy()
        p = self.problem
        if p is not None and p.f is not None:
            z += h * np.array([p.f(xk) for xk in self.x[:-1]])
        if p is not None:
            dU = p.input_increments(self.t)
            if dU is not None:
                z += dU.reshape((dU.shape[0],) + (1,) * (self.x.ndim - 2) + (dU.shape[-1],))
        return (z - self.x[1:]) / h

    def interpolate(self, tau: Any, kind: str = "linear", psi: Callable | None = None) -> np.ndarray:
        """Values at times ``tau``: piecewise linear in ``t``, or in ``ψ`` (the paper's ``e:x delta``).

        ``kind="psi"`` gives ``x_Δ(τ) = ((ψ(t_{k+1}) - ψ(τ)) x_k + (ψ(τ) - ψ(t_k)) x_{k+1}) /
        (ψ(t_{k+1}) - ψ(t_k))`` for a strictly increasing ``ψ`` (``problem.psi`` when not given).
        """
        tau = np.asarray(tau, dtype=float)
        scalar = tau.ndim == 0
        tau = np.atleast_1d(tau)
        if np.any(tau < self.t[0]) or np.any(tau > self.t[-1]):
            raise InvalidProblem(f"interpolation times must lie in [{self.t[0]}, {self.t[-1]}]")
        k = np.clip(np.searchsorted(self.t, tau, side="right") - 1, 0, len(self.t) - 2)
        if kind == "linear":
            a, b, s = self.t[k], self.t[k + 1], tau
        elif kind == "psi":
            psi = psi or getattr(self.problem, "psi", None)
            if psi is None:
                raise InvalidProblem("kind='psi' needs a strictly increasing function psi")
            ps = np.vectorize(lambda s: float(psi(s)))
            a, b, s = ps(self.t[k]), ps(self.t[k + 1]), ps(tau)
            if np.any(b <= a):
                raise InvalidProblem("psi must be strictly increasing on the grid")
        else:
            raise InvalidProblem(f"kind must be 'linear' or 'psi', got {kind!r}")
        w = ((s - a) / (b - a)).reshape((-1,) + (1,) * (self.x.ndim - 1))
        out = (1.0 - w) * self.x[k] + w * self.x[k + 1]
        return out[0] if scalar else out

    def __repr__(self) -> str:
        return f"Trajectory(K={len(self.t) - 1}, shape={self.x.shape}, T={self.t[-1]:g})"


def solve(problem: Problem, t_grid: Any) -> Trajectory:
    """Run the proximal scheme of the paper on the partition ``t_grid`` (see the module docstring).

    Raises :class:`verimono.InvalidGrid` for a grid that is not an increasing partition of
    ``[0, problem.T]`` and :class:`verimono.SolverFailure` when the resolvent returns a value of the
    wrong shape or a non-finite value (reported with its step).
    """
    if not isinstance(problem, Problem):
        raise InvalidProblem(f"solve expects a verimono.Problem, got {type(problem).__name__}")
    t = validate_grid(t_grid, problem.T)
    h = np.diff(t)
    K = h.size
    x0 = problem.x0
    x = np.empty((K + 1,) + x0.shape)
    x[0] = x0
    resolvent = problem.operator.resolvent
    f = problem.f
    dU = problem.input_increments(t)
    if dU is not None and x0.ndim == 2:
        dU = dU[:, None, :]
    hs, ts = h.tolist(), t[1:].tolist()
    first = np.asarray(resolvent(_drift(x0, hs[0], f, dU, 0), hs[0], ts[0]), dtype=float)
    if first.shape != x0.shape:
        raise SolverFailure(f"the resolvent of {problem.operator.name} returned shape {first.shape} "
                            f"for a point of shape {x0.shape}")
    x[1] = first
    xk = first
    if f is None and dU is None:
        for k in range(1, K):
            xk = resolvent(xk, hs[k], ts[k])
            x[k + 1] = xk
    else:
        for k in range(1, K):
            xk = resolvent(_drift(xk, hs[k], f, dU, k), hs[k], ts[k])
            x[k + 1] = xk
    if not np.all(np.isfinite(x)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(x.reshape(K + 1, -1)), axis=1))[0])
        raise SolverFailure(f"non-finite state at step {bad} (t = {t[bad]:g}) of {problem.name}: the resolvent "
                            f"of {problem.operator.name} returned {x[bad]} from x = {x[bad - 1]}")
    return Trajectory(t, x, problem)


def _drift(xk, hk, f, dU, k):
    z = xk
    if f is not None:
        z = z + hk * np.asarray(f(xk), dtype=float)
    if dU is not None:
        z = z + dU[k]
    return z


__all__ = ["Trajectory", "solve"]
