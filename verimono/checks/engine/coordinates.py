"""The last phase of an operator law's search: each coordinate of the worst sample searched on its own.

An operator law holds for every ``λ, μ, ν > 0``, every ``t`` and every point; the draws, hypothesis and the
scale sweep (:mod:`verimono.checks.search`) sample them, and a violation confined to a narrow band of one
coordinate — a resolvent using ``2λ`` only for ``λ ∈ [0.031, 0.036]``, a projection that forgets to project
points just outside its set — is met there by chance only.  So the search ends here: from the sample with
the largest ratio, each coordinate is maximised over its whole space with the others held
(:func:`verimono.checks.supremum.maximise`, ``coordinate`` budget of the profile) — one at a time: a
violation that needs two coordinates at once (a band of large ``λ`` that shows only at points larger than
``λ``) is outside this phase:

* ``direction`` first — the direction of ``x2 − x1`` over the sphere (:mod:`.directions`); the coordinates
  below then start from the worst direction found;
* ``lam``, and with a budget of at least :data:`MORE_FROM` ``mu``, ``nu`` — step sizes over every decade the
  precision represents (:func:`_decades`, :func:`verimono.core.tolerances.current_step_range`: float64
  ``[10^-153, 10^7]``), and ``[10^-4, Λ]`` with ``Λ = 10`` (:data:`STEPS`) at the budget's full density;
* ``t`` — ``[0, horizon]``;
* ``scale`` (with a budget of at least :data:`MORE_FROM`; the sweep's points span ``10^-9`` to ``10^6`` at
  every budget) — the points ``x1, x2`` scaled together so that ``|x1|`` runs over ``[10^-9, 10^6]``: tiny
  points (the kink ``0`` of every norm) and far ones (``|x| ≫`` the problem's scale);
* ``offset`` — ``x1`` moved to ``b + s n``, ``b = J_ν x1`` (on the boundary of the domain when ``x1`` is
  outside it), ``n`` the outer normal ``(x1 − b)/|x1 − b|``, ``s ∈ [10^-12, 10^3](1 + |b|)``, and
  ``x2 = b + 1000 s n``: a pair just outside the boundary, on one normal.

A law with a vectorised form (:mod:`.batches`) gets dense designs (:data:`DENSE_SHARE`, :data:`DENSE_SHARE_BATCHED`),
evaluated as one list (``many``), the local search of :func:`maximise` then refining around the largest value.

A coordinate whose ratio is the same to the last bit at every design point (one the law does not read,
or an identity that holds exactly there) is covered by the budget's points more (:func:`_covering`: one in
each of ``points`` equal cells, so ``thorough`` covers it 27 times as densely as ``ci``), and if still flat
there by those only (``"read": False`` in the record); the step decades get ``DECADE_SHARE`` times the budget
log-evenly once that exceeds one point a decade (``thorough``).  Samples of more than ``NUMPY_DIM`` coordinates (recorded by recipe) are searched in
``lam, mu, nu, t`` only.  What was searched is recorded: :func:`searched` of the whole search.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from ...core.tolerances import current_largest, current_step_range
from .directions import direction_search
from .blocks import SampleBlock
from .samples import Sample, with_field as _with, with_fields as _replace
from .supremum import Searched, Space, maximise

#: the step sizes searched: ``[10^-4, Λ]`` (Λ = 10: the largest step the samples draw)
STEPS = (1e-4, 10.0)
#: the range of ``|x1|`` of the scale coordinate
SCALE = (1e-9, 1e6)
#: the range of the offset from the boundary, relative to ``1 + |J_ν x1|``
OFFSET = (1e-12, 1e3)
#: coordinates searched, in order, each from the worst sample (one at a time: a violation that needs two
#: of them at once — a band of large λ that shows only at points larger than λ — is outside this phase);
#: ``mu``, ``nu`` and ``scale`` from a budget of :data:`MORE_FROM` points on (below it the draws, hypothesis and
#: the sweep — whose points span ``10^-9`` to ``10^6`` — cover them; ``λ``, ``t`` and the boundary come first)
COORDINATES = ("direction", "lam", "t", "offset", "mu", "nu", "scale")
MORE_FROM = 81
#: the decades of the step range (:func:`_decades`) get a design of ``DECADE_SHARE`` times the coordinate budget
DECADE_SHARE = 2
_MORE = ("mu", "nu", "scale")
#: a law with a vectorised form (:mod:`.batches`, whose evaluations of a list cost about one subject call each)
#: gets a design of ``DENSE_SHARE`` times the coordinate budget on the step and time coordinates (one subject call
#: per point: each has its own λ or t) and, on an operator that maps batches, ``DENSE_SHARE_BATCHED`` times on the
#: points' coordinates (``offset``, ``scale``: one λ and t, so one batched call for the whole design), at most
#: :data:`DENSE_MAX` points, spread evenly over the whole space (log-evenly on a logarithmic one) — fixed by the
#: profile and the operator's declaration, never by time
DENSE_SHARE = 2
DENSE_SHARE_BATCHED = 8
DENSE_MAX = 4096

def _norm(v: np.ndarray) -> float:
    m = float(np.max(np.abs(v), initial=0.0))
    return 0.0 if m == 0.0 or not math.isfinite(m) else m * float(np.linalg.norm(v / m))


def _moves(s: Sample, name: str, op: Any, horizon: float) -> tuple[Space, Callable[[float], Sample], list] | None:
    """The space of coordinate ``name`` of ``s``, the sample at a point of it, and design points (``None``
    when the coordinate cannot move: a recipe sample's points, ``x1 = 0``, ``x1`` inside the domain)."""
    if name in ("lam", "mu", "nu"):
        lo, hi = current_step_range()
        space = Space(name, lo, hi, log=True)
        return space, _along(s, name), [10.0 ** k for k in range(-4, 2)] + [lo, hi, getattr(s, name)]
    if name == "t":
        space = Space("t", 0.0, float(horizon))
        return space, _along(s, "t"), [0.0, horizon / 2, float(horizon), s.t]
    if s.recipe is not None:
        return None
    if name == "scale":
        r = _norm(s.x1)
        if r == 0.0:
            return None
        space = Space("|x1|", SCALE[0], min(SCALE[1], current_largest() / 64.0), log=True)
        at = lambda v: _replace(s, x1=s.x1 * (v / r), x2=s.x2 * (v / r))      # noqa: E731
        at.many = lambda vs: _rows_of(s, vs, lambda f: f[:, None] * s.x1, lambda f: f[:, None] * s.x2,
                                      (np.array(vs) / r))
        return space, at, [10.0 ** k for k in range(-9, 7, 3)] + [min(max(r, SCALE[0]), SCALE[1])]
    # offset from the boundary: x1 = b + s n
    try:
        b = np.asarray(op.resolvent(s.x1.copy(), s.nu, s.t), dtype=float)
    except Exception:       # noqa: BLE001 - the laws meet (and judge) the resolvent's exception themselves
        return None
    if b.shape != s.x1.shape or not np.all(np.isfinite(b)):
        return None
    d = _norm(s.x1 - b)
    if d == 0.0:
        return None
    n, size = (s.x1 - b) / d, 1.0 + _norm(b)
    hi = min(OFFSET[1] * size, current_largest() / 64e3)      # x2 = b + 1000 s n stays representable
    if not OFFSET[0] * size < hi:
        return None
    space = Space("offset", OFFSET[0] * size, hi, log=True)
    at = lambda v: _replace(s, x1=b + v * n, x2=b + 1e3 * v * n)      # noqa: E731
    at.many = lambda vs: _rows_of(s, vs, lambda V: b + V[:, None] * n, lambda V: b + (1e3 * V)[:, None] * n,
                                  np.array(vs))
    return space, at, [10.0 ** k * size for k in range(-12, 4, 3)]


#: points of at most this many coordinates get a design's samples as rows of one array (:func:`_rows_of`)
ROWS_OF_N = 64


def _along(s: Sample, name: str) -> Callable[[float], Sample]:
    """The sample at a value of the step or time coordinate ``name`` of ``s`` (``with_field(s, name, float(v))``),
    with ``many``: a design's samples as one :class:`~.blocks.SampleBlock` (``SampleBlock.along``; a row made from it
    is that sample, field for field)."""
    at = lambda v: _with(s, name, float(v))      # noqa: E731
    if np.size(s.x1) <= ROWS_OF_N:      # above, a list (the vectorised passes stack it in chunks of ROW_CELLS)
        at.many = lambda vs: SampleBlock.along(s, name, vs)
    return at


def _rows_of(s: Sample, vs: list, x1: Callable, x2: Callable, V: np.ndarray) -> SampleBlock | None:
    """The samples of a points' design at ``vs`` in one broadcast pass, as one :class:`~.blocks.SampleBlock`:
    ``x1(V)``, ``x2(V)`` are ``(len(vs), n)`` arrays whose row ``i`` is, element by element, the one-point lambda's
    arithmetic at ``vs[i]`` (a product and a sum of float64 numbers, the same whether one scalar or a column
    multiplies: the same numbers).  A sample made from it holds a row of its own (no two share one).  ``None``
    above :data:`ROWS_OF_N` coordinates: a kept worst sample would hold the whole design's array alive."""
    if s.x1.size > ROWS_OF_N:
        return None
    return SampleBlock.rows(s, x1(V), x2(V))


def _samples(at: Callable[[float], Sample], design: list[float]) -> Any:
    """``[at(v) for v in design]``, in one pass where ``at`` has one (:func:`_rows_of`, :func:`_along`: a
    :class:`~.blocks.SampleBlock`)."""
    many = getattr(at, "many", None)
    out = many(design) if many is not None and design else None
    return out if out is not None else [at(v) for v in design]


def coordinate_search(evaluate: Callable[[Sample], float], op: Any, start: Sample, horizon: float, points: int,
                      seed: int, stop: Callable[[], bool],
                      many: Callable[[list[Sample]], list[float]] | None = None, dense: bool = False,
                      rows: bool = False, over: tuple = COORDINATES,
                      prefetch: Callable[[list[list[Sample]]], None] | None = None) -> list[dict]:
    """Each coordinate of ``start`` maximised on its own (module docstring); ``evaluate(sample)`` returns the
    law's ratio (and raises to end the search, as on a violation); ``many(samples)`` the ratios of a list
    (default: ``evaluate`` of each; the search's evaluates a law's vectorised form over all of them at once —
    the design points of every coordinate); ``dense``: the law has a vectorised form, so every coordinate's
    design is :func:`dense_count` points of its space (``rows``: the operator maps batches, so the points'
    coordinates are denser still); ``stop()`` ends it between coordinates; ``over``: the law's declared
    quantifiers (:attr:`verimono.checks.core.Law.over`) — a coordinate it does not declare is not searched.
    ``prefetch(lists)`` (with ``dense``): told the designs of every coordinate after the direction before the
    first is evaluated (they all start from the same sample), so that ``many`` evaluates them in one pass; each is
    still searched in its turn, its design then its local search, as without it.
    Returns what each coordinate's search covered."""
    if many is None:
        many = lambda ss: [evaluate(s) for s in ss]     # noqa: E731
    done, here = [], start
    best: list = [-math.inf, start]          # the largest ratio the direction search met, and its sample

    def ev(s: Sample) -> float:
        v = evaluate(s)
        if v > best[0]:
            best[:] = [v, s]
        return v

    def evs(ss: list[Sample]) -> list[float]:
        vals = many(ss)
        for s, v in zip(ss, vals):
            if v > best[0]:
                best[:] = [v, s]
        return vals

    def plan(name: str) -> tuple | None:
        """The coordinate's space, its sample at a point, its design and samples, and the step decades' (``None``:
        it cannot move)."""
        moved = _moves(here, name, op, horizon)
        if moved is None:
            return None
        space, at, design = moved
        decades = None
        if name in ("lam", "mu", "nu"):
            d_design, stride = _decade_design(space, points, dense)
            decades = (space, d_design, stride, _samples(at, d_design))
            space = Space(name, *STEPS, log=True)       # the steps the samples are drawn from, at full density
        if dense:
            design = design + _even(space, dense_count(points, name, rows))
        design = [float(min(max(v, space.lo), space.hi)) for v in design]
        return space, at, design, _samples(at, design), decades

    names = [c for c in COORDINATES if c in over and not (c in _MORE and points < MORE_FROM)]
    plans: dict = {}
    for name in names:
        if stop():
            break
        if name == "direction":        # not one-dimensional: the sphere of directions of x2 - x1
            got = direction_search(ev, op, start, points, seed, evs)
            if got is not None:
                done.append(got)
            here = best[1]             # the other coordinates from the worst direction (or the worst sample)
            continue
        if dense and prefetch is not None and not plans:     # every design from ``here``, known now: one pass
            plans = {c: plan(c) for c in names if c != "direction"}
            prefetch([ss for p in plans.values() if p is not None
                      for ss in ((p[4][3], p[3]) if p[4] is not None else (p[3],))])
        planned = plans[name] if name in plans else plan(name)
        if planned is None:
            continue
        space, at, design, samples, decades = planned
        if decades is not None:
            d_space, d_design, stride, d_samples = decades
            done.append(_decades(evaluate, d_space, at, points, seed, name, many, dense,
                                 planned=(d_design, stride, d_samples)))
        first = many(samples)
        if len(set(first)) <= 1 and not dense:     # flat at the design: covered by the budget's points
            more = [v for v in _covering(space, points, seed) if v not in set(design)]
            design, first = design + more, first + many([at(v) for v in more])
        if len(set(first)) <= 1:     # flat to the last bit: a coordinate the law does not read
            done.append({"coordinate": name, "points": len(design), "read": False,
                         "range": [space.lo, space.hi], "log": space.log})
            continue
        sup = maximise(_cached(evaluate, at, design, first), space, design=design, points=points,
                       seed=seed, nodes=1, per_node=1, global_search=not dense)     # a dense design covers it
        done.append({"coordinate": name, "read": True, **_brief(sup.searched)})
    return done


def _decade_design(space: Space, points: int, dense: bool) -> tuple[list[float], float]:
    """The design of :func:`_decades` over ``space`` and its stride (decades between design points)."""
    lo, hi = math.ceil(math.log10(space.lo)), math.floor(math.log10(space.hi))
    stride: float = max(1, math.ceil((hi - lo) / (DECADE_SHARE * max(1, points))))
    design = [10.0 ** k for k in range(lo, hi + 1, int(stride))] + [space.hi]
    if dense or DECADE_SHARE * points > hi - lo:   # a vectorised law, or a budget beyond one point a decade
        # (thorough): DECADE_SHARE x the budget (x DENSE_SHARE when vectorised), log-evenly over every decade
        extra = _even(space, min(DENSE_MAX, DECADE_SHARE * (dense_count(points) if dense else points)))
        stride = min(float(stride), (math.log10(space.hi) - math.log10(space.lo)) / max(1, len(extra) - 1))
        design = sorted(set(design + extra))
    return design, stride


def _decades(evaluate: Callable[[Sample], float], space: Space, at: Callable[[float], Sample], points: int,
             seed: int, name: str, many: Callable[[list[Sample]], list[float]] | None = None,
             dense: bool = False, planned: tuple | None = None) -> dict:
    """The step coordinate ``name`` over every decade the precision represents (``space``,
    :func:`verimono.core.tolerances.current_step_range`): a design of every ``stride``-th decade, ``stride`` the
    smallest that ``DECADE_SHARE · points`` evaluations pay (ci: every 3rd decade of float64's 160, dev every 6th,
    thorough every one), then, unless the ratio is the same at every design point (a law that does not read the
    step: ``"read": False``), the local search of :func:`maximise` around the largest design values (the design
    is the coverage: its stride is the resolution promised).  ``planned``: the design, its stride and its samples,
    made before (:func:`_decade_design`)."""
    design, stride, samples = planned if planned is not None else (*_decade_design(space, points, dense), None)
    if samples is None:
        samples = [at(v) for v in design]
    first = many(samples) if many is not None else [evaluate(s) for s in samples]
    if len(set(first)) <= 1:
        return {"coordinate": f"{name} decades", "read": False, "stride": stride, "points": len(design),
                "range": [space.lo, space.hi], "log": True}
    sup = maximise(_cached(evaluate, at, design, first), space, design=design, points=points,
                   seed=seed, nodes=1, per_node=1, global_search=False)
    return {"coordinate": f"{name} decades", "read": True, "stride": stride, **_brief(sup.searched)}


def dense_count(points: int, name: str = "lam", rows: bool = False) -> int:
    """Design points of coordinate ``name`` of a law with a vectorised form at a coordinate budget of ``points``
    (``rows``: on an operator that maps batches)."""
    share = DENSE_SHARE_BATCHED if rows and name in ("offset", "scale") else DENSE_SHARE
    return min(DENSE_MAX, share * max(1, int(points)))


def _covering(space: Space, count: int, seed: int) -> list[float]:
    """``count`` points of ``space``, one in each of ``count`` equal cells (log-equal on a logarithmic space) at a
    seeded offset: the coverage of a coordinate flat at its design (the same points at a seed on every machine)."""
    off = float(np.random.default_rng([int(seed) % (2 ** 63), 0xC0FE]).uniform(0.05, 0.95))
    return [space.value((i + off) / count) for i in range(max(0, int(count)))]


def _even(space: Space, count: int) -> list[float]:
    """``count`` points evenly spread over ``space`` (log-evenly on a logarithmic one), both ends included."""
    if space.log:
        return [float(v) for v in np.logspace(math.log10(space.lo), math.log10(space.hi), count)]
    return [float(v) for v in np.linspace(space.lo, space.hi, count)]


def _cached(evaluate: Callable[[Sample], float], at: Callable[[float], Sample], design: list[float],
            first: list[float]) -> Callable:
    """The values callback of :func:`maximise`: the design's ratios already evaluated (by ``many``) are taken
    as they are, every other point evaluated."""
    known = dict(zip(design, first))

    def values(v: float, which) -> np.ndarray:
        v = float(v)
        return np.array([known[v] if v in known else evaluate(at(v))])

    def table(xs: np.ndarray) -> np.ndarray | None:
        """The values at ``xs`` (one family) when every one is known (:func:`maximise`'s design), else ``None``."""
        try:
            return np.array([known[v] for v in xs.tolist()], dtype=float).reshape(-1, 1)
        except KeyError:
            return None
    values.table = table        # type: ignore[attr-defined]
    return values


def _brief(s: Searched) -> dict:
    return {"range": [s.space.lo, s.space.hi], "log": s.space.log, "points": s.points, "resolution": s.resolution}


def searched(xs: list[float], lams: list[float], ts: list[float], horizon: float, coordinates: list[dict],
             rows: tuple | None = None) -> dict:
    """What an operator law's search evaluated: the range of ``|x|``, of the step sizes, the largest gap
    between its times in ``[0, horizon]``, and the coordinate searches.  ``rows``: more of the same as arrays
    ``(|x|, λ, t)`` (the rows of the vectorised passes), taken with the lists."""
    if rows is not None:
        rx, rl, rt = rows
        if rt.size:
            x_lo, x_hi, l_lo, l_hi = float(rx.min()), float(rx.max()), float(rl.min()), float(rl.max())
            if xs:
                x_lo, x_hi, l_lo, l_hi = (min(min(xs), x_lo), max(max(xs), x_hi), min(min(lams), l_lo),
                                          max(max(lams), l_hi))
            return _searched(ts, horizon, coordinates, [x_lo, x_hi], [l_lo, l_hi], rt)
    if not xs:
        return {"samples": 0}
    return _searched(ts, horizon, coordinates, [float(min(xs)), float(max(xs))], [float(min(lams)), float(max(lams))])


def _searched(ts: list[float], horizon: float, coordinates: list[dict], x_range: list, lambda_range: list,
              more_ts: np.ndarray | None = None) -> dict:
    # np.unique(np.r_[0.0, np.clip(ts, 0.0, horizon), horizon])'s largest gap without np.r_, the list's own clip and
    # the unique: the sorted times with their repeats have the same gaps and zeros (the largest gap is >= 0, NaN
    # sorted last as unique sorts it), and more than one distinct time exactly when the first and last differ
    extra = 0 if more_ts is None else more_ts.size
    tt = np.empty(len(ts) + extra + 2)
    tt[0], tt[-1] = 0.0, horizon
    inner = tt[1:-1]
    inner[:len(ts)] = ts
    if extra:
        inner[len(ts):] = more_ts
    np.clip(inner, 0.0, horizon, out=inner)
    tt.sort()
    return {"samples": len(ts) + extra, "x_range": x_range, "lambda_range": lambda_range,
            "t_resolution": float(np.diff(tt).max()) if tt[-1] != tt[0] else float(horizon),
            "coordinates": coordinates}


__all__ = ["coordinate_search", "searched", "COORDINATES", "MORE_FROM", "STEPS", "SCALE", "OFFSET"]
