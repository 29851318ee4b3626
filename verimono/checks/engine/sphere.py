"""The largest value of a function of a direction ``d ∈ S^{n-1}``: the sphere as a searched coordinate of a
law that is not over pairs (:mod:`.directions` serves the pair laws from their worst sample).

Used by (A3): the domain's motion ``sup_{x ∈ dom F(s)} dist(x, dom F(t))`` is attained on the boundary of
``dom F(s)``, at the point exposed in some direction ``d`` — the projection onto ``dom F(s)`` of a far point
``x0 + R d``.  A ball translating by ``v`` moves its boundary point ``c + r d`` by about ``−v·d``: the points
around ``x0`` meet the worst direction within an angle ``θ`` only with a probability that vanishes with the
dimension (in ``R^10`` a ``φ`` 6% too small everywhere passed, ratio 0.911 = the best ``cos θ`` of 13 points).
:func:`sphere_maximise` searches the sphere in three phases, deterministic per seed:

1. **drawn**: the caller's ``start`` directions and :data:`DRAWN_PER_DIM` ``n`` directions uniform on the
   sphere (normalised Gaussians);
2. **ascent**: from the best, the tangent gradient by forward differences along ``n`` random orthonormal
   directions, then the best point of the great circle toward it (golden section on the angle in
   ``[0, π/2]``), :data:`ASCENT_STEPS` times;
3. **refinement**: a (1+1) evolution strategy — a random rotation by ``θ``, kept when the value grows (``θ``
   × 1.5), else ``θ`` × 0.8 — with what is left of ``points``, down to :data:`FINEST` radians.
"""

from __future__ import annotations

import math
from typing import Callable, Sequence

import numpy as np

from .supremum import _golden

#: directions drawn per dimension in the first phase
DRAWN_PER_DIM = 2
#: gradient-and-line-search steps of the ascent, the golden-section steps of each line search, and the
#: step of the forward differences (radians)
ASCENT_STEPS = 3
LINE_STEPS = 12
DIFF_STEP = 1e-4
#: the refinement's first and finest rotation angles (radians)
FIRST_ANGLE = 0.2
FINEST = 1e-4


def _unit(v: np.ndarray) -> np.ndarray | None:
    m = float(np.linalg.norm(v))
    return None if m == 0.0 or not math.isfinite(m) else v / m


def sphere_maximise(f: Callable[[np.ndarray], float], n: int, *, points: int, seed: int = 0,
                    start: Sequence[np.ndarray] = ()) -> dict:
    """The largest ``f(d)`` found over ``d ∈ S^{n-1}`` (module docstring), at most about ``points``
    evaluations (the drawn directions and the ascent first).  Returns ``{"value", "direction", "points",
    "resolution", "sphere"}``: ``resolution`` the last rotation angle of the refinement (radians)."""
    rng = np.random.default_rng([int(seed) % (2 ** 63), int(n), 0x5A8E])
    best = [-math.inf, None]
    count = [0]

    def ev(d: np.ndarray) -> float:
        v = float(f(d))
        count[0] += 1
        if v != v:
            v = math.inf
        if v > best[0] or best[1] is None:
            best[:] = [v, d]
        return v

    if n == 1:
        for d in (np.ones(1), -np.ones(1)):
            ev(d)
        return {"value": best[0], "direction": best[1], "points": count[0], "resolution": 0.0, "sphere": "S^0"}
    for d in start:
        u = _unit(np.asarray(d, dtype=float))
        if u is not None:
            ev(u)
    for _ in range(DRAWN_PER_DIM * n):
        u = _unit(rng.standard_normal(n))
        if u is not None:
            ev(u)
    for _ in range(ASCENT_STEPS):
        if count[0] + n + LINE_STEPS > points or not math.isfinite(best[0]):
            break
        d, f0 = best[1], best[0]
        q, _ = np.linalg.qr(rng.standard_normal((n, n)))
        g = np.zeros(n)
        for i in range(n):
            e = q[:, i] - (q[:, i] @ d) * d
            e = _unit(e)
            if e is None:
                continue
            g += (ev(math.cos(DIFF_STEP) * d + math.sin(DIFF_STEP) * e) - f0) / DIFF_STEP * e
        g = _unit(g - (g @ d) * d)
        if g is None:
            break
        # the line search along the great circle from d toward g (ev keeps the best point it meets)
        _golden(lambda th, d=d, g=g: -ev(math.cos(th) * d + math.sin(th) * g), 0.0, math.pi / 2, steps=LINE_STEPS)
    theta, d = FIRST_ANGLE, best[1]
    while count[0] < points and theta >= FINEST:
        g = rng.standard_normal(n)
        g = _unit(g - (g @ d) * d)
        if g is None:
            break
        cand = math.cos(theta) * d + math.sin(theta) * g
        before = best[0]
        ev(cand)
        if best[0] > before:
            d, theta = cand, theta * 1.5
        else:
            theta *= 0.8
    return {"value": best[0], "direction": best[1], "points": count[0], "resolution": float(min(theta, FIRST_ANGLE)),
            "sphere": f"S^{n - 1}"}


__all__ = ["sphere_maximise", "DRAWN_PER_DIM", "ASCENT_STEPS", "LINE_STEPS", "FIRST_ANGLE", "FINEST"]
