"""References for subdifferential flows ``x' ∈ -∂g(t, x)``.

* ``t_norm``: the paper's example ``g(t, x) = t|x|`` (Section 4, ``sec:convexSubdiff``).  With
  ``r = |x0|`` the solution is ``x(t) = max(1 - t²/(2r), 0) x0`` (``|x|' = -t`` until extinction at
  ``t* = sqrt(2r)``).  On a uniform grid the scheme shrinks ``|x_{k+1}| = max(|x_k| - h t_{k+1}, 0)``,
  so ``|x_k| = r - t_k²/2 - h t_k/2`` before extinction: the error ``h t_k/2`` peaks near ``t*`` at
  ``h sqrt(r/2) + O(h²)`` — order 1 with constant ``sqrt(r/2)`` (derived here, checked in tests).
* ``log_barrier``: ``g = -c ln x`` on ``(0, ∞)``, ``x' = c/x``, ``x0 = 0 ∈ cl dom``: ``x = sqrt(2ct)``.
  The first step gives ``x_1 = sqrt(ch)`` against ``sqrt(2ch)``: sup error ``(√2 - 1) sqrt(ch)``, order
  exactly 1/2 (derived here).  The O(h^{1/2}) results of the literature notes do not cover this start:
  Crandall–Liggett and Rulla 1996 ask ``x0 ∈ D(A)`` or ``x0 ∈ D(φ)``, and here ``x0 = 0`` lies only in
  the closure (``φ(0) = -c ln 0 = +∞``); the derivation shows the rate 1/2 holds there too, and is
  sharp.  The harness must never certify order 1 here.
"""

from __future__ import annotations

import math

import numpy as np

from verimono.core.operators import LogBarrier, NormSubdifferential
from verimono.core.problem import Order, Problem

#: the regularity of t|x|: x is Lipschitz, with a jump of x' at the extinction time
LIPSCHITZ_KINK = ("x is Lipschitz and x' jumps at the extinction time t* = sqrt(2|x0|) (x in W^{1,inf}, not "
                  "C^1): first order, Rulla 1996 (x0 in D(dphi)); no uniform order above 1 for a generic scheme")


def _tnorm_c(t):
    return t


def t_norm(x0=(1.0,), T: float = 2.0) -> Problem:
    """``x' ∈ -∂(t|x|)(x)`` (any dimension): exact solution and order-1 error constant sqrt(r/2)."""
    x0 = np.asarray(x0, dtype=float)
    r = float(np.linalg.norm(x0))

    def exact(t):
        return max(1.0 - t * t / (2.0 * r), 0.0) * x0

    def on_times(t):
        """``exact`` at every time of the array ``t`` at once, bit for bit (the same operations, elementwise):
        a study's per-node Python calls were a third of its time (0.24 s per 10^5 nodes)."""
        return np.maximum(1.0 - t * t / (2.0 * r), 0.0)[:, None] * x0

    exact.on_times = on_times
    n = x0.size
    return Problem(
        NormSubdifferential(_tnorm_c, dim=n), x0, T, exact=exact,
        order=Order(1.0, "derived in verimono.reference.subdifferential: |x_k| = r - t_k^2/2 - h t_k/2 "
                         "before extinction, sup error h sqrt(r/2) + O(h^2); paper Section 4 example "
                         "g(t,x)=t|x| satisfies (YB') with theta(s)=s", constant=math.sqrt(r / 2.0),
                    regularity=1.0, regularity_source=LIPSCHITZ_KINK),
        name=f"t|x| (n={n})", steps=[T / k for k in (40, 80, 160, 320, 640)],
        theta=lambda s: s, sigma=lambda s: s,
        notes="extinction at t* = sqrt(2|x0|) lies inside [0, T]")


def log_barrier(c: float = 1.0, T: float = 1.0) -> Problem:
    """``x' = c/x`` from ``x0 = 0``: ``x = sqrt(2ct)``, error ``(√2-1) sqrt(ch)`` — order exactly 1/2."""
    def exact(t):
        return np.array([math.sqrt(2.0 * c * t)])

    return Problem(
        LogBarrier(c), [0.0], T, exact=exact,
        order=Order(0.5, "derived in verimono.reference.subdifferential: x_1 = sqrt(ch) vs sqrt(2ch), "
                         "sup error (sqrt 2 - 1) sqrt(c h), exactly; x0 = 0 is outside D(phi), beyond Rulla 1996's "
                         "O(h^1/2) for x0 in D(phi)",
                    constant=(math.sqrt(2.0) - 1.0) * math.sqrt(c), regularity=0.5,
                    regularity_source="x = sqrt(2ct) is only Hölder-1/2 at t = 0 (x0 on the boundary of "
                                      "D(phi)): O(h^1/2), Crandall-Liggett 1971, Rulla 1996"),
        name="x' = c/x from 0 (order 1/2)", steps=[T / k for k in (100, 200, 400, 800, 1600)],
        notes="(LG) fails: |F^0(x)| = c/x is unbounded near the boundary of the domain")


def _slow_c(t):
    return 0.1 * t ** -0.9 if t > 0 else 0.0


def slow_rate(T: float = 1.0) -> Problem:
    """``x' ∈ -∂(c(t)|x|)`` with ``c(t) = 0.1 t^{-0.9}`` from ``x0 = 2``: ``x = 2 - t^{0.1}`` while positive
    (until ``t = 2^{10}``).  ``σ = c`` is in L¹ but unbounded, so (LG) holds and the paper gives no rate.
    On a uniform grid the scheme subtracts ``h c(t_{k+1})`` per cell, ``h c(h) = 0.1 h^{0.1}`` on the first
    against ``∫_0^h c = h^{0.1}``, and ``h^{0.1}(j^{0.1} − (j−1)^{0.1} − 0.1 j^{−0.9})`` on cell ``j``: the error
    at ``t_k`` sums to ``h^{0.1} Σ_{j≤k}(...) → 0.943 h^{0.1}`` (the series, summed to 10^7 terms) — order 0.1
    (measured: 1.0477·0.9 h^{0.1} at K = 40 … 2560), and the uniform and graded
    (``h_1 = T/K²``) solutions drift *apart* like ``0.9(K^{-0.1} − K^{-0.2})`` until ``K = 2^{10}``.
    ``c(0) = 0`` is a convention (the scheme never evaluates ``F`` at ``t = 0``).  Not in the run's catalog:
    the test problem of ``unique_limit`` without an assumed rate (``tests/checks/test_trajectory_laws.py``)."""
    def exact(t):
        return np.array([2.0 - t ** 0.1])

    return Problem(NormSubdifferential(_slow_c, dim=1), [2.0], T, exact=exact,
                   order=Order(0.1, "derived in verimono.reference.subdifferential.slow_rate: the cell errors sum to "
                                    "0.943 h^0.1; none is ever recovered", constant=0.943),
                   name="c = 0.1 t^-0.9 (order 0.1)", steps=[T / k for k in (40, 160, 640, 2560, 10240)],
                   sigma=_slow_c, phi=lambda t: 0.0,
                   notes="sigma in L1 but unbounded near 0: no rate from the paper")
