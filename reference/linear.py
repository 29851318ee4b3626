"""References with a linear operator, a Lipschitz field and an input.

* ``linear``: ``x' = -Mx`` with ``M + Mᵀ ⪰ 0`` (non-symmetric): ``x(t) = e^{-Mt} x0``.  The implicit
  Euler local error is ``|∫ (x'(t_{k+1}) - x'(s)) ds| ≤ h² max|x''|/2 ≤ h²|M²x0|/2`` (``|e^{-Mt}| ≤ 1``),
  and ``(I + hM)^{-1}`` is nonexpansive, so ``|x_k - x(t_k)| ≤ t_k h |M²x0|/2`` — order 1.  Slopes are
  pre-asymptotic while ``h|λ(M)|`` is not small, hence the small steps.
* ``lipschitz_input``: ``x' = -m x + f(x) + u(t)`` with ``f(x) = -a x + b`` and ``u = cos(ωt)``; the
  solution of the linear ODE with ``k = m + a`` is ``x = e^{-kt}(x0 - x_p(0)) + x_p(t)``,
  ``x_p(t) = b/k + (k cos ωt + ω sin ωt)/(k² + ω²)``.  The scheme is the IMEX Euler method (explicit
  in ``f``, implicit in ``F``, exact quadrature of ``u`` to 6th order) — order 1 (Bastien–Schatzman 2002
  for the implicit/explicit splitting; classical for smooth data).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import expm

from verimono.core.operators import Linear
from verimono.core.problem import Order, Problem

M_DEFAULT = np.array([[1.0, 3.0], [-3.0, 0.5]])


def linear(M=M_DEFAULT, x0=(1.0, 0.0), T: float = 2.0) -> Problem:
    """``x' = -Mx`` with ``M + Mᵀ ⪰ 0``; error ``≤ t_k h |M² x0| / 2``."""
    M, x0 = np.asarray(M, dtype=float), np.asarray(x0, dtype=float)
    bound = float(np.linalg.norm(M @ M @ x0)) / 2.0
    # e^{-Mt} x0 = x0 + V (e^{-Λt} - I) V^{-1} x0 when M = VΛV^{-1} is diagonalisable with a well-conditioned V
    # (the default M: a complex pair, cond(V) = 1.09): a few flops per t instead of a Padé expm, which a
    # convergence study asks for at every node (6200 of them), and x0 exactly at t = 0; otherwise expm
    lam, V = np.linalg.eig(M)
    if np.linalg.cond(V) < 1e3:
        c = np.linalg.solve(V, x0.astype(complex))

        def exact(t):
            return x0 + (V @ (np.expm1(-lam * t) * c)).real
    else:
        def exact(t):
            return expm(-M * t) @ x0

    return Problem(Linear(M), x0, T, exact=exact,
                   order=Order(1.0, "implicit Euler on x' = -Mx: |x_k - x(t_k)| <= t_k h |M^2 x0|/2 "
                                    "(derived in verimono.reference.linear; literature notes)",
                               constant=bound * T, regularity=math.inf,
                               regularity_source="x = exp(-Mt) x0 is analytic"),
                   name="linear x' = -Mx", steps=[T / k for k in (200, 400, 800, 1600, 3200)])


def lipschitz_input(m: float = 1.0, a: float = 0.5, b: float = 0.2, omega: float = 2.0,
                    x0: float = 1.0, T: float = 3.0) -> Problem:
    """``x' = -mx + (-ax + b) + cos(ωt)``: exercises the Lipschitz and input terms of Section 6."""
    k = m + a

    def xp(t):
        return b / k + (k * math.cos(omega * t) + omega * math.sin(omega * t)) / (k * k + omega * omega)

    def exact(t):
        return np.array([math.exp(-k * t) * (x0 - xp(0.0)) + xp(t)])

    return Problem(Linear([[m]]), [x0], T, f=lambda x: -a * x + b, u=lambda t: np.array([math.cos(omega * t)]),
                   exact=exact, lipschitz=a,
                   order=Order(1.0, "IMEX Euler (explicit f, implicit F): Bastien-Schatzman 2002; classical "
                                    "first order for smooth data", regularity=math.inf,
                               regularity_source="smooth data: the solution is C^infinity"),
                   name="Lipschitz field and input", steps=[T / k for k in (100, 200, 400, 800, 1600)])
