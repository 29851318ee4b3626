"""The time coordinate of the assumption laws: every "for all t ∈ [lo, hi]" searched by count, declared once.

(A1), (A2), (A3), (LG) and (YB) are claims about every time.  Each law hands this module its ratio as a
function of ``t`` (and of its *families*: a sample point, a step size, a pair) and gets the largest value
over the **time design** of :func:`time_design`:

* **by count, the same on every machine**: ``N =`` :func:`strata` ``= STRATA_PER_POINT · budget("time")`` points
  (``dev`` 1536, ``ci`` 3072, ``thorough`` 32768 — at most :data:`MOST_STRATA`; ``budgets(time=n)`` sets ``6n``
  for a block), fixed by the
  profile and the seed — a busy machine evaluates the
  same points as an idle one, only more slowly.  The unit's time budget is a guard: a search it stops is
  recorded undecided (the unit's timeout), never passed;
* **both ends**, ``lo`` and ``hi``;
* **stratified and jittered**: one point in each of ``N`` equal strata, at the stratum's middle moved by up to
  ``±JITTER/2`` of a stratum (seeded).  No two gaps are equal, so a violation periodic with the spacing of a
  uniform grid (``kT/384 + offset``, between every pair of a grid's points) is not aliased away: each of its
  windows is met with a probability of its width over a stratum's, independently; and the largest gap is at
  most ``(1 + JITTER)·(hi − lo)/N`` (:func:`promised_resolution`): a violation on any interval wider than
  that contains a point of the design;
* **refined at the worst windows**: DIRECT and the bounded Brent searches of
  :func:`verimono.checks.engine.supremum.maximise` (its ``cover`` phase is this design).

A law whose ``values`` carries a vectorised form ``values.many(ts, which) -> (len(ts), len(which))`` has the
coverage (every design time known in advance) evaluated through it, in blocks of :data:`MANY_BLOCK` times: the
subject's calls as the law makes them, the law's arithmetic over all the times at once, and the engine's
bookkeeping in one pass.  The engine takes a vectorised value only when it is ``-inf`` (a family undefined
there) or finite and at most ``SUSPECT`` times the form's ``bound`` (default 1); any other row — NaN, ``inf``,
near or above the bound, a block that met an unverified solve of verimono's own — is evaluated again by
``values`` itself, which alone decides a failure (:meth:`verimono.checks.engine.supremum._Evaluator.many`).  The
forms repeat their law's operations to the bit (tests/checks/test_time_vectorised.py compares them).

What was searched goes in the record (``details["searched"]["t"]``): the points, the evaluations, the
**resolution** (the largest gap between evaluated times, at most the promised one) and the finest bracket of
the refinement.  ``ci`` resolves ``t`` to ``T/2048`` (better than the ``T/2000`` issue 42 asks), ``thorough``
evaluates ten times ``ci``'s times and more, ``dev`` fewer.
"""

from __future__ import annotations

from typing import Callable, Sequence

import numpy as np

from ...core.errors import UnverifiedSolution
from ...execution.timeouts import note_progress
from .supremum import Space, Sup, budget, maximise

#: the jitter of a stratum's point, as a fraction of the stratum (its point lies in the middle
#: ``JITTER`` of it): gaps between ``(1 − JITTER)`` and ``(1 + JITTER)`` strata
JITTER = 0.5
#: strata of the time design per point of the profile's ``search["time"]`` budget (which the one-dimensional
#: searches of other laws, Section 7's, keep): ``ci``'s 512 give 3072 strata, resolving ``(1 + JITTER)/3072 =
#: T/2048``
STRATA_PER_POINT = 6
#: the refinement at the worst windows: DIRECT's evaluations, and the local phase's, are the design's count
#: over ``REFINE_PER`` each (``ci``: 64, as before the design), at least ``LOCAL_MIN_POINTS``
REFINE_PER = 48
LOCAL_MIN_POINTS = 16


#: times per block of a law's vectorised form (``values.many``) in the coverage: the unit's budget meets the
#: search between blocks (:func:`verimono.execution.timeouts.note_progress`)
MANY_BLOCK = 256

#: the most strata of one design: ``thorough``'s, a little over ten times ``ci``'s (its stage budgets are ten
#: times ``ci``'s; 6 x 8192 would be 16 times, and the LCS references' evaluations, one LP each, would outrun
#: them)
MOST_STRATA = 32768


def strata(profile: str | None = None) -> int:
    """The time design's count at ``profile`` (default: the active one, or what ``budgets(time=...)`` set):
    ``STRATA_PER_POINT · search["time"]``, at most :data:`MOST_STRATA`."""
    return min(STRATA_PER_POINT * budget("time", profile), MOST_STRATA)


def promised_resolution(count: int) -> float:
    """The largest gap of a design of ``count`` strata, as a fraction of the interval."""
    return (1.0 + JITTER) / max(int(count), 1)


def time_design(lo: float, hi: float, count: int | None = None, seed: int = 0) -> np.ndarray:
    """``lo``, ``hi`` and one point in each of ``count`` (default :func:`strata`) equal strata of
    ``[lo, hi]``, jittered (seeded: the same points for the same profile and seed, on every machine)."""
    count = strata() if count is None else int(count)
    rng = np.random.default_rng([int(seed) % (2 ** 63), count, 0x71AE])
    k = np.arange(count)
    u = (k + 0.5 + JITTER * (rng.random(count) - 0.5)) / count
    return np.r_[lo, lo + (hi - lo) * u, hi]


def search_time(values: Callable[[float, Sequence[int] | None], np.ndarray], lo: float, hi: float, *,
                design: Sequence[float] = (), seed: int = 0, count: int | None = None,
                bounds: Callable[[int], tuple[float, float]] | None = None, rank: Sequence[float] | None = None,
                families: int = 1, nodes: int | None = None, per_node: int | None = None,
                golden: bool = False) -> Sup:
    """The sup over ``t ∈ [lo, hi]`` and the families of ``values(t, which)`` (an array over the families
    ``which``; ``None``: all of them) on the law's own ``design`` (sample times, times just after a jump)
    and :func:`time_design` (``count`` strata), refined at the worst windows by
    :func:`verimono.checks.engine.supremum.maximise`.  ``families``: how many families the coverage
    follows (the largest at the law's design; a law whose every family costs one batched call passes
    all of them)."""
    count = strata() if count is None else int(count)
    lo, hi = float(lo), float(hi)
    cover = time_design(lo, hi, count, seed)
    own = np.asarray([d for d in design if lo <= d <= hi], dtype=float)
    if own.size == 0:
        own = np.array([lo, hi])
    refine = max(LOCAL_MIN_POINTS, count // REFINE_PER)       # DIRECT's evaluations, and the local phase's
    points = len(own) + len(cover) + 2 * refine
    more = {} if nodes is None else {"nodes": nodes}
    if per_node is not None:
        more["per_node"] = per_node
    seen: list[float] = []
    held = [True]

    def covered() -> dict:
        return {"t": reached(seen, lo, hi, count)}

    def tracked(t: float, which):
        v = values(t, which)
        seen.append(float(t))
        held[0] = held[0] and not np.any(np.asarray(v, dtype=float) > 1.0)     # every ratio's bound is 1
        # to the unit's budget: a subject slow at every call is no hang, and a search it stops is undecided with
        # the resolution it had reached (the record's details["searched"])
        note_progress(len(seen), held[0], "times", searched=covered)
        return v

    form = getattr(values, "many", None)
    if form is not None:     # the law's vectorised form over a list of times: the coverage in blocks
        def many(ts: np.ndarray, which) -> np.ndarray:
            out = []
            for a in range(0, len(ts), MANY_BLOCK):
                block = ts[a:a + MANY_BLOCK]
                try:
                    v = np.asarray(form(block, which), dtype=float).reshape(len(block), len(which))
                except UnverifiedSolution:      # verimono's own solver: the engine takes these times one by one
                    v = np.full((len(block), len(which)), np.nan)
                seen.extend(block.tolist())
                with np.errstate(invalid="ignore"):
                    held[0] = held[0] and not np.any(v > 1.0)
                note_progress(len(seen), held[0], "times", searched=covered)
                out.append(v)
            return np.vstack(out)
        many.bound = getattr(form, "bound", 1.0)     # type: ignore[attr-defined]
        many.own = getattr(form, "own", False)       # type: ignore[attr-defined]
        tracked.many = many                          # type: ignore[attr-defined]

    return maximise(tracked, Space("t", lo, hi), design=own, cover=cover, points=points, seed=seed, bounds=bounds,
                    rank=rank, families=families, refine=golden, direct_points=refine, **more)


def reached(seen: Sequence[float], lo: float, hi: float, count: int) -> dict:
    """What a search (stopped short by the unit's budget, say) had covered of ``[lo, hi]``: the times evaluated and the largest gap between
    them, the interval's ends included (``resolution_reached``; ``hi − lo`` when none was), against the
    resolution the full design promises."""
    pts = np.unique(np.clip(np.asarray(seen, dtype=float), lo, hi))
    gaps = np.diff(np.r_[lo, pts, hi])
    return {"points": int(pts.size), "resolution_reached": float(gaps.max()) if gaps.size else float(hi - lo),
            "promised_resolution": promised_resolution(count) * (hi - lo), "strata": int(count), "range": [lo, hi]}


def searched_t(sup: Sup, count: int | None = None) -> dict:
    """The record's ``searched["t"]``: what :func:`search_time` evaluated, with the design's count and the
    resolution it promises (the largest gap reached is ``resolution``)."""
    count = strata() if count is None else int(count)
    space = sup.searched.space
    return {**sup.searched.as_dict(), "design": "stratified, jittered, both ends", "strata": count,
            "promised_resolution": promised_resolution(count) * (space.hi - space.lo)}


__all__ = ["time_design", "search_time", "searched_t", "reached", "promised_resolution", "strata", "JITTER", "STRATA_PER_POINT", "MOST_STRATA"]
