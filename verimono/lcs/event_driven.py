"""An event-driven scheme for complementarity systems (Section 7): smooth integration within a mode, the
switching times located as events.

For ``x' = Ax + Bz + u``, ``w = Cx + Dz + v(t)``, ``0 ≤ z ⊥ w ≥ 0``, a *mode* is a set ``S`` of indices with
``w_S = 0`` and ``z_{S^c} = 0``: there ``z_S = -D_SS^{-1}(Cx + v)_S`` (``D_SS`` nonsingular) and the system is
the ODE ``x' = Ax + B_S z_S + u``, valid while ``z_S ≥ 0`` and ``w_{S^c} ≥ 0``.  The scheme integrates that ODE
with ``scipy.integrate.solve_ivp`` (``DOP853``, ``rtol = atol = tol``) and hands it the mode's validity
conditions as terminal events (each component crossing 0 downwards), which ``solve_ivp`` locates on its
dense output; at an event it chooses the next mode — the mode valid at the event and a little after it
(``LOOK_AHEAD · T`` later, the state frozen), among the ``2^m`` candidates — and restarts there.  The
partition is the union of the runs' steps, the events its nodes; the stepper returns ``(t, x, events)``
(:class:`verimono.Adaptive`).  A switching the event functions cannot see (a mode valid on both sides) is no
switching of the dynamics.

``locate=False`` is the classic mistake, kept as the planted bug of the tests: the mode is checked at the
ends of the integrator's steps only, and switched there — the switching time is off by up to a step.
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np

from ..core.adaptive import Adaptive
from ..core.errors import InvalidProblem, SolverFailure
from ..core.problem import Problem
from .relations import Complementarity

#: the look-ahead that picks the mode after an event (as a fraction of T)
LOOK_AHEAD = 1e-9
#: validity of a mode: components may be this far below 0 (relative to the data's size) at an event
SLACK = 1e-10
#: at most this many mode changes per run
MAX_EVENTS = 10_000


class _Mode:
    def __init__(self, system: Any, S: tuple[int, ...]) -> None:
        self.S = S
        m = system.m
        self.Sc = tuple(i for i in range(m) if i not in S)
        D = system.D
        self.inv = np.linalg.inv(D[np.ix_(S, S)]) if S else np.zeros((0, 0))
        self.system = system

    def z(self, t: float, x: np.ndarray) -> np.ndarray:
        s = self.system
        z = np.zeros(s.m)
        if self.S:
            z[list(self.S)] = -self.inv @ (s.C @ x + s.v(t))[list(self.S)]
        return z

    def w(self, t: float, x: np.ndarray, z: np.ndarray) -> np.ndarray:
        s = self.system
        return s.C @ x + s.D @ z + s.v(t)

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        s = self.system
        v = s.A @ x + s.B @ self.z(t, x)
        return v + s.u(t) if s.u is not None else v

    def margins(self, t: float, x: np.ndarray) -> np.ndarray:
        """The quantities that must stay ≥ 0 in this mode: ``z_S`` and ``w_{S^c}``."""
        z = self.z(t, x)
        w = self.w(t, x, z)
        return np.concatenate([z[list(self.S)], w[list(self.Sc)]])


def _modes(system: Any) -> list[_Mode]:
    out = []
    for r in range(system.m + 1):
        for S in itertools.combinations(range(system.m), r):
            if not S or abs(np.linalg.det(system.D[np.ix_(S, S)])) > 1e-12:
                out.append(_Mode(system, S))
    return out


def _choose(modes: list[_Mode], t: float, x: np.ndarray, ahead: float, scale: float) -> _Mode:
    """The mode valid at ``t`` and at ``t + ahead`` (state frozen), the one with the largest margin."""
    best, best_margin = None, -np.inf
    for mode in modes:
        now, later = mode.margins(t, x), mode.margins(t + ahead, x)
        if now.size == 0:
            margin = np.inf
        else:
            margin = min(float(now.min()), float(later.min()))
        if margin >= -SLACK * scale and (margin > best_margin or best is None):
            best, best_margin = mode, margin
    if best is None:
        raise SolverFailure(f"no mode of the complementarity system is valid at t = {t:g}, x = {x}")
    return best


def _system_of(problem: Problem) -> Any:
    system = getattr(problem.operator, "system", None)
    if system is None or not isinstance(system.relation, Complementarity):
        raise InvalidProblem(f"{problem.name}: the event-driven scheme needs a complementarity system's problem "
                             "(LinearRelationSystem(..., Complementarity()).problem(...))")
    return system


def _run(problem: Problem, T: float, tol: float, locate: bool = True, method: str = "DOP853",
         max_step: float = 1.0 / 64):
    from scipy.integrate import solve_ivp

    system = _system_of(problem)
    modes = _modes(system)
    T = float(T)
    t, x = 0.0, np.array(problem.x0, dtype=float)
    ts, xs, events = [0.0], [x.copy()], []
    scale = 1.0 + float(np.max(np.abs(x)))
    mode = _choose(modes, t, x, LOOK_AHEAD * T, scale)
    while t < T:
        if len(events) > MAX_EVENTS:
            raise SolverFailure(f"more than {MAX_EVENTS} mode changes before T: the modes chatter")
        fns = []
        for i in range(len(mode.S) + len(mode.Sc)):
            def g(s, y, i=i, mode=mode, offset=SLACK * scale):
                # below 0 by more than the slack: a component that sits at 0 and stays there (x on the
                # boundary with x' = 0) is no switching, and solve_ivp would stop on it at once
                return mode.margins(s, y)[i] + offset
            g.terminal, g.direction = True, -1
            fns.append(g)
        sol = solve_ivp(mode.rhs, (t, T), x, method=method, rtol=tol, atol=tol, max_step=max_step * T,
                        events=fns if locate else None, dense_output=not locate)
        if sol.status < 0:
            raise SolverFailure(f"solve_ivp({method}) failed at t = {t:g}: {sol.message}")
        tt, yy = sol.t, sol.y.T
        if not locate:                 # the mistake: the mode checked at the steps' ends only
            bad = [k for k in range(1, len(tt)) if np.min(mode.margins(tt[k], yy[k]), initial=np.inf) < -SLACK * scale]
            if bad:
                k = bad[0]
                tt, yy = tt[:k + 1], yy[:k + 1]
        if tt[-1] <= t:                # an event at the start: the mode chosen was not valid after all
            raise SolverFailure(f"the mode {mode.S} stopped at once at t = {t:g}")
        ts += tt[1:].tolist()
        xs += list(yy[1:])
        t, x = float(tt[-1]), yy[-1].copy()
        if t < T * (1 - 1e-14):
            events.append(t)
            scale = max(scale, 1.0 + float(np.max(np.abs(x))))
            mode = _choose(modes, t, x, LOOK_AHEAD * T, scale)
        else:
            t = T
    ts[-1] = T
    return np.array(ts), np.array(xs), np.array(events)


def event_driven(*, locate: bool = True, method: str = "DOP853", rate: float = 1.0, order: float | None = None,
                 name: str | None = None, tolerances: Any = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8),
                 max_step: float = 1.0 / 64) -> Adaptive:
    """The event-driven scheme (module docstring) as a :class:`verimono.Adaptive` stepper returning
    ``(t, x, events)``; ``locate=False``: the mode switched at step ends (a planted bug).  ``max_step``
    (a fraction of ``T``) bounds the integrator's steps: its event detection compares the event functions'
    signs at the ends of its steps, so a step over two switchings (a mode whose ODE is ``x' = 0``, where the
    error control sets no limit, while ``v(t)`` goes through a period) would see neither."""
    def fn(problem: Problem, T: float, tol: float):
        return _run(problem, T, tol, locate, method, max_step)

    return Adaptive(fn, rate=rate, order=order, tolerances=tolerances,
                    name=name or ("event-driven " + method + ("" if locate else " (unlocated)")))


__all__ = ["event_driven", "LOOK_AHEAD"]
