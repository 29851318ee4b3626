"""The scale sweep: seeded samples at every scale, evaluated after the draws and edge samples of each law
(:func:`law_draws`, :func:`edge_draws`: NumPy's versions of what hypothesis's generate phase drew).

Hypothesis draws points of moderate size and climbs toward large ratios; a bug confined to a thin region
(a prox that crashes or takes a wrong branch only for ``|x| < 10^-6``, or only on the boundary of its
domain) is then found at some seeds only.  The sweep evaluates every law, after its search, on
``count`` samples drawn from ``numpy.random.default_rng(seed)`` (the record's seed, so the same seed gives
the same samples): ``x1`` at each scale of :data:`SCALES` in turn (from ``10^-9`` to ``10^6``, below 1/64 of
the largest number of the precision the subject is judged at; every
third one with a single nonzero coordinate, the boundary of orthants, boxes and ℓ1 balls, but every other far one in a
general direction, :func:`far_general`), ``x2`` near
``x1`` or at another scale, and every fourth sample (not those far general ones) replaced by ``J_ν x`` and ``J_ν(J_ν x)`` — points in
the range of the resolvent, i.e. on the boundary of ``dom F`` for a normal cone; and every fourth (from the
first such boundary point on) by a pair of points just *outside* that boundary, ``b + δ(1 + |b|) n`` and
``b + 1000δ(1 + |b|) n`` with ``b`` the last point ``J_ν x ≠ x`` met, ``n`` the outer normal and ``δ`` from
:data:`OUTSIDE` (a projection that forgets the points within ``10^-6`` of its set returns the first and
projects the second: no longer firmly nonexpansive).  Step sizes are log-uniform in ``[10^-3, 10]``
(``λ = 1`` every fifth sample), times uniform in ``[0, horizon]`` with both ends included.  Every sixth sample
(from the second) has coordinates of mixed magnitudes ``±10^u``, ``u ∈`` :data:`MIXED` each, with step sizes of
as many decades: a minimal section wrong only for coordinates in ``(0, 10^-3]`` is met there.

A sweep sample that breaks the law is shrunk greedily (:func:`shrink`: ``t → 0``, step sizes → 1,
coordinates → 0, then each coordinate rounded to fewer digits, kept while the law still fails) and
reported like a hypothesis counterexample (``counterexample["found_by"] = "sweep"``); it is replayed by
``sample=``.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ...core.tolerances import current_largest

#: magnitudes of the swept points: tiny (below the rounding scale of a unit problem), unit, huge, far
SCALES = (1e-9, 1e-7, 5e-7, 1e-5, 1e-3, 1e-1, 1.0, 3.0, 10.0, 1e2, 1e3, 1e6)
#: offsets of the points just outside the boundary of the domain, ``b + δ(1 + |b|) n``, relative
OUTSIDE = (1e-12, 1e-10, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3)
#: decades of the mixed-magnitude samples: each coordinate ``±10^u``, and each step ``10^u``, ``u`` uniform here
#: (a law whose violation needs a coordinate in ``(0, 10^-3]`` at a step below it: the kinks of ``∂|x|₁``)
MIXED = (-9.0, 2.0)
#: sweep samples per law and profile (``None``: a profile not of verimono's, e.g. a user's own)
SWEEP_BY_PROFILE = {"dev": 33, "ci": 33, "thorough": 132, None: 33}
#: laws whose one evaluation is expensive (an independent minimiser) see this many sweep samples at most: the
#: sweep's first ``len(SCALES)`` samples, one at each scale, so that the law searches the range of ``|x|`` its
#: siblings search (to ``10^6``).  It was 4, the four tiniest scales (``10^-9 … 10^-5``): with its draws'
#: ``|x| ≤ 10`` a prox wrong only for ``|x| > 20`` passed it while every sibling law failed it (issue 43, probe2)
SWEEP_CAP = {"prox_minimiser": len(SCALES)}


#: the far decades: a sweep sample whose ``|x1|`` scale is at least this is "far"
FAR = 1e5


def far_general(i: int, cap: float, n: int) -> bool:
    """Whether sweep sample ``i`` is a far point in a general direction, evaluated as drawn: every other far sample
    (the first of each pair), at a scale of at least :data:`FAR`.  The far scale comes every ``len(SCALES) = 12``
    samples, and ``12`` is a multiple of ``3`` and ``4`` less one (``i ≡ 11 mod 12``): every far sample fell on the
    coordinate axes (``i % 3 == 2``) and was replaced by points in the range of the resolvent (``i % 4 == 3``), so the
    search's far points were only ``±10^6 e_k`` and their projections (blind set 7, ``ball_far_sign_shortcut``: a
    shortcut exact on the axes, missed at ``dev`` and ``ci`` seed 0).  The other far samples keep the axes and the
    range of ``J``.  On ``R^1`` every direction is an axis: nothing changes there (``n = 1`` samples are as before)."""
    return n >= 2 and min(SCALES[i % len(SCALES)], cap) >= FAR and (i // len(SCALES)) % 2 == 0


def sweep_count(profile: str | None, law: str) -> int:
    n = SWEEP_BY_PROFILE.get(profile, SWEEP_BY_PROFILE[None])
    return min(n, SWEEP_CAP.get(law, n))


def _sweep_draws(n: int, seed: int, horizon: float, count: int, cap: float) -> tuple:
    """The seeded part of :func:`sweep_samples` — every sample's ``x1, x2, λ, μ, ν, t`` before the points in the
    range of the resolvent replace some (those consume no draw) — as ``(X1, X2, steps, t)``, read-only: the same
    for every law of a battery (cached by :func:`_cached_draws`)."""
    rng = np.random.default_rng([int(seed) % (2 ** 63), n, count])
    X1, X2, steps, ts = np.empty((count, n)), np.empty((count, n)), np.empty((count, 3)), np.empty(count)
    for i in range(count):
        s1 = min(SCALES[i % len(SCALES)], cap)
        u = rng.uniform(-1.0, 1.0, n)
        if i % 3 == 2:
            sign = rng.choice((-1.0, 1.0))      # drawn (in u[k] = sign's order) for a far general sample too: the
            k = rng.integers(n)                 # stream, and every other sample, stay as they were
            if not far_general(i, cap, n):
                u = np.zeros(n)
                u[k] = sign
        x1 = s1 * u
        if i % 2 == 0:
            x2 = x1 + 1e-2 * s1 * rng.uniform(-1.0, 1.0, n)
        else:
            x2 = min(SCALES[rng.integers(len(SCALES))], cap) * rng.uniform(-1.0, 1.0, n)
        lam, mu, nu = (float(10.0 ** rng.uniform(-3.0, 1.0)) for _ in range(3))
        if i % 5 == 0:
            lam = 1.0
        if i % 6 == 1:   # coordinates of mixed magnitudes, with steps of as many decades
            x1 = rng.choice((-1.0, 1.0), n) * 10.0 ** rng.uniform(*MIXED, n)
            x1 = np.minimum(np.abs(x1), cap) * np.sign(x1)
            x2 = x1 + 1e-2 * np.abs(x1) * rng.uniform(-1.0, 1.0, n)
            lam, mu, nu = (float(10.0 ** rng.uniform(*MIXED)) for _ in range(3))
        t = float((0.0, float(horizon))[i % 2]) if i % 7 < 2 else float(rng.uniform(0.0, horizon))
        X1[i], X2[i], steps[i], ts[i] = x1, x2, (lam, mu, nu), t
    return X1, X2, steps, ts


#: the seeded draws of the last few (function, arguments) — a battery's laws draw the same samples for the same
#: seed, dimension and count: :func:`_cached_draws`
_DRAWS: dict = {}
#: how many draws :data:`_DRAWS` keeps (a battery's; a stage's operators of one dimension share theirs)
DRAWS_KEPT = 16


def _cached_draws(fn: Callable, *args) -> tuple:
    """``fn(*args)`` (a pure function of its arguments: seeded NumPy draws), computed once for the last
    :data:`DRAWS_KEPT` distinct calls; its arrays read-only (every sample made from them gets copies)."""
    key = (fn.__name__,) + args
    got = _DRAWS.get(key)
    if got is None:
        got = fn(*args)
        for a in got:
            a.flags.writeable = False
        if len(_DRAWS) >= DRAWS_KEPT:
            _DRAWS.pop(next(iter(_DRAWS)))
        _DRAWS[key] = got
    return got


def sweep_samples(op, seed: int, horizon: float, count: int, make: Callable) -> list:
    """``count`` samples (built by ``make(x1, x2, lam, mu, nu, t)``) for ``op`` on ``R^n``, seeded by ``seed``: the
    rows of :func:`sweep_arrays`, each sample with copies of its points."""
    return _samples(sweep_arrays(op, seed, horizon, count), make)


def sweep_arrays(op, seed: int, horizon: float, count: int) -> tuple:
    """The samples of :func:`sweep_samples` as arrays ``(X1, X2, steps, t)`` (``(count, n)``, ``(count, n)``,
    ``(count, 3)``, ``(count,)``; fresh, the caller's own), for a block of them
    (:class:`verimono.checks.engine.blocks.SampleBlock`): the seeded draws with the points in the range of the
    resolvent, and just outside the boundary, put in their rows."""
    n = int(op.dim)
    cap = current_largest() / 64.0           # a float16 subject cannot be given |x| = 1e6
    X1, X2, steps, ts = _cached_draws(_sweep_draws, n, int(seed), float(horizon), int(count), float(cap))
    lams, mus, nus, tl = steps[:, 0].tolist(), steps[:, 1].tolist(), steps[:, 2].tolist(), ts.tolist()
    boundary = None
    P1, P2, S, T = np.array(X1), np.array(X2), np.array(steps), np.array(ts)    # writable copies, filled below
    for i in range(count):
        x1, x2, lam, mu, nu, t = X1[i].copy(), X2[i].copy(), lams[i], mus[i], nus[i], tl[i]
        if i % 4 == 3 and not far_general(i, cap, n):   # points in the range of J: J_ν x and J_ν(J_ν x), or just outside the boundary
            try:
                a = np.asarray(op.resolvent(x1.copy(), nu, t), dtype=float)
                b = np.asarray(op.resolvent(a.copy(), nu, t), dtype=float)
                if a.shape == x1.shape and b.shape == x1.shape and np.all(np.isfinite(a)) and np.all(np.isfinite(b)):
                    d = float(np.linalg.norm(x1 - a))
                    if d > 0:
                        boundary = (a, (x1 - a) / d, nu, t)
                    x1, x2 = a, b
            except Exception:   # noqa: BLE001 - the law itself evaluates (and fails) the raw point
                pass
        if i % 8 in (5, 7) and boundary is not None:   # b + δ n, b + 1000 δ n: the last boundary point seen
            a, normal, nu, t = boundary
            delta = OUTSIDE[(i // 4) % len(OUTSIDE)] * (1.0 + float(np.linalg.norm(a)))
            x1, x2 = a + delta * normal, a + 1e3 * delta * normal
        P1[i], P2[i], S[i], T[i] = x1, x2, (lam, mu, nu), t
    return P1, P2, S, T


#: the values hypothesis's float strategies favour, drawn here as often: ends of the range, 0, ±1, ±1/2, ±2
_NASTY = (0.0, 1.0, -1.0, 0.5, -0.5, 2.0, -2.0, 10.0, -10.0)
#: the simple step sizes and times of :func:`verimono.strategies.step_sizes` / :func:`~verimono.strategies.times`
_SIMPLE_STEPS = (1.0, 0.5, 2.0, 0.1, 10.0, 1e-3)


def law_draws(n: int, seed: int, horizon: float, count: int, make: Callable, scale: float = 10.0) -> list:
    """``count`` samples like :func:`verimono.checks.operator_laws.law_samples` draws them — ``x1`` in
    ``[-scale, scale]^n``, ``x2`` independent or within ``10^-2`` of ``x1`` (half each), ``λ, μ, ν`` in
    ``[10^-3, 10]``, ``t`` in ``[0, horizon]`` — with hypothesis's preference for simple values (each coordinate
    is one of 0, ±1/2, ±1, ±2, ±scale a quarter of the time, a small integer another eighth; half the step
    sizes and times are the strategies' simple ones), but drawn by NumPy from ``default_rng(seed)``, about a
    hundred times faster than hypothesis's engine draws a sample."""
    return _samples(_cached_draws(_law_draws, int(n), int(seed), float(horizon), int(count), float(scale)), make)


def _law_draws(n: int, seed: int, horizon: float, count: int, scale: float) -> tuple:
    """The draws of :func:`law_draws` as ``(X1, X2, steps, t)``."""
    rng = np.random.default_rng([int(seed) % (2 ** 63), int(n), int(count), 1])

    def point(size: float) -> np.ndarray:
        u = rng.uniform(-size, size, n)
        pick = rng.uniform(size=n)
        nasty = np.array(_NASTY) * (size / 10.0)
        u = np.where(pick < 0.25, nasty[rng.integers(len(nasty), size=n)], u)
        return np.where((pick >= 0.25) & (pick < 0.375), np.rint(u), u)

    def step() -> float:
        if rng.uniform() < 0.5:
            return float(_SIMPLE_STEPS[rng.integers(len(_SIMPLE_STEPS))])
        return float(10.0 ** rng.uniform(-3.0, 1.0)) if rng.uniform() < 0.5 else float(rng.uniform(1e-3, 10.0))

    X1, X2, steps, ts = np.empty((count, n)), np.empty((count, n)), np.empty((count, 3)), np.empty(count)
    for i in range(count):
        x1 = point(scale)
        x2 = x1 + point(1e-2) if rng.uniform() < 0.5 else point(scale)
        lam, mu, nu = step(), step(), step()
        t = (0.0, float(horizon), 0.5 * horizon)[rng.integers(3)] if rng.uniform() < 0.5 else \
            float(rng.uniform(0.0, horizon))
        X1[i], X2[i], steps[i], ts[i] = x1, x2, (lam, mu, nu), float(t)
    return X1, X2, steps, ts


def _samples(draws: tuple, make: Callable) -> list:
    """The samples of cached draws ``(X1, X2, steps, t)``, each with its own copies of the points — or, when ``make``
    has a ``block`` (:func:`verimono.checks.engine.blocks.make_sample`), ``make.block(X1, X2, steps, t)``: the same
    samples as one block of arrays, each made with its own copies when asked for."""
    block = getattr(make, "block", None)      # a maker of blocks (blocks.make_sample): the rows as one block
    if block is not None:
        return block(*draws)
    X1, X2, steps, ts = draws
    return [make(X1[i].copy(), X2[i].copy(), lam, mu, nu, t)
            for i, ((lam, mu, nu), t) in enumerate(zip(steps.tolist(), ts.tolist()))]


#: hypothesis's own favourites that :func:`law_draws` does not draw (printed from its generate phase on the catalog at
#: ci, docs/speed.md "Edge samples"): the smallest normal float64, float32's smallest normal and smallest subnormal,
#: float64's machine epsilon, float16's epsilon and smallest normal — as coordinates beside ordinary ones
EDGE_CONSTANTS = (2.2250738585072014e-308, 1.1754943508222875e-38, 1.401298464324817e-45, 2.220446049250313e-16,
                  5.960464477539063e-08, 6.103515625e-05)
#: hypothesis's values next to the simple ones (1 - 2^-53 is the float below 1), and the ends of the range
EDGE_NEAR_SIMPLE = (1.9, 1.1, 1.5, 1.0 / 3.0, 0.99999, 1.001, 2.00001, 1.0 - 2.0 ** -53, 10.0)
#: step sizes of the edge samples: the strategies' simple ones and hypothesis's values next to them
EDGE_STEPS = _SIMPLE_STEPS + (0.99999, 1.001, 2.00001, 1.9, 1.5, 1.0 - 2.0 ** -53)
#: times of the edge samples, as fractions of the horizon: both ends, the middle, hypothesis's tiny times
#: (``10^-98``, ``2^-24``, ``2^-14``) and the float below the horizon
EDGE_TIMES = (0.0, 1.0, 0.5, 1e-98, 5.960464477539063e-08, 6.103515625e-05, 1.0 - 2.0 ** -53)
#: the coordinate kinds of an edge sample and how often each is drawn: ordinary uniform, an :data:`EDGE_CONSTANTS`,
#: tiny ``±10^u`` (``u`` uniform in ``[-307, -10]``: hypothesis draws floats by exponent), subnormal, ``±0.0``,
#: an :data:`EDGE_NEAR_SIMPLE`, a small integer
EDGE_KINDS = (0.30, 0.15, 0.15, 0.08, 0.12, 0.12, 0.08)
#: edge samples per law: at least this many, ``examples // 2`` when more
EDGE_MIN = 16


def edge_count(examples: int) -> int:
    """How many edge samples :func:`edge_draws` makes for a law searched with ``examples`` draws."""
    return max(EDGE_MIN, int(examples) // 2)


def edge_draws(n: int, seed: int, horizon: float, count: int, make: Callable, scale: float = 10.0) -> list:
    """``count`` samples of the kinds hypothesis's generate phase contributed beyond :func:`law_draws` (its
    simplest example, its extreme floats beside ordinary entries, repeated values), drawn by NumPy in one pass
    from ``default_rng(seed)`` (the same on every machine):

    * the simplest sample, ``x1 = x2 = 0``, ``λ = μ = ν = 1``, ``t = 0`` (hypothesis's first example), and a
      pair of identical points ``x1 = x2``;
    * coordinates of ``x1`` of the kinds :data:`EDGE_KINDS` — ordinary ones in ``[-scale, scale]`` beside
      :data:`EDGE_CONSTANTS`, tiny ``±10^u`` (``10^-307`` to ``10^-10``), subnormals, ``±0.0`` and
      :data:`EDGE_NEAR_SIMPLE` (times ``scale / 10``);
    * ``x2`` within ``10^-2`` of ``x1`` (half the samples), with half its offsets exactly 0 (coordinates equal
      to ``x1``'s: repeated values), or drawn like ``x1``;
    * step sizes from :data:`EDGE_STEPS` half the time (else log-uniform in ``[10^-3, 10]``), times from
      :data:`EDGE_TIMES` (times ``horizon``) half the time (else uniform in ``[0, horizon]``)."""
    return _samples(edge_arrays(n, seed, horizon, count, scale), make)


def edge_arrays(n: int, seed: int, horizon: float, count: int, scale: float = 10.0) -> tuple:
    """The samples of :func:`edge_draws` as its cached arrays ``(X1, X2, steps, t)``, read-only (a block of them:
    :meth:`verimono.checks.engine.blocks.SampleBlock.drawn`)."""
    return _cached_draws(_edge_draws, int(n), int(seed), float(horizon), int(count), float(scale))


def _edge_draws(n: int, seed: int, horizon: float, count: int, scale: float) -> tuple:
    """The draws of :func:`edge_draws` as ``(X1, X2, steps, t)``."""
    count, n = int(count), int(n)
    rng = np.random.default_rng([int(seed) % (2 ** 63), n, count, 2])
    kinds = np.cumsum(EDGE_KINDS) / np.sum(EDGE_KINDS)

    def points(size: float) -> np.ndarray:
        shape = (count, n)
        kind = np.searchsorted(kinds, rng.random(shape), side="right")
        sign = np.where(rng.random(shape) < 0.5, -1.0, 1.0)
        choices = [
            rng.uniform(-size, size, shape),
            sign * np.array(EDGE_CONSTANTS)[rng.integers(len(EDGE_CONSTANTS), size=shape)],
            sign * 10.0 ** rng.uniform(-307.0, -10.0, shape),
            sign * 5e-324 * rng.integers(1, 2 ** 52, size=shape).astype(float),     # k · 2^-1074: subnormal
            sign * 0.0,
            sign * np.array(EDGE_NEAR_SIMPLE)[rng.integers(len(EDGE_NEAR_SIMPLE), size=shape)] * (size / 10.0),
            np.rint(rng.uniform(-size, size, shape)),
        ]
        return np.choose(np.minimum(kind, len(choices) - 1), choices)

    x1 = points(scale)
    near = rng.random(count) < 0.5
    offset = np.where(rng.random((count, n)) < 0.5, 0.0, points(1e-2))
    x2 = np.where(near[:, None], x1 + offset, points(scale))
    steps = np.where(rng.random((count, 3)) < 0.5, np.array(EDGE_STEPS)[rng.integers(len(EDGE_STEPS), size=(count, 3))],
                     10.0 ** rng.uniform(-3.0, 1.0, (count, 3)))
    t = float(horizon) * np.where(rng.random(count) < 0.5, np.array(EDGE_TIMES)[rng.integers(len(EDGE_TIMES), size=count)],
                                  rng.random(count))
    if count:
        x1[0], x2[0], steps[0], t[0] = 0.0, 0.0, 1.0, 0.0      # hypothesis's simplest example
    if count > 1:
        x2[1] = x1[1]                                          # identical points
    return x1, x2, steps, t


def _simpler_floats(v: float) -> list[float]:
    if v == 0.0:
        return []
    out = []
    for digits in (1, 2, 4):
        r = float(f"{v:.{digits - 1}e}")
        if r != v:
            out.append(r)
    return out


def shrink(sample, fails: Callable[[object], bool], replace: Callable, budget: int = 300):
    """Greedy shrinking of a failing ``sample``: simpler candidates (``t = 0``, step sizes 1, coordinates 0,
    coordinates rounded to 1, 2, 4 significant digits) are kept while ``fails(candidate)``; at most
    ``budget`` evaluations.  ``replace(sample, **fields)`` builds a modified sample."""
    calls = 0

    def attempt(cand) -> bool:
        nonlocal calls, sample
        if calls >= budget:
            return False
        calls += 1
        try:
            ok = fails(cand)
        except Exception:   # noqa: BLE001 - a candidate the law cannot evaluate is not simpler
            ok = False
        if ok:
            sample = cand
        return ok

    changed = True
    while changed and calls < budget:
        changed = False
        for field, simple in (("t", 0.0), ("lam", 1.0), ("mu", 1.0), ("nu", 1.0)):
            if getattr(sample, field) != simple:
                changed |= attempt(replace(sample, **{field: simple}))
        for field in ("x1", "x2"):
            for i in range(getattr(sample, field).size):
                v = getattr(sample, field)
                if v[i] == 0.0:
                    continue
                for r in [0.0] + _simpler_floats(float(v[i])):
                    w = v.copy()
                    w[i] = r
                    if attempt(replace(sample, **{field: w})):
                        changed = True
                        break
    return sample, calls


__all__ = ["SCALES", "SWEEP_BY_PROFILE", "SWEEP_CAP", "sweep_count", "sweep_samples", "sweep_arrays", "law_draws",
           "edge_draws", "edge_arrays",
           "edge_count", "EDGE_MIN", "shrink"]
