"""The one search of every "for all": the largest violation ratio over a low-dimensional space, and what was
searched to find it.

The paper's hypotheses and laws are quantified over every ``t ∈ [0, T]``, every step ``λ ∈ (0, Λ)``, every
point ``x``.  A fixed design (seven sample times, three step sizes) is blind between its points, so every law
whose statement is such a supremum maximises its ratio here instead, over a one-dimensional :class:`Space`
(a time, a step size or a distance, linear or logarithmic), in four phases:

1. **design**: the law's own points (its sample times, the times just after the jumps it found, ...) with
   every *family* (a sample point, a step size: whatever the ratio also depends on); the families are
   ranked by their largest value there and the :data:`FAMILIES` largest are searched on;
2. **coverage**: a uniform grid of the space with a seeded offset, so that every interval of the space
   wider than the grid's spacing holds an evaluated point (a violation on such an interval is seen);
3. **global**: ``scipy.optimize.direct`` (DIRECT, Jones et al.) on the largest family value, which divides
   the space where the values are largest;
4. **local**: a bounded Brent maximisation (``scipy.optimize.minimize_scalar``) between the neighbours of
   the :data:`NODES` largest points found, for their :data:`PER_NODE` largest families; with
   ``refine=True`` a golden-section search then narrows the maximiser down to adjacent floats (a ratio
   that touches its bound at one point is ``O(|t − t*|)`` there).

The budget is a number of points of the space (:func:`budget`, per profile: ``ci`` modest, ``thorough`` large);
everything is deterministic for a given seed.  The result (:class:`Sup`) never falls below the design's
largest value, and says what was searched (:class:`Searched`): the space, the number of evaluations, the
**resolution** (the largest gap between evaluated points: a violation on an interval wider than it contains
an evaluated point) and the finest bracket the local search reached.  A violation narrower than the
resolution is *outside what was searched*: the records say so instead of passing it silently.

:func:`zoom` and :func:`unbounded` search for a singularity: the largest value of ``f`` on ever shorter
brackets around its maximiser, and whether it still grows there (``v = −1/|t − τ|``) or has settled (a
narrow bounded spike).
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import math
from typing import Callable, Iterator, Sequence

import numpy as np
from scipy.optimize import direct, minimize_scalar

from ...core.errors import UnverifiedSolution
from ...core.tolerances import STALL_RATIO, STALL_WINDOW, tolerance
from ...execution.config import current as current_config
from ...execution.profiles import UnknownProfile, get_profile

#: families searched in the coverage and global phases (the largest at the design points; ties broken by
#: the law's own ``rank``, e.g. the distance of a point from the domain)
FAMILIES = 1
#: largest points around which the local phase searches, and families at each
NODES = 3
PER_NODE = 2
#: shares of the budget: the coverage grid, DIRECT; the local phase gets what is left (at least
#: :data:`LOCAL_MIN` evaluations per local search)
COVER_SHARE = 0.75
DIRECT_SHARE = 0.125
LOCAL_MIN = 8
#: Brent's iterations at least before a refinement to adjacent floats (``refine=True``)
REFINE_MAXITER = 40
#: Brent's absolute tolerance relative to its bracket (a ratio's maximum is flat: a relative error ``δ`` in
#: its place costs ``O(δ²)`` of its value)
XATOL = 1e-6
#: golden-section steps of the refinement (``refine=True``): from Brent's ``~1e-8`` to below one ulp
REFINE_STEPS = 80
#: a vectorised value above this fraction of its bound (or not finite) is evaluated again by the law's own
#: ``values`` (:meth:`_Evaluator.many`; as :data:`verimono.checks.engine.batches.SUSPECT` for the operator laws)
SUSPECT = 0.999
#: the default budget (points of a space per search) when the active profile is not one of verimono's
DEFAULT_BUDGET = {"time": 512, "coordinate": 27, "points": 100}

_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


#: budgets set by :func:`budgets` (innermost last), overriding the profile's
_OVERRIDE: list[dict] = []


def budget(kind: str, profile: str | None = None) -> int:
    """Points of a space one search evaluates at ``profile`` (default: the run configuration's, or what
    :func:`budgets` set): ``kind`` is ``"time"`` (a sup over ``t`` of a problem's hypothesis),
    ``"coordinate"`` (a step size, a time or a distance of an operator law's sample) or ``"points"`` (a point
    search in ``R^n``)."""
    if profile is None:
        for o in reversed(_OVERRIDE):
            if kind in o:
                return int(o[kind])
    name = current_config().profile if profile is None else profile
    try:
        return int(get_profile(name).search[kind])
    except UnknownProfile:
        return DEFAULT_BUDGET[kind]


@contextlib.contextmanager
def budgets(**kinds: int) -> Iterator[None]:
    """Within the block, searches of the given kinds evaluate that many points (``budgets(coordinate=729)``:
    a thorough search of one law without the thorough profile's other efforts)."""
    for k, v in kinds.items():
        if k not in DEFAULT_BUDGET or int(v) < 1:
            raise ValueError(f"budgets: {k}={v!r}; kinds are {sorted(DEFAULT_BUDGET)}, each a positive count")
    _OVERRIDE.append({k: int(v) for k, v in kinds.items()})
    try:
        yield
    finally:
        _OVERRIDE.pop()


@dataclasses.dataclass(frozen=True)
class Space:
    """A one-dimensional space searched: ``name`` in ``[lo, hi]``, uniform in ``log10`` when ``log``."""

    name: str
    lo: float
    hi: float
    log: bool = False

    def __post_init__(self) -> None:
        if not (math.isfinite(self.lo) and math.isfinite(self.hi) and self.lo < self.hi) or (self.log and self.lo <= 0):
            raise ValueError(f"a space needs finite lo < hi (lo > 0 on a log scale), got [{self.lo}, {self.hi}]")

    def value(self, u: float) -> float:
        """The point at ``u ∈ [0, 1]``."""
        u = min(max(float(u), 0.0), 1.0)
        if self.log:
            return float(10.0 ** (math.log10(self.lo) + u * (math.log10(self.hi) - math.log10(self.lo))))
        return float(self.lo + u * (self.hi - self.lo))

    def unit(self, x: float) -> float:
        """``u ∈ [0, 1]`` of the point ``x``."""
        if self.log:
            lo10, span = self._log_ends
            return (math.log10(x) - lo10) / span
        return (float(x) - self.lo) / (self.hi - self.lo)

    @functools.cached_property
    def _log_ends(self) -> tuple[float, float]:
        """``(log10 lo, log10 hi - log10 lo)``, the numbers :meth:`unit` reads at every point (a design notes
        thousands), computed once: the same operations, the same bits."""
        lo10 = math.log10(self.lo)
        return lo10, math.log10(self.hi) - lo10

    def width(self, du: float) -> float:
        """A gap ``du`` of the unit interval in the space's units: a length, or a factor on a log scale."""
        if self.log:
            return float(10.0 ** (du * (math.log10(self.hi) - math.log10(self.lo))))
        return float(du * (self.hi - self.lo))

    def describe(self, resolution: float) -> str:
        if self.log:
            return f"{self.name} ∈ [{self.lo:.3g}, {self.hi:.3g}] to within a factor {resolution:.4g}"
        return f"{self.name} ∈ [{self.lo:.6g}, {self.hi:.6g}] at resolution {resolution:.3g}"


@dataclasses.dataclass
class Searched:
    """What one search evaluated: ``points`` of the space (``evaluations`` family values), the
    ``resolution`` (largest gap between evaluated points, in the space's units: a length, or a factor on a
    log scale) and the ``finest`` bracket of the local search around the maximiser."""

    space: Space
    points: int
    evaluations: int
    resolution: float
    finest: float
    methods: tuple = ("design", "coverage", "direct", "brent")
    #: families covered by the coverage and DIRECT phases, of how many
    families: tuple = (1, 1)

    def as_dict(self) -> dict:
        return {"space": self.space.name, "range": [self.space.lo, self.space.hi], "log": self.space.log,
                "points": self.points, "evaluations": self.evaluations, "resolution": self.resolution,
                "finest": self.finest, "methods": list(self.methods), "families": list(self.families)}

    def describe(self) -> str:
        return f"{self.space.describe(self.resolution)} ({self.points} points)"

    def outside(self) -> str:
        """The sentence a passed record carries: what the search cannot have seen."""
        what = (f"a factor {self.resolution:.4g}" if self.space.log else f"{self.resolution:.3g}")
        return f"a violation confined to an interval of {self.space.name} narrower than {what} is outside what was searched"


@dataclasses.dataclass
class Sup:
    """The largest value found (``value`` at ``at``, family ``family``), the design's largest (``grid_value``
    at ``grid_at``), the local searches and what was searched."""

    value: float
    at: float
    family: int
    grid_value: float
    grid_at: float
    searched: Searched
    local: list
    harness_limited: int = 0

    # the names of the sup over time (verimono.checks.over_time)
    @property
    def t(self) -> float:
        return self.at

    @property
    def grid_t(self) -> float:
        return self.grid_at

    @property
    def evaluations(self) -> int:
        return self.searched.evaluations

    @property
    def nodes(self) -> int:
        return self.searched.points

    def as_dict(self) -> dict:
        return {"sup": self.value, "at": self.at, "t": self.at, "family": self.family, "grid_sup": self.grid_value,
                "grid_t": self.grid_at, "evaluations": self.searched.evaluations, "grid_nodes": self.searched.points,
                "local_searches": self.local, "harness_limited": self.harness_limited,
                "searched": self.searched.as_dict()}


def _finite(v) -> np.ndarray:
    """A NaN ratio counts as the largest (a NaN never passes)."""
    v = np.asarray(v, dtype=float)
    return np.where(np.isnan(v), np.inf, v)


def _offset(seed: int) -> float:
    """A seeded offset in ``[0, 1)`` of the coverage grid (the golden-ratio sequence: deterministic per seed)."""
    return float((0.5 + (int(seed) % 100003) * _GOLDEN) % 1.0)


class _Evaluator:
    """Evaluations of ``values(x, which)`` with their bookkeeping: the best value, the points evaluated, the
    evaluations an unverified solve of verimono's own made inconclusive."""

    def __init__(self, values: Callable, space: Space) -> None:
        self.values, self.space = values, space
        self.best = {"value": -np.inf, "at": space.lo, "family": 0}
        self.us: list[float] = []
        self.evaluations = 0
        self.limited = 0
        #: points whose values came from the law's vectorised form (:meth:`many`)
        self.vectorised = 0

    def note(self, x: float, vals: np.ndarray, which: Sequence[int]) -> None:
        self.us.append(self.space.unit(x))
        self.evaluations += len(which)
        if vals.size:
            i = int(np.argmax(vals))
            if vals[i] > self.best["value"]:
                self.best.update(value=float(vals[i]), at=float(x), family=int(which[i]))

    def some(self, x: float, which: Sequence[int]) -> np.ndarray:
        """The values of the families ``which`` at ``x`` (``-inf`` where verimono's solver is unverified)."""
        vals = self._some(x, which)
        self.note(x, vals, which)
        return vals

    def _some(self, x: float, which: Sequence[int]) -> np.ndarray:
        """:meth:`some`'s values, not noted."""
        try:
            vals = _finite(self.values(x, list(which)))
            if vals.size != len(which) and vals.size > max(which):     # a values() that returned every family
                vals = vals[list(which)]
        except UnverifiedSolution:
            vals = np.empty(len(which))
            for k, f in enumerate(which):
                try:
                    vals[k] = float(_finite(self.values(x, [f]))[0])
                except UnverifiedSolution:      # verimono's own solver, not the subject: no evidence here
                    self.limited += 1
                    vals[k] = -np.inf
        return vals

    def table(self, xs: np.ndarray, table: np.ndarray, which: Sequence[int] | None = None) -> None:
        """:meth:`note` of every row of ``table`` (the values of the families ``which`` — every family when
        ``None`` — at ``xs``, known before: a design the caller evaluated as one list), in one pass: the same
        points, counts and best as noting row by row (the first largest value, in the order of the rows)."""
        unit = self.space.unit
        self.us += [unit(x) for x in xs.tolist()]
        self.evaluations += table.size
        if table.size:
            i = int(np.argmax(table))
            if table.flat[i] > self.best["value"]:
                k = i % table.shape[1]
                self.best.update(value=float(table.flat[i]), at=float(xs[i // table.shape[1]]),
                                 family=k if which is None else int(which[k]))

    def many(self, xs: np.ndarray, which: Sequence[int], form: Callable) -> np.ndarray:
        """The values of the families ``which`` at every point of ``xs`` (a list known in advance: the coverage),
        from the law's vectorised form ``form(xs, which) -> (len(xs), len(which))`` where it is accepted, noted
        in order as :meth:`some` notes them (the same points, counts and best).  A vectorised value is accepted
        only when it is ``-inf`` (the family undefined there) or finite and at most :data:`SUSPECT` times the
        form's ``bound`` (its attribute; default 1: every ratio's bound), a margin far beyond the rounding of
        a sum reduced in another order; a row with any other value (NaN, ``inf``, near or above the bound: what
        decides a failure) is evaluated again by the law's own ``values``, through :meth:`some`'s path.  A form
        that states ``own = True`` is the law's own ``values`` at each point (a loop without the engine's
        bookkeeping per point): its values are the law's, only a NaN row (a block it could not evaluate) is
        evaluated again."""
        which = list(which)
        bound = float(getattr(form, "bound", 1.0))
        table = np.asarray(form(xs, which), dtype=float).reshape(len(xs), len(which))
        with np.errstate(invalid="ignore"):
            if getattr(form, "own", False):     # the law's own values at each point, in a loop: nothing to redo
                fine = ~np.isnan(table)         # (NaN: a block the form could not evaluate)
            else:
                fine = (table == -np.inf) | (np.isfinite(table) & (table <= SUSPECT * bound))
        redo = ~fine.all(axis=1)
        self.vectorised += int((~redo).sum())
        out = table.copy()
        for k in np.flatnonzero(redo).tolist():
            out[k] = self._some(float(xs[k]), which)
        self.table(xs, out, which)
        return out

    def every(self, x: float) -> np.ndarray | None:
        """Every family's value at ``x`` (``None`` when an unverified solve prevents the whole row)."""
        try:
            vals = _finite(self.values(x, None))
        except UnverifiedSolution:
            return None
        self.note(x, vals, range(vals.size))
        return vals


def maximise(values: Callable[[float, Sequence[int] | None], np.ndarray], space: Space, *,
             design: Sequence[float] | None = None, points: int | None = None, kind: str = "time",
             families: int = FAMILIES, nodes: int = NODES, per_node: int = PER_NODE, refine: bool = False,
             seed: int = 0, bounds: Callable[[int], tuple[float, float]] | None = None,
             global_search: bool = True, rank: Sequence[float] | None = None,
             cover: Sequence[float] | None = None, direct_points: int | None = None) -> Sup:
    """The sup over ``x ∈ space`` and the families of ``values(x, which)`` — an array over the families
    ``which`` (``None``: all of them in a fixed order; ``-inf`` where a family is not defined at ``x``) — by
    the four phases of the module docstring, with ``points`` points of the space (default :func:`budget` of
    ``kind``).  ``design``: the law's own points (default: 17 equally spaced ones); ``bounds(f)`` restricts
    family ``f`` to a sub-interval; ``global_search=False`` skips the coverage and DIRECT phases (a design
    that is already dense); ``rank`` (one number per family) orders families whose largest design values
    tie, largest first.  ``cover``: the coverage phase's points (:mod:`.times`' stratified, jittered design of a
    time search) instead of the uniform grid with a seeded offset; ``direct_points``: DIRECT's evaluations
    (default: a share of ``points``)."""
    points = budget(kind) if points is None else int(points)
    ev = _Evaluator(values, space)
    xs = np.linspace(space.lo, space.hi, 17) if design is None else np.asarray(design, dtype=float)
    xs = np.unique(np.clip(xs[np.isfinite(xs)], space.lo, space.hi))
    known = getattr(values, "table", None)      # the design's values, evaluated before as one list
    table = known(xs) if known is not None and xs.size else None
    if table is not None:
        table = _finite(table)
        ev.table(xs, table)
        width = table.shape[1]
    else:
        rows = [ev.every(float(x)) for x in xs]
        width = next((r.size for r in rows if r is not None), None)
        if width is None:
            raise UnverifiedSolution(f"no point of the design could be evaluated ({len(xs)} tried)")
        table = np.array([r if r is not None else ev.some(float(x), range(width)) for r, x in zip(rows, xs)])
    if table.ndim != 2 or table.shape[1] == 0:
        raise ValueError("values(x, None) must return a nonempty 1-D array (one value per family)")
    grid_value, grid_at = ev.best["value"], ev.best["at"]
    second = np.zeros(width) if rank is None else np.asarray(rank, dtype=float)
    ranked = [int(f) for f in np.lexsort((-second, -table.max(axis=0)))]
    chosen = ranked[:max(1, families)]
    everyone = list(range(width))
    found: list[tuple] = [(x, m, r, everyone) for x, m, r in zip(xs.tolist(), table.max(axis=1).tolist(), table)]

    def lim(f: int) -> tuple[float, float]:
        return (space.lo, space.hi) if bounds is None else bounds(f)

    if global_search:
        if cover is None:
            count = max(0, int(points * COVER_SHARE) - len(xs))
            off = _offset(seed)
            cover = [space.value((i + off) / count) for i in range(count)]
        many = getattr(values, "many", None)     # the law's vectorised form over a list of points
        if many is not None and len(cover):
            xc = np.asarray(cover, dtype=float)
            for x, r in zip(xc.tolist(), ev.many(xc, chosen, many)):
                found.append((x, float(r.max()), r, chosen))
        else:
            for x in cover:
                r = ev.some(float(x), chosen)
                found.append((float(x), float(r.max()), r, chosen))
        maxfun = int(points * DIRECT_SHARE) if direct_points is None else int(direct_points)
        if maxfun >= 3:
            def neg(u: np.ndarray) -> float:
                x = space.value(float(u[0]))
                r = ev.some(x, chosen)
                found.append((x, float(r.max()), r, chosen))
                m = float(r.max())
                return -m if math.isfinite(m) else (-1e300 if m > 0 else 1e300)

            direct(neg, [(0.0, 1.0)], maxfun=maxfun, maxiter=10 * maxfun, locally_biased=False, eps=1e-4,
                   vol_tol=0.0, len_tol=0.0)
    # the local phase: brackets between the neighbours of the largest points found
    found.sort(key=lambda e: (e[0], -e[1]))
    found = [e for k, e in enumerate(found) if k == 0 or e[0] != found[k - 1][0]]     # one entry per point
    at = np.array([e[0] for e in found])
    score = np.array([e[1] for e in found])
    local, finest = [], space.width(1.0) if not space.log else space.hi / space.lo
    left = max(points - len(ev.us), 0)
    maxiter = max(REFINE_MAXITER if refine else LOCAL_MIN, left // max(1, nodes * per_node))
    picked: list[int] = []
    for i in np.argsort(-score, kind="stable"):
        if len(picked) >= nodes or not score[i] > -np.inf:
            break
        if any(abs(int(i) - j) <= 1 for j in picked):       # a neighbour of a node already searched: same peak
            continue
        picked.append(int(i))
        a, b = float(at[max(i - 1, 0)]), float(at[min(i + 1, len(at) - 1)])
        row, fams = found[i][2], found[i][3]
        for k in np.argsort(-row, kind="stable")[:per_node]:
            f = int(fams[int(k)])
            if not row[int(k)] > -np.inf:
                continue
            fa, fb = lim(f)
            a2, b2 = max(a, fa), min(b, fb)
            if not a2 < b2:
                continue

            def neg1(x: float, _f: int = f) -> float:
                v = float(ev.some(float(x), [_f])[0])
                return -v if math.isfinite(v) else (-1e300 if v > 0 else 1e300)

            ua, ub = space.unit(a2), space.unit(b2)
            if space.log:     # Brent on the unit scale of a logarithmic space
                res = minimize_scalar(lambda u: neg1(space.value(u)), bounds=(ua, ub), method="bounded",
                                      options={"xatol": XATOL * (ub - ua), "maxiter": maxiter})
                x = space.value(float(res.x))
                width_reached = space.width(XATOL * (ub - ua))
            else:
                res = minimize_scalar(neg1, bounds=(a2, b2), method="bounded",
                                      options={"xatol": XATOL * (b2 - a2), "maxiter": maxiter})
                x = float(res.x)
                width_reached = XATOL * (b2 - a2)
                if refine:
                    h = 64 * (XATOL * (b2 - a2) + 1.5e-8 * abs(x))
                    x = _golden(neg1, max(a2, x - h), min(b2, x + h))
                    width_reached = max(abs(x) * 2.0 ** -52, 5e-324)
            finest = min(finest, width_reached)
            local.append({"node": float(at[i]), "family": f, "bracket": [a2, b2], "argmax": x, "value": -neg1(x)})
    us = np.sort(np.array(ev.us + [0.0, 1.0]))
    gap = float(np.max(np.diff(us))) if us.size > 1 else 1.0
    if not global_search:       # the design alone: its own largest gap
        gap = float(np.max(np.diff(np.sort(np.r_[0.0, [space.unit(x) for x in xs], 1.0]))))
    methods = ("design",) + (("coverage", "direct") if global_search else ()) + ("brent",) + (("golden",) if refine else ())
    searched = Searched(space, len(ev.us), ev.evaluations, space.width(gap), finest, methods, (len(chosen), width))
    b = ev.best
    return Sup(b["value"], b["at"], b["family"], grid_value, grid_at, searched, local, ev.limited)


def _golden(neg: Callable[[float], float], a: float, b: float, steps: int = REFINE_STEPS) -> float:
    """Golden-section minimisation of ``neg`` on ``[a, b]`` down to adjacent floats (or ``steps`` steps)."""
    c, d = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
    fc, fd = neg(c), neg(d)
    for _ in range(steps):
        if not (a < c < d < b):
            break
        if fc <= fd:
            b, d, fd = d, c, fc
            c = b - _GOLDEN * (b - a)
            fc = neg(c)
        else:
            a, c, fc = c, d, fd
            d = a + _GOLDEN * (b - a)
            fd = neg(d)
    return c if fc <= fd else d


# -- singularities ------------------------------------------------------------------------------------

#: probes per level of the zoom toward a singularity, and the levels at most (each halves the bracket:
#: from T/1000, 64 levels reach adjacent floats)
ZOOM_PROBES = 5
ZOOM_LEVELS = 64


@dataclasses.dataclass
class Zoom:
    """The zoom toward the largest value of ``f``: per level the bracket width and the largest value so
    far, the final point."""

    widths: list
    values: list
    at: float
    evaluations: int
    #: the point the bracket was centred on after each level
    points: list = dataclasses.field(default_factory=list)

    def as_dict(self) -> dict:
        return {"at": self.at, "widths": self.widths, "values": self.values, "evaluations": self.evaluations}


def zoom(f: Callable[..., float], lo: float, hi: float, at: float, width: float, *,
         probes: int = ZOOM_PROBES, levels: int = ZOOM_LEVELS, scaled: bool = False, shrink: float = 0.5) -> Zoom:
    """The largest value of ``f`` on brackets around ``at`` shrinking from ``width`` by ``shrink`` per level:
    at each level ``probes`` equally spaced points of the bracket (its ends included) and its centre, the
    bracket then centred on the largest (kept inside ``[lo, hi]``), until no float lies between two probes
    (or ``levels`` levels).  ``scaled=True``: ``f(x, w)`` is told the bracket's width ``w`` (a difference
    quotient whose step shrinks with it).  ``f.many(xs, w)``, when ``f`` carries it, gives a level's values at
    once (the same values as ``f`` at each probe, bit for bit; taken in the same order)."""
    call = (lambda x, w: float(f(x, w))) if scaled else (lambda x, w: float(f(x)))
    many = getattr(f, "many", None)
    best_x = float(at)
    widths, vals, count, pts = [], [], 0, []
    w = float(width)
    for _ in range(levels):
        a = min(max(best_x - w / 2, lo), hi - w) if w < hi - lo else lo
        b = min(a + w, hi)
        xs = np.r_[np.linspace(a, b, probes), best_x]
        if not np.all(np.diff(xs[:-1]) > 0):
            break
        level_best, level_x = -math.inf, best_x
        level = None if many is None else np.asarray(many(xs, w), dtype=float).tolist()
        for k, x in enumerate(xs):
            v = call(float(x), w) if level is None else level[k]
            count += 1
            if v != v:
                v = math.inf
            if v > level_best:
                level_best, level_x = v, float(x)
        best_x = level_x
        widths.append(w)
        vals.append(level_best)
        pts.append(best_x)
        if not math.isfinite(level_best):
            break
        w *= shrink
    return Zoom(widths, vals, best_x, count, pts)


def unbounded(z: Zoom, window: int = STALL_WINDOW) -> bool:
    """Whether the zoom's largest value still grows where the zoom ends: infinite, or its increase over the
    last ``window`` halvings is at least ``STALL_RATIO`` times its increase over the ``window`` before and
    above the rounding of its size (``1/|t − τ|`` doubles per halving, ``log|t − τ|`` grows by ``log 2``;
    near a bounded maximum the increase shrinks: by 4 per halving at a smooth peak, by ``√2`` at a cusp
    ``1 − √|t − τ|``)."""
    v = z.values
    if v and not math.isfinite(v[-1]):
        return True
    if len(v) < 2 * window + 1:
        return False
    last, before = v[-1] - v[-1 - window], v[-1 - window] - v[-1 - 2 * window]
    return last > tolerance(v[-1]) and last >= STALL_RATIO * before


__all__ = ["Space", "Searched", "Sup", "maximise", "budget", "budgets", "zoom", "Zoom", "unbounded", "FAMILIES", "NODES",
           "PER_NODE", "COVER_SHARE", "DIRECT_SHARE", "XATOL", "REFINE_STEPS", "ZOOM_PROBES", "ZOOM_LEVELS"]
