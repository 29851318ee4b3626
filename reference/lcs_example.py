"""The paper's Example ``ex`` (Section 3.2): a complementarity system whose ``H(t,·)`` is not absolutely
continuous in Vladimirov's pseudo-distance, yet satisfies Theorem ``e: linear case-comp``.

``n = 1``, ``m = 2``, ``A = 0``, ``B = Cᵀ = [0 1]``, ``D = [[0, 1], [−1, 0]]``, ``0 ≤ z ⊥ w ≥ 0``.
With ``η = Cx + v = (v1, x + v2)`` the multipliers solve ``LCP(η, D)``: ``w1 = z2 + v1``, ``w2 = x + v2 − z1``.
Case analysis (``x + v2 > 0`` forces ``z2 = max(−v1, 0)``; ``x + v2 = 0`` forces ``z1 = 0`` and leaves
``z2 ≥ max(−v1, 0)``; ``x + v2 < 0`` is infeasible) gives

    H(t, x) = −Bz = −max(−v1(t), 0) + N_[−v2(t), ∞)(x),
    J_{hH(t,·)}(x) = max(x + h max(−v1(t), 0), −v2(t)).

References (proximal scheme, uniform steps ``h = T/K``):

* ``v = (−t, 0)``, ``x0 ≥ 0``: ``x = x0 + t²/2``; the scheme gives ``x_k = x0 + h Σ_{j≤k} t_j =
  x0 + t_k²/2 + h t_k/2``, so the sup error is exactly ``hT/2`` (order 1, constant ``T/2``).
* ``v = (sin t, 0)``, ``x0 ≥ 0``: ``x = x0 + ∫_0^t max(−sin s, 0) ds = x0 + 2⌊t/2π⌋ + g(t mod 2π)`` with
  ``g(τ) = 0`` on ``[0, π]`` and ``1 + cos τ`` on ``[π, 2π]``; the scheme is the right Riemann sum of a
  Lipschitz, piecewise smooth integrand, error ``(h/2) max(−sin t, 0) + O(h²)`` (order 1, constant 1/2).

Pseudo-distance: with ``v(t1) = (0, 0)`` and ``v(t2) = (−1, 0)``, ``F1 = N_[0,∞)`` and ``F2 = −1 + N_[0,∞)``;
``(0, 0) ∈ graph F1`` and ``(ρ+1, −1) ∈ graph F2`` give ``dis(F1, F2) ≥ (ρ+1)/(1 + 0 + 1) = (ρ+1)/2`` for all
``ρ ≥ 0`` (the paper writes ``0 ∈ F1(ρ+1)``, ``1 ∈ F2(0)``; with ``H`` as above ``F2(0) = (−∞, −1]``, and the
symmetric numerator of ``def:dis`` gives the same bound from the pair used here).
"""

from __future__ import annotations

import math

import numpy as np

from verimono.lcs.relations import Complementarity
from verimono.lcs.system import LinearRelationSystem
from verimono.core.problem import Order, Problem
from verimono.core.pseudo_distance import pseudo_distance_lower_bound

A = np.zeros((1, 1))
B = np.array([[0.0, 1.0]])
C = B.T.copy()
D = np.array([[0.0, 1.0], [-1.0, 0.0]])


def example_system(v) -> LinearRelationSystem:
    """The Example's complementarity system with input ``v`` (constant or callable of ``t``)."""
    return LinearRelationSystem(A, B, C, D, Complementarity(), v=v, name="paper Example ex")


def closed_form_resolvent(x, h, v1, v2):
    """``J_{hH}(x) = max(x + h max(−v1, 0), −v2)``."""
    return np.maximum(np.asarray(x, float) + h * max(-v1, 0.0), -v2)


def closed_form_H(x, v1, v2):
    """``H(x)`` as an interval ``(lo, hi)`` (``None`` outside the domain ``x ≥ −v2``)."""
    if x < -v2:
        return None
    top = -max(-v1, 0.0)
    return (-np.inf, top) if x == -v2 else (top, top)


def _static_domain(t):
    """(A3) with φ = 0: ``dom H(t,·) = [−v2(t), ∞) = [0, ∞)`` does not move when ``v2 = 0``; and (LG) holds
    with ``σ(t) = max(−v1(t), 0)``, since ``|H^0(t, x)| = max(−v1(t), 0)`` on the whole domain."""
    return 0.0


def _unit_rate(t):
    """(YB) with ``θ(s) = s``: for ``x ∈ dom H(s,·) = [0, ∞)`` and ``c = max(−v1, 0)`` (1-Lipschitz for both
    references), ``J_{λH(s+λ,·)}(x) = x + λc(s+λ)``, so ``|Y_λ(s+λ, x)| = c(s+λ) ≤ c(s) + λ = |H^0(s, x)| +
    θ(s+λ) − θ(s)`` — ``H^0(s, x) = −c(s)`` on the whole domain, the boundary point included."""
    return float(t)


def ramp_problem(x0: float = 0.5, T: float = 2.0) -> Problem:
    """``v = (−t, 0)``: ``x = x0 + t²/2``, proximal-scheme error exactly ``hT/2``."""
    if x0 < 0:
        raise ValueError("x0 must be feasible: x0 ≥ −v2(0) = 0")
    sys = example_system(lambda t: np.array([-t, 0.0]))
    return sys.problem([x0], T, exact=lambda t: np.array([x0 + 0.5 * t * t]),
                       order=Order(1.0, "Example ex, v = (−t, 0): x_k = x0 + t_k²/2 + h t_k/2 (derived in "
                                   "reference/lcs_example.py)", constant=T / 2.0, regularity=math.inf,
                                   regularity_source="x = x0 + t^2/2 is a polynomial"),
                       steps=[T / 8, T / 16, T / 32, T / 64], name="Example ex, v = (−t, 0)",
                       phi=_static_domain, sigma=lambda t: t, theta=_unit_rate)


def _sine_exact(x0):
    def exact(t):
        k, tau = divmod(float(t), 2 * np.pi)
        g = 0.0 if tau <= np.pi else 1.0 + np.cos(tau)
        return np.array([x0 + 2.0 * k + g])
    return exact


def sine_problem(x0: float = 0.0, T: float = 3 * np.pi) -> Problem:
    """``v = (sin t, 0)``: ``x = x0 + ∫_0^t max(−sin s, 0) ds``; order 1 (right Riemann sum)."""
    if x0 < 0:
        raise ValueError("x0 must be feasible: x0 ≥ −v2(0) = 0")
    sys = example_system(lambda t: np.array([np.sin(t), 0.0]))
    return sys.problem([x0], T, exact=_sine_exact(x0),
                       order=Order(1.0, "Example ex, v = (sin t, 0): right Riemann sum of the Lipschitz "
                                   "max(−sin t, 0)", constant=0.5, regularity=1.0,
                                   regularity_source="x' = max(-sin t, 0) jumps in slope at t = k pi: x is "
                                                     "C^1 with a Lipschitz, non-differentiable derivative; "
                                                     "order 1 is what the scheme is bound to here"),
                       steps=[T / 64, T / 128, T / 256, T / 512], name="Example ex, v = (sin t, 0)",
                       phi=_static_domain, sigma=lambda t: max(-np.sin(t), 0.0), theta=_unit_rate)


def pseudo_distance_demo(rhos=(0.0, 1.0, 10.0, 100.0, 1000.0), lams=(0.5, 1.0, 2.0)):
    """``[(ρ, bound)]``: sampled lower bounds of ``dis(H(t1,·), H(t2,·))``, each ``≥ (ρ+1)/2``.

    ``v(t1) = (0, 0)``, ``v(t2) = (−1, 0)`` (``v(t) = (−t, 0)`` at ``t1 = 0``, ``t2 = 1``); graph points come
    from the resolvents of the system's ``H`` at samples that include ``0`` and ``ρ + 1 − λ``.
    """
    H = example_system(lambda t: np.array([-t, 0.0])).operator()
    out = []
    for rho in rhos:
        samples = np.unique(np.concatenate([np.linspace(-1.0, rho + 1.0, 9), [0.0], rho + 1.0 - np.asarray(lams)]))
        out.append((rho, pseudo_distance_lower_bound(H, H, samples, lams=lams, t1=0.0, t2=1.0)))
    return out


__all__ = ["example_system", "closed_form_resolvent", "closed_form_H", "ramp_problem", "sine_problem",
           "pseudo_distance_demo"]
