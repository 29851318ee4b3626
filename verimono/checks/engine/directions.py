"""The direction coordinate of the operator laws over pairs: ``x2 = x1 + r d`` for every ``d`` on the unit
sphere ``S^{n-1}``.

A law over pairs — monotonicity ``⟨x_a − x_b, y_a − y_b⟩ ≥ 0`` (A1), firm nonexpansiveness
``|J_λx1 − J_λx2|² ≤ ⟨J_λx1 − J_λx2, x1 − x2⟩``, the ``1/λ``-Lipschitz Yosida approximation (Proposition
``prop:maxmon-resolvent-Yosida`` ii, iv) — holds for every direction of ``x2 − x1``.  In ``R^12`` the directions
within 10° of one 2-plane are a fraction ``~10^-8`` of the sphere: random pairs never meet an operator that is
non-monotone only there.  So, from the worst sample ``(x1, x2)`` of the search (``r = |x2 − x1|``; for a pair
``x1 = x2``, often the worst of a law ``lhs ≥ 0``, ``r = 10^-2 (1 + |x1|)``), the direction is searched in three
ways:

1. **the sketch** (:func:`sketch_directions`): the difference map of the resolvent at ``x1``,
   ``M q_i = (J_λ(x1 + r q_i) − J_λ x1)/r`` on a random orthonormal basis ``q_1 … q_n`` (``n`` calls of the
   resolvent), is the resolvent's linearisation at scale ``r``.  Each pair law is, to first order, a quadratic
   form in ``d`` whose worst direction is an extreme eigenvector: of ``sym M`` (monotonicity of ``J`` and of
   ``I − J``, i.e. of ``F`` and ``Y_λ``), of ``MᵀM`` (nonexpansiveness), of ``MᵀM − sym M`` (firm
   nonexpansiveness, ``λ``-cocoercivity of ``Y_λ``) and of ``(I − M)ᵀ(I − M)`` (the Lipschitz constant of
   ``λY_λ``).  Both extreme eigenvectors of each, with both signs, at radius ``r``;
2. **the sphere**: ``points`` directions drawn uniformly on ``S^{n-1}`` (normalised Gaussians, seeded), at most
   :data:`PER_DIMENSION` ``n``;
3. **refinement**: a (1+1) evolution strategy on the sphere from the worst direction found — a random
   rotation by an angle ``θ`` kept when the ratio grows (``θ`` × 1.5), ``θ`` × 0.8 otherwise — with
   ``points / 2`` evaluations, down to :data:`FINEST` radians, then again from a drawn direction while
   evaluations are left (``thorough``'s budget: the evaluations scale with the profile).

A law that does not read the direction (its ratio the same to the last bit at three random directions and the
sample's own, and then at ``points`` more drawn) is covered by those points only (``"read": False``).  The record states what was searched:
directions drawn, sketched and refined, and the finest angle of the refinement.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Callable

import numpy as np

from ...execution.interrupts import interruptible
from ..members import norm
from .samples import NUMPY_DIM, Sample, with_field

#: the refinement's first and finest rotation angles (radians)
FIRST_ANGLE = 0.3
FINEST = 1e-4
#: the radii of the sketch's candidate directions, relative to the worst pair's ``r``
SKETCH_RADII = (1.0,)
#: directions drawn per dimension at most (:func:`drawn_count`)
PER_DIMENSION = 4
#: the distance of the pair searched when the worst sample is a pair ``x1 = x2``, relative to ``1 + |x1|``
PAIR_RADIUS = 1e-2


def drawn_count(points: int, n: int) -> int:
    """Directions drawn on ``S^{n-1}``: the budget's ``points``, but no more than :data:`PER_DIMENSION` per
    dimension or a quarter of the budget, whichever is more (the circle of ``R^2`` needs no 729 directions; the
    sketch and the refinement cover the rest — but ``thorough`` draws 182 where ``ci`` draws 12 in ``R^3``)."""
    return max(1, min(int(points), max(PER_DIMENSION * n, int(points) // 4)))


def _unit(v: np.ndarray) -> np.ndarray | None:
    m = norm(v)
    return None if m == 0.0 or not math.isfinite(m) else v / m


@interruptible   # the subject's code: the unit's budget may stop it
def sketch_directions(op: Any, s: Sample, r: float, rng: np.random.Generator) -> list[np.ndarray]:
    """Candidate worst directions of the pair laws at ``x1``: extreme eigenvectors of the four matrices of the
    module docstring, built from ``n`` resolvent calls at ``x1 + r q_i`` (``[]`` when a call raises or returns
    no finite point: the laws meet that themselves)."""
    n = s.x1.size
    q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    try:
        j0 = np.asarray(op.resolvent(s.x1.copy(), s.lam, s.t), dtype=float)
        cols = [np.asarray(op.resolvent(s.x1 + r * q[:, i], s.lam, s.t), dtype=float) for i in range(n)]
    except Exception:       # noqa: BLE001 - the laws evaluate (and judge) the resolvent's exceptions
        return []
    if j0.shape != (n,) or any(c.shape != (n,) for c in cols):
        return []
    m = ((np.array(cols) - j0) / r).T @ q.T            # M = D Qᵀ, D's columns the differences along q_i
    if not np.all(np.isfinite(m)):
        return []
    with np.errstate(over="ignore", invalid="ignore"):
        sym, gram, res = 0.5 * (m + m.T), m.T @ m, np.eye(n) - m
        forms = (sym, gram, gram - sym, res.T @ res)
    out = []
    for a in forms:
        # a finite M whose squares overflow (a resolvent with differences ~1e160: LogBarrier near 0 at a large
        # step) has no eigenvectors to read: eigh of inf gave NaN directions, and the search then handed the
        # subject x2 = x1 + r·NaN and blamed it for the NaN it returned (a correct operator failed yosida_monotone
        # in the dev profile, seed 2853691650)
        if not np.all(np.isfinite(a)):
            continue
        _, v = np.linalg.eigh(0.5 * (a + a.T))
        out += [d for d in (v[:, 0], v[:, -1]) if np.all(np.isfinite(d))]
    return out


def direction_search(evaluate: Callable[[Sample], float], op: Any, s: Sample, points: int,
                     seed: int, many: Callable[[list[Sample]], list[float]] | None = None) -> dict | None:
    """The direction of ``x2 − x1`` searched from the worst sample ``s`` (module docstring); ``evaluate`` returns
    the law's ratio (``-inf`` when inconclusive) and raises on a violation, which ends the search.  ``None`` when
    the direction cannot move (``n = 1``, ``n`` above :data:`NUMPY_DIM`, a recipe sample); a pair ``x1 = x2`` is
    opened to ``r =`` :data:`PAIR_RADIUS` ``(1 + |x1|)``.  ``many(samples)``: the ratios of a list, in order (the
    search's evaluates a law's vectorised form over all of them at once); the directions known before any of
    them is evaluated — the first four, the flat check's, the sketch's and the drawn ones — are evaluated as
    lists (the same directions, from the same draws of the generator, as one at a time), the refinement one at
    a time (each step depends on the last)."""
    n = s.x1.size
    if s.recipe is not None or n < 2 or n > NUMPY_DIM:
        return None
    rng = np.random.default_rng([int(seed) % (2 ** 63), n, 0xD1EC])
    r = norm(s.x2 - s.x1)
    if r == 0.0:        # the worst sample of a law "≥ 0" is often the pair x1 = x2 (ratio 0): a nearby pair
        r = PAIR_RADIUS * (1.0 + norm(s.x1))
        s = dataclasses.replace(s, x2=s.x1 + r * _unit(rng.standard_normal(n)))
    if not math.isfinite(r) or r == 0.0:
        return None

    def at(d: np.ndarray, radius: float = r) -> Sample:
        return with_field(s, "x2", s.x1 + radius * d)

    best = [-math.inf, (s.x2 - s.x1) / r, r]

    def ev(d: np.ndarray, radius: float = r) -> float:
        v = evaluate(at(d, radius))
        if v > best[0]:
            best[:] = [v, d, radius]
        return v

    def evs(ds: list[tuple[np.ndarray, float]]) -> list[float]:
        """``ev`` of each ``(d, radius)``, in order, through ``many``."""
        if many is None or len(ds) < 2:
            return [ev(d, radius) for d, radius in ds]
        vals = many([at(d, radius) for d, radius in ds])
        for (d, radius), v in zip(ds, vals):
            if v > best[0]:
                best[:] = [v, d, radius]
        return list(vals)

    drawn = [_unit(rng.standard_normal(n)) for _ in range(3)]
    first = evs([(best[1], r)] + [(d, r) for d in drawn if d is not None])
    if len(set(first)) <= 1:        # flat at four directions: ``points`` more drawn before it is called unread
        first += evs([(d, r) for d in (_unit(rng.standard_normal(n)) for _ in range(int(points))) if d is not None])
        if len(set(first)) <= 1:
            return {"coordinate": "direction", "read": False, "points": len(first), "log": False,
                    "range": [0.0, math.pi], "unit": "rad", "sphere": f"S^{n - 1}"}
    count = len(first)
    sketched = sketch_directions(op, s, r, rng)
    known = [(sign * d, radius) for d in sketched for radius in (r * k for k in SKETCH_RADII) for sign in (1.0, -1.0)]
    for _ in range(drawn_count(points, n)):
        d = _unit(rng.standard_normal(n))
        if d is not None:
            known.append((d, r))
    evs(known)
    count += len(known)
    theta, d, radius = FIRST_ANGLE, best[1], best[2]
    restarts, cur, finest = 0, best[0], theta
    for _ in range(max(1, int(points) // 2)):
        if theta < FINEST:      # refined to the finest angle: again from a drawn direction, while budget is left
            d = _unit(rng.standard_normal(n))
            if d is None:
                break
            restarts, theta = restarts + 1, FIRST_ANGLE
            cur = ev(d, radius)
            count += 1
            continue
        g = rng.standard_normal(n)
        g -= (g @ d) * d
        g = _unit(g)
        if g is None:
            break
        cand = math.cos(theta) * d + math.sin(theta) * g
        v = ev(cand, radius)
        count += 1
        if v > cur:
            d, cur, theta = cand, v, theta * 1.5
        else:
            theta *= 0.8
        finest = min(finest, theta)
    return {"coordinate": "direction", "read": True, "points": count, "log": False, "unit": "rad",
            "range": [0.0, math.pi], "resolution": float(min(finest, FIRST_ANGLE)), "sphere": f"S^{n - 1}",
            "drawn": drawn_count(points, n), "sketched": len(sketched), "restarts": restarts}


__all__ = ["direction_search", "sketch_directions", "drawn_count", "FIRST_ANGLE", "FINEST", "SKETCH_RADII",
           "PER_DIMENSION"]
