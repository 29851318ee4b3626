"""The proximal scheme with a step controller of its own: :data:`solve_adaptive`.

Every step is the paper's scheme (``eq:iteration``), ``x_{k+1} = J_{h F(t_{k+1},·)}(x_k + h f(x_k) +
∫_{t_k}^{t_{k+1}} u)``, on a partition the controller chooses as it goes: the paper's results hold for any
partition (Section 5.1 asks only ``|Δ| → 0``), so the laws local to steps (``selections``, ``in_domain``,
the bounds of ``lem:bndSeq``) hold on it, and the limit is the solution (Theorem ``thm:main``).

**The error estimate** — step doubling.  From ``x_k`` the controller takes one step of ``h`` (``x_big``) and
two of ``h/2`` (``x_mid``, ``x_small``); for a solution with bounded ``x''`` the scheme's local error is
``C h² + O(h³)``, so ``|x_big - x_small| ≈ C h²/2``, the local error of the two half steps.  No step is
longer than ``h_max = tol · T`` (:data:`MAX_STEP`: the estimate is blind where one step and two half steps
agree although both are wrong, and Section 5.1 needs ``|Δ| → 0``), and a step is accepted when its estimate
is at most ``tol · h_max · (1 + |x_small|)``: where ``x''`` is bounded the steps are ``O(tol)``, ``N ∝ 1/tol``
and the local errors add up, through the nonexpansive resolvents, to ``O(tol · T (1 + max|x|))`` — rate 1 in
the tolerance, order 1 against the number of steps; where ``x''`` is not integrable to a bounded step count
under an error-per-unit-step rule (``x = √(2ct)`` at ``t = 0``: ``h ≤ tol t^{3/2}``) the per-step rule still
takes ``O(T^{1/4}/tol)`` steps there.  The two half steps are kept, so the partition holds ``t_k``,
``t_k + h/2`` and ``t_k + h`` and every kept state is a proximal iterate on it.  The next step is
``h · min(MAX_GROWTH, max(MIN_SHRINK, SAFETY · tol h_max (1 + |x|) / err))``.  Where the
solution has a kink (an extinction, a switching of the complementarity system) the estimate grows and
the controller shrinks the steps around it; where it jumps (a discontinuous input, a set that jumps) no
step satisfies the estimate and steps below ``T · MIN_STEP`` are accepted as they are (counted).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .adaptive import Adaptive
from .errors import InvalidProblem
from .problem import Problem
from .stepping import Trajectory

SAFETY = 0.8
MAX_GROWTH = 2.0
MIN_SHRINK = 0.2
#: steps below ``T · MIN_STEP`` are accepted whatever the estimate (a jump of the solution)
MIN_STEP = 1e-12
#: no step longer than ``MAX_STEP · tol · T``: the step-doubling estimate is blind where one step and two half
#: steps agree although both are wrong (a piecewise-linear input read between its breakpoints, a rate-independent
#: operator), and convergence needs ``|Δ| → 0`` as ``tol → 0`` (Section 5.1); with it the partition's mesh is
#: ``O(tol)``, which a rate-1 scheme's global error bound asks anyway
MAX_STEP = 1.0
#: the first trial step, as a fraction of ``T``
FIRST_STEP = 1e-2
#: at most this many steps (a tolerance meant in other units is refused, not run for an hour)
MAX_STEPS = 200_000


#: 3-point Gauss–Legendre nodes and weights on [0, 1] (``Problem.input_increments``' rule, computed once)
_GL_X, _GL_W = np.polynomial.legendre.leggauss(3)
_GL_X, _GL_W = (_GL_X + 1.0) / 2.0, _GL_W / 2.0


def _increment(problem: Problem, t: float, h: float) -> np.ndarray | None:
    """``∫_t^{t+h} u``: from the primitive ``U`` when given, else by ``Problem.input_increments``' rule."""
    if problem.U is not None:
        return np.asarray(problem.U(t + h), dtype=float) - np.asarray(problem.U(t), dtype=float)
    if problem.u is None:
        return None
    return h * sum(w * np.asarray(problem.u(t + x * h), dtype=float) for x, w in zip(_GL_X, _GL_W))


def _step(problem: Problem, x: np.ndarray, t: float, h: float) -> np.ndarray:
    z = x + h * np.asarray(problem.f(x), dtype=float) if problem.f is not None else x
    dU = _increment(problem, t, h)
    if dU is not None:
        z = z + dU
    return np.asarray(problem.operator.resolvent(z, h, t + h), dtype=float)


def _solve_adaptive(problem: Problem, T: float, tol: float) -> Trajectory:
    """The proximal scheme on ``[0, T]`` with the step-doubling controller at tolerance ``tol`` (module
    docstring): a :class:`verimono.Trajectory` on the partition it chose."""
    tol = float(tol)
    if not (np.isfinite(tol) and 0.0 < tol < 1.0):
        raise InvalidProblem(f"tol must be a number in (0, 1), got {tol!r}")
    T = float(T)
    ts, xs = [0.0], [np.array(problem.x0, dtype=float)]
    h_max = MAX_STEP * tol * T
    t, x, h = 0.0, xs[0], min(FIRST_STEP * T, h_max)
    forced = 0
    while t < T:
        if len(ts) > MAX_STEPS:
            raise InvalidProblem(f"solve_adaptive took more than {MAX_STEPS} steps at tol = {tol:g}: a tolerance "
                                 "this small needs another scheme (the proximal scheme has order 1)")
        h = min(h, h_max)
        last = h >= T - t
        h = T - t if last else h
        big = _step(problem, x, t, h)
        mid = _step(problem, x, t, h / 2)
        small = _step(problem, mid, t + h / 2, h / 2)
        err = float(np.max(np.abs(big - small)))
        allowed = tol * h_max * (1.0 + float(np.max(np.abs(small))))
        if err <= allowed or h <= MIN_STEP * T:
            forced += err > allowed
            t_mid, t = t + h / 2, (T if last else t + h)
            ts += [t_mid, t]
            xs += [mid, small]
            x = small
        grow = MAX_GROWTH if err == 0.0 else min(MAX_GROWTH, max(MIN_SHRINK, SAFETY * allowed / err))
        h = h * grow
    traj = Trajectory(np.array(ts), np.array(xs), problem)
    traj.extras["forced_steps"] = np.array([forced])
    return traj


#: the adaptive proximal scheme: ``solve_adaptive(problem, T, tol) -> Trajectory`` on the partition it chose,
#: claiming rate 1 in the tolerance and order 1 in the number of steps, every step the paper's scheme
solve_adaptive = Adaptive(_solve_adaptive, rate=1.0, order=1.0, scheme="proximal", name="solve_adaptive",
                          tolerances=(1e-2, 10 ** -2.5, 1e-3, 10 ** -3.5, 1e-4))


def adaptive_proximal(**kw: Any) -> Adaptive:
    """:data:`solve_adaptive` with other claims or default tolerances (``Adaptive`` keywords)."""
    base = dict(rate=1.0, order=1.0, scheme="proximal", name="solve_adaptive",
                tolerances=(1e-2, 10 ** -2.5, 1e-3, 10 ** -3.5, 1e-4))
    base.update(kw)
    return Adaptive(_solve_adaptive, **base)


__all__ = ["solve_adaptive", "adaptive_proximal"]
