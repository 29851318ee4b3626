"""Seeded random problems (numpy, no hypothesis) for the plain runner's battery and the no-false-alarm tests.

Every problem is valid by construction and states the functions of the paper's assumptions that hold
for it, derived here:

* ``linear`` — ``F = M`` with ``M = SSᵀ + W - Wᵀ`` (``M + Mᵀ ⪰ 0``): ``dom F = R^n`` so (A3) with
  ``φ ≡ 0``; (LG) with ``σ = ‖M‖₂`` (``|Mx| ≤ ‖M‖|x|``); (YB') with ``θ ≡ 0`` (static, Prop. vi).
* ``norm`` — ``∂(c(t)|·|)``, ``c = c0 + c1 t`` (``c1 ≥ 0``): ``|F^0| ≤ c`` so σ = c; (YB) with ``θ = c``
  (``|Y_λ(s+λ,x)| = min(|x|/λ, c(s+λ)) ≤ c(s+λ) - c(s) + |F^0(s,x)|`` for ``x ≠ 0``, 0 at 0).
* ``l1`` — ``∂(Σ c_i(t)|x_i|)``, ``c = c0 + c1 t``: σ = |c(t)|, θ = |c1| t (``Y_λ`` is componentwise
  ``min(|x_i|/λ, c_i)`` sgn, 1-Lipschitz in ``c``).
* ``ball`` / ``box`` / ``halfspace`` — normal cones of moving sets: ``F^0 = 0`` on the domain, so (LG)
  with ``σ ≡ 0``; (A3) with ``φ = rate·t``: a ball ``B(c0 + vt, r0 + ρt)`` moves by ``|v| + max(-ρ, 0)``,
  a box with bounds ``l0 + at``, ``u0 + bt`` by ``|max(|a|, |b|)|``, a half-space
  ``⟨a,x⟩ ≤ b0 + b1 sin ωt`` by ``|b1| ω / |a|``.
* ``input`` — ``linear`` with ``u = A cos ωt`` (primitive ``U`` exact): lemma ``l:extinput``.
* ``lipschitz`` — a static ball's normal cone with ``f(x) = Bx + b``, ``L = ‖B‖₂``.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.operators import L1Subdifferential, Linear, NormalCone, NormSubdifferential
from ..core.errors import InvalidCheckArgument
from ..core.problem import Problem
from ..core.sets import Ball, Box, HalfSpace

FAMILIES = ("linear", "norm", "l1", "ball", "box", "halfspace", "input", "lipschitz")


def sample_problem(seed: int, family: str | None = None) -> Problem:
    """One random problem (dimension 1–3, ``T ∈ [0.5, 2]``) of ``family`` (default: by ``seed``)."""
    rng = np.random.default_rng(seed)
    family = family or FAMILIES[seed % len(FAMILIES)]
    n = int(rng.integers(1, 4))
    T = float(rng.uniform(0.5, 2.0))
    x0 = rng.uniform(-2.0, 2.0, n)
    name = f"sample[{family}, seed={seed}, n={n}]"
    if family in ("linear", "input"):
        S = rng.uniform(-1.5, 1.5, (n, n))
        W = rng.uniform(-2.0, 2.0, (n, n))
        M = S @ S.T + W - W.T
        nrm = float(np.linalg.norm(M, 2))
        kw = {}
        if family == "input":
            A = rng.uniform(-2.0, 2.0, n)
            w = float(rng.uniform(0.5, 4.0))
            kw = dict(u=lambda t, A=A, w=w: A * math.cos(w * t), U=lambda t, A=A, w=w: A * math.sin(w * t) / w)
        return Problem(Linear(M), x0, T, name=name, phi=lambda t: 0.0, sigma=lambda t, s=nrm: s,
                       theta=lambda t: 0.0, **kw)
    if family == "norm":
        c0, c1 = rng.uniform(0.0, 2.0), rng.uniform(0.0, 2.0)
        c = lambda t, a=c0, b=c1: a + b * t  # noqa: E731
        return Problem(NormSubdifferential(c, n), x0, T, name=name, phi=lambda t: 0.0, sigma=c, theta=c)
    if family == "l1":
        c0, c1 = rng.uniform(0.0, 2.0, n), rng.uniform(0.0, 2.0, n)
        c = lambda t, a=c0, b=c1: a + b * t  # noqa: E731
        r1 = float(np.linalg.norm(c1))
        return Problem(L1Subdifferential(c, n), x0, T, name=name, phi=lambda t: 0.0,
                       sigma=lambda t, f=c: float(np.linalg.norm(f(t))), theta=lambda t, r=r1: r * t)
    zero = lambda t: 0.0  # noqa: E731
    if family == "ball":
        c0, v = rng.uniform(-1.0, 1.0, n), rng.uniform(-1.5, 1.5, n)
        r0, rho = float(rng.uniform(0.3, 2.0)), float(rng.uniform(-0.1, 0.5))
        S = Ball(lambda t, a=c0, b=v: a + b * t, lambda t, a=r0, b=rho: a + b * t)
        rate = float(np.linalg.norm(v)) + max(-rho, 0.0)
        op = NormalCone(S)
        return Problem(op, op.project_domain(x0, 0.0), T, name=name, phi=lambda t, r=rate: r * t, sigma=zero)
    if family == "box":
        l0, a, b = rng.uniform(-1.5, 0.0, n), rng.uniform(-1.0, 1.0, n), rng.uniform(-1.0, 1.0, n)
        w0 = rng.uniform(0.1, 1.0, n) + np.abs(b - a) * T
        S = Box(lambda t, l=l0, s=a: l + s * t, lambda t, l=l0 + w0, s=b: l + s * t)
        rate = float(np.linalg.norm(np.maximum(np.abs(a), np.abs(b))))
        op = NormalCone(S)
        return Problem(op, op.project_domain(x0, 0.0), T, name=name, phi=lambda t, r=rate: r * t, sigma=zero)
    if family == "halfspace":
        a = rng.uniform(0.5, 2.0, n) * rng.choice([-1.0, 1.0], n)
        b0, b1, w = float(rng.uniform(-0.5, 0.5)), float(rng.uniform(0.5, 2.0)), float(rng.uniform(1.0, 4.0))
        S = HalfSpace(a, lambda t, p=b0, q=b1, o=w: p + q * math.sin(o * t))
        rate = abs(b1) * w / float(np.linalg.norm(a))
        op = NormalCone(S)
        return Problem(op, op.project_domain(x0, 0.0), T, name=name, phi=lambda t, r=rate: r * t, sigma=zero)
    if family == "lipschitz":
        B = rng.uniform(-1.0, 1.0, (n, n))
        b = rng.uniform(-1.0, 1.0, n)
        op = NormalCone(Ball(np.zeros(n), 1.5))
        return Problem(op, op.project_domain(x0, 0.0), T, name=name, f=lambda x, B=B, b=b: x @ B.T + b,
                       lipschitz=float(np.linalg.norm(B, 2)), phi=zero, sigma=zero)
    raise ValueError(f"unknown family {family!r}; known: {FAMILIES}")


def valid_count(count: object, what: str = "generated") -> int:
    """``count`` as a number of sample problems: an integer ``>= 0`` (0: none), else
    :class:`verimono.InvalidCheckArgument` — ``generated=-1`` would draw none and say nothing."""
    import numbers

    if isinstance(count, bool) or not isinstance(count, numbers.Integral) or count < 0:
        raise InvalidCheckArgument(f"{what} is a number of sample problems, an integer >= 0, got {count!r}")
    return int(count)


def sample_problems(seed: int = 0, count: int = len(FAMILIES)) -> list[Problem]:
    """``count`` problems cycling through the families, seeds ``seed, seed + 1, ...`` (``count`` an integer
    ``>= 0``: :func:`valid_count`)."""
    count = valid_count(count)
    return [sample_problem(seed + i, FAMILIES[(seed + i) % len(FAMILIES)]) for i in range(count)]


__all__ = ["FAMILIES", "sample_problem", "sample_problems", "valid_count"]
