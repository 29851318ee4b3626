"""Sweeping-process references ``x' ∈ -N_{S(t)}(x)`` (Moreau's catching-up algorithm).

* ``static_inside`` / ``static_outside``: a fixed ball.  From inside nothing moves; from outside the
  catching-up scheme jumps to ``proj_S(x0)`` in its first step, which is the solution for ``t > 0``
  (Moreau 1977's convention for a state outside the set).  Both exact at the nodes.
* ``play_smooth`` / ``play_piecewise_linear``: the 1-D interval ``[u(t) - r, u(t) + r]`` — the play
  operator.  On each interval where ``u`` is monotone, ``x(t) = clamp(x(τ), u(t) - r, u(t) + r)``
  (``τ`` the last turning point), so the scheme is the exact solution for the piecewise-linear
  interpolant of ``u`` at the nodes; the play operator is 1-Lipschitz in the sup norm, hence the error
  is at most ``max|u - u_PL| ≤ h² max|u''|/8`` — order 2 for smooth ``u`` and exact for ``u``
  piecewise linear on the grid (verimono's literature notes; Krejčí, Visintin for the Lipschitz bound).
  Grids are chosen so that turning points fall at the same relative place inside cells.
* ``moving_half_space``: ``{x : ⟨a, x⟩ ≤ g(t)}`` with a fixed normal: ``s = ⟨a, x⟩`` follows the running
  minimum ``min(s0, min_[0,t] g)``; the scheme takes the minimum over the nodes — order 2, with error
  ``(1 - cos(h/2))/|a|`` for ``g = cos`` and ``π`` at the middle of a cell.
* ``moving_box``: two independent play operators (order 2).
* ``translating_ball``: ``B(c0 + v t, R)``.  ``y = x - c(t)`` solves ``y' ∈ -v - N_B(y)``, the gradient
  flow of ``⟨v, y⟩ + I_B`` (order 1 for the implicit Euler scheme, Rulla 1996; literature notes).  In
  closed form: ``x`` rests until the boundary reaches it at ``t_h``, then slides on the sphere with the
  angle ``α`` to ``-v`` obeying ``R α' = -|v| sin α``, i.e. ``tan(α/2) = tan(α_h/2) e^{-|v|(t - t_h)/R}``.
"""

from __future__ import annotations

import bisect
import math

import numpy as np

from verimono.core.operators import NormalCone
from verimono.core.problem import Order, Problem
from verimono.core.sets import Ball, Box, HalfSpace

TWO_PI = 2.0 * math.pi
#: regularity of a sweeping solution whose set moves smoothly: Lipschitz, its derivative jumps where the
#: constraint engages or releases — order 1 for a generic convergent scheme (Moreau 1977; Kunze–Monteiro
#: Marques 2000 give only 1/2 for Lipschitz motion in general)
SWEEP_KINKS = "x is Lipschitz and x' jumps where the constraint engages or releases: order 1 at most"
#: a solution constant on (0, T]
CONSTANT = "x is constant on (0, T]"
#: K = 2m+1 cells on [0, 2π]: π sits mid-cell and π/2, 3π/2 a quarter-cell from a node
_ODD_STEPS = [TWO_PI / k for k in (41, 81, 161, 321, 641)]


def static_inside() -> Problem:
    S = Ball([0.0, 0.0], 1.0)
    x0 = np.array([0.3, -0.4])
    return Problem(NormalCone(S), x0, 1.0, exact=lambda t: x0,
                   order=Order.exact_at_nodes("x0 in S: x stays; J = proj_S fixes it", math.inf, CONSTANT),
                   name="static ball, x0 inside", steps=[0.1, 0.05, 0.025])


def static_outside() -> Problem:
    S = Ball([0.0, 0.0], 1.0)
    x0 = np.array([2.0, 1.0])
    p = x0 / np.linalg.norm(x0)
    return Problem(NormalCone(S), x0, 1.0, exact=lambda t: x0 if t == 0.0 else p,
                   order=Order.exact_at_nodes("catching-up jump: x_1 = proj_S(x0) = x(0+) (Moreau 1977)", math.inf,
                                             CONSTANT),
                   name="static ball, x0 outside (jump)", steps=[0.1, 0.05, 0.025], initial_jump=True)


def _play_exact(u, turning, r, x0):
    """Exact play-operator output for an input monotone between the sorted ``turning`` points."""
    def exact(t):
        x = float(x0)
        for tau in turning:
            if tau >= t:
                break
            x = min(max(x, u(tau) - r), u(tau) + r)
        return np.array([min(max(x, u(t) - r), u(t) + r)])
    return exact


def play_smooth(amplitude: float = 1.0, r: float = 0.25, x0: float = 0.1) -> Problem:
    """Interval ``[u - r, u + r]`` with ``u = A sin t`` on ``[0, 2π]``: order 2."""
    u = lambda t: amplitude * math.sin(t)  # noqa: E731
    S = Box(lambda t: np.array([u(t) - r]), lambda t: np.array([u(t) + r]))
    return Problem(NormalCone(S), [x0], TWO_PI, exact=_play_exact(u, [math.pi / 2, 3 * math.pi / 2], r, x0),
                   order=Order(2.0, "scheme = play operator of the piecewise-linear interpolant of u; play "
                                    "is 1-Lipschitz in sup norm, |u - u_PL| <= h^2 max|u''|/8",
                               regularity=1.0, regularity_source=SWEEP_KINKS),
                   name="play operator, u = sin t", steps=_ODD_STEPS, phi=lambda t: amplitude * t)


def _interp(t: float, xp: list, fp: list) -> float:
    """``float(np.interp(t, xp, fp))`` for a real ``t`` and strictly increasing ``xp`` (at least two), in Python floats:
    NumPy's own steps (``arr_interp``: the bracketing cell by bisection, ``fp`` at a node or outside ``[xp_0, xp_K]``,
    else ``slope·(t − xp_j) + fp_j`` with ``slope = (fp_{j+1} − fp_j)/(xp_{j+1} − xp_j)``, the other end's formula
    when that is NaN), so the same roundings, bit for bit; ~15× cheaper than the call, which is most of the play
    operator's assumption unit (its box's bounds are asked ~50,000 times)."""
    t = float(t)
    if t != t:
        return t
    if t < xp[0]:
        return float(fp[0])
    if t >= xp[-1]:
        return float(fp[-1])
    j = bisect.bisect_right(xp, t) - 1
    if xp[j] == t:
        return float(fp[j])
    slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j])
    out = slope * (t - xp[j]) + fp[j]
    if out != out:
        out = slope * (t - xp[j + 1]) + fp[j + 1]
        if out != out and fp[j] == fp[j + 1]:
            out = fp[j]
    return float(out)


def play_piecewise_linear(r: float = 0.25, x0: float = 0.0) -> Problem:
    """Interval ``[u - r, u + r]`` with a zigzag ``u`` whose kinks are grid nodes: exact at the nodes."""
    kinks = [0.0, 1.0, 1.5, 3.0, 4.0]
    values = [0.0, 1.0, 0.2, 1.4, 0.0]
    u = lambda t: _interp(t, kinks, values)  # noqa: E731 - float(np.interp(t, kinks, values)), bit for bit
    S = Box(lambda t: np.array([u(t) - r]), lambda t: np.array([u(t) + r]))
    return Problem(NormalCone(S), [x0], 4.0, exact=_play_exact(u, kinks[1:-1], r, x0),
                   order=Order.exact_at_nodes("the scheme is the play operator of the piecewise-linear "
                                              "interpolant of u, which is u itself on these grids",
                                              1.0, SWEEP_KINKS),
                   name="play operator, piecewise-linear u", steps=[0.5, 0.25, 0.125, 0.0625],
                   phi=lambda t: 1.6 * t)


def moving_half_space(a=(1.0, 2.0), x0=(-1.0, 0.5)) -> Problem:
    """``{x : ⟨a, x⟩ ≤ cos t}`` on ``[0, 2π]`` (x0 inside): order 2 with constant ``1/(8|a|)``."""
    a = np.asarray(a, dtype=float)
    x0 = np.asarray(x0, dtype=float)
    s0 = float(a @ x0)
    if s0 > 1.0:
        raise ValueError("x0 must satisfy <a, x0> <= cos 0 = 1")
    S = HalfSpace(a, lambda t: math.cos(t))

    def exact(t):
        running_min = math.cos(min(t, math.pi))  # cos decreases on [0, π], increases on [π, 2π]
        s = min(s0, running_min)
        return x0 - (s0 - s) * a / (a @ a)

    return Problem(NormalCone(S), x0, TWO_PI, exact=exact,
                   order=Order(2.0, "s = <a,x> follows the running minimum of cos; the nodes miss the "
                                    "minimum at pi (mid-cell) by 1 - cos(h/2) ~ h^2/8",
                               constant=1.0 / (8.0 * float(np.linalg.norm(a))), regularity=1.0,
                               regularity_source=SWEEP_KINKS),
                   name="moving half-space", steps=_ODD_STEPS, phi=lambda t: t / float(np.linalg.norm(a)))


def moving_box(r=(0.3, 0.5), x0=(0.1, 0.6)) -> Problem:
    """Box ``[u(t) - r, u(t) + r]`` with ``u = (sin t, 0.7 cos t)`` on ``[0, 2π]``: two plays, order 2."""
    r = np.asarray(r, dtype=float)

    def u(t):
        return np.array([math.sin(t), 0.7 * math.cos(t)])

    if r.shape == (2,):     # the bounds in Python floats, then one array: the same two sums as u(t) ∓ r, cheaper
        r0, r1 = float(r[0]), float(r[1])
        S = Box(lambda t: np.array([math.sin(t) - r0, 0.7 * math.cos(t) - r1]),
                lambda t: np.array([math.sin(t) + r0, 0.7 * math.cos(t) + r1]))
    else:
        S = Box(lambda t: u(t) - r, lambda t: u(t) + r)
    ex1 = _play_exact(lambda t: math.sin(t), [math.pi / 2, 3 * math.pi / 2], r[0], x0[0])
    ex2 = _play_exact(lambda t: 0.7 * math.cos(t), [math.pi], r[1], x0[1])
    return Problem(NormalCone(S), x0, TWO_PI, exact=lambda t: np.concatenate([ex1(t), ex2(t)]),
                   order=Order(2.0, "componentwise play operators (see play_smooth)", regularity=1.0,
                               regularity_source=SWEEP_KINKS),
                   name="moving box", steps=_ODD_STEPS, phi=lambda t: math.hypot(1.0, 0.7) * t)


def translating_ball(v=(1.0, 0.5), R: float = 1.0, x0=(0.3, 0.6), T: float = 4.0) -> Problem:
    """Ball ``B(v t, R)`` translating at constant velocity, ``x0`` inside: order 1 (closed form)."""
    v, x0 = np.asarray(v, dtype=float), np.asarray(x0, dtype=float)
    speed = float(np.linalg.norm(v))
    vhat = v / speed
    if np.linalg.norm(x0) >= R:
        raise ValueError("x0 must lie strictly inside the initial ball")
    b = float(x0 @ v)
    t_hit = (b + math.sqrt(b * b - speed ** 2 * (x0 @ x0 - R * R))) / speed ** 2
    y_hit = x0 - v * t_hit                      # position relative to the centre at the hit
    w_hit = y_hit / R
    cos_a = float(np.clip(-w_hit @ vhat, -1.0, 1.0))
    alpha_hit = math.acos(cos_a)
    perp = w_hit - (w_hit @ vhat) * vhat
    e = perp / np.linalg.norm(perp) if np.linalg.norm(perp) > 0 else np.zeros_like(v)

    def exact(t):
        if t <= t_hit:
            return x0.copy()
        alpha = 2.0 * math.atan(math.tan(alpha_hit / 2.0) * math.exp(-speed * (t - t_hit) / R))
        return v * t + R * (math.cos(alpha) * (-vhat) + math.sin(alpha) * e)

    S = Ball(lambda t: v * t, R)
    return Problem(NormalCone(S), x0, T, exact=exact,
                   order=Order(1.0, "y = x - vt is the gradient flow of <v,y> + I_B (implicit Euler, "
                                    "order 1 for x0 in D(dphi): Rulla 1996; literature notes)",
                               regularity=1.0, regularity_source=SWEEP_KINKS),
                   name="translating ball", steps=[T / k for k in (50, 100, 200, 400, 800)],
                   phi=lambda t: speed * t)
