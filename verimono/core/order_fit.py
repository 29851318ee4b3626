"""The order of a scheme from its errors: the least-squares slope of ``log e`` against ``log h`` with a 95% interval.

The order in each norm is the slope of ``log e`` against ``log |Δ|`` (``|Δ| = max_k h_k``) by least squares —
valid for any step ratio — with a 95% Student-t confidence interval.  Errors at the floor of a grid are
dropped; if every error is there the scheme is exact on the grids.  A fit may be restricted to a window of the
grids (``within``: the grids a verdict rests on, :mod:`verimono.core.verdicts`); the others are ``excluded``.

A fit over grids whose local slopes still move (pre-asymptotic) averages the coarse end's slopes with the fine
end's: local slopes 3.50, 2.14, 2.03 fit as 2.46 with an interval up to 3.46, which "reaches" 3 for a scheme of
order 2.  The order a scheme shows is the limit of its local slopes as ``h → 0``, so a verdict rests on the
finest of them (:func:`finest_slopes`): the finest local slope whose finer error lies well above its floor, with
an interval that holds where the slopes are still heading — the last change of slope extrapolated for an error
``C h^p (1 + O(h))`` (the deviation of the slope from ``p`` shrinks by the step ratio ``ρ`` per refinement, so
the slope can still move by ``|Δs| / (ρ − 1)``), how far the slopes jump up and down (noise), and what the floor
can do to the two errors.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Sequence

import numpy as np

#: local slopes that spread by more than this are not yet in the asymptotic regime
ASYMPTOTIC_SPREAD = 0.25
#: the finest local slopes have *settled* when the interval of the finest is at most this much either side
SETTLED = 0.25
#: a claim is missed on the finest slopes only when the two finest lie this much below it (times min(p, 1)): a scheme
#: of order p − 1 claimed as p is, a correct scheme on noisy errors (slopes 0.69, 0.74 for order 1) is not
FAIL_MARGIN = 0.4
#: the finest local slope is read where the floor can move it (and the slope before it) by at most this much —
#: by ``(floor_a/e_a + floor_b/e_b) / log(h_a/h_b)`` —, unless it can move every slope more
TRUSTED_NOISE = 0.1
#: an order estimate "reaches" p when its interval's upper end is within this of p; the slack absorbs
#: the O(h) drift of the slope of C h^p (1 + O(h)) over the studied range
ORDER_SLACK = 0.1


@dataclasses.dataclass
class OrderFit:
    """Least-squares slope of ``log e`` vs ``log h`` with its 95% interval (``nan`` with < 3 points).

    ``used``/``dropped``: the grids fitted and those at their floor (indices into the study's grids);
    ``local_slopes``: the slopes between successive fitted grids, fine to coarse; ``excluded``: grids outside the
    window the fit was restricted to."""

    slope: float
    low: float
    high: float
    used: list[int]
    dropped: list[int]
    local_slopes: list[float]
    pre_asymptotic: bool
    exact: bool = False
    #: indices of the grids whose error is not a finite number (a failed study, never "exact")
    nonfinite: list[int] = dataclasses.field(default_factory=list)
    #: indices of the grids outside the window the fit was restricted to
    excluded: list[int] = dataclasses.field(default_factory=list)

    def contains(self, p: float, slack: float = ORDER_SLACK) -> bool:
        return self.low - slack <= p <= self.high + slack

    def reaches(self, p: float, slack: float = ORDER_SLACK) -> bool:
        return self.high + slack >= p

    def __str__(self) -> str:
        if self.nonfinite:
            return "undefined (non-finite errors)"
        if self.exact:
            return "exact (round-off)"
        if math.isnan(self.low):
            return f"{self.slope:.3f}"
        return f"{self.slope:.3f} [{self.low:.3f}, {self.high:.3f}]"


@dataclasses.dataclass
class FinestSlopes:
    """The order at the fine end of a study (module docstring): the finest trusted local ``slope`` (between the
    grids of steps ``h``, coarse to fine) and the one before it (``previous``), with three widths:

    * ``drift`` — how far the slopes may still move, ``|slope − previous| / (ρ − 1)`` where they follow a trend
      (the last change of slope goes the way of the one before), ``|slope − previous|`` where they reverse;
    * ``scatter`` — how far they jump up and down (noise, not a trend): the largest zigzag of the slopes, the
      smaller of two successive changes of opposite sign;
    * ``noise`` — how far the floor can move the slope, ``(floor_a/e_a + floor_b/e_b) / log(h_a/h_b)``.

    The order is met (:meth:`reaches`) on the drift and the scatter — agreeing slopes show that the floor did not
    act —, and missed (:meth:`below`) only when the interval widened by the floor's noise lies below it too: near
    the floor a slope is never failed on what rounding could have done to it.  ``slopes``: the local slopes it was
    read from, coarse to fine."""

    slope: float
    previous: float
    drift: float
    scatter: float
    noise: float
    h: tuple[float, float]
    slopes: list[float]

    @property
    def spread(self) -> float:
        """How far the slopes' limit may lie from the finest slope on what the slopes show (drift, scatter)."""
        return max(self.drift, self.scatter)

    @property
    def half(self) -> float:
        """The half width of the interval the slopes' limit lies in (with what the floor can do)."""
        return max(self.spread, self.noise)

    @property
    def low(self) -> float:
        return self.slope - self.half

    @property
    def high(self) -> float:
        return self.slope + self.half

    @property
    def settled(self) -> bool:
        """The finest slopes agree and do not jump: they may move by at most ``SETTLED``."""
        return self.spread <= SETTLED

    @property
    def erratic(self) -> bool:
        """The slopes jump up and down by more than ``SETTLED``: noise, which a fit over several grids averages."""
        return self.scatter > SETTLED

    def reaches(self, p: float, slack: float = ORDER_SLACK) -> bool:
        """The order ``p`` is met at the fine end: wherever the slopes still move they stay at or above ``p``, or
        they have settled within ``slack`` of it or above."""
        return self.slope - self.spread + slack >= p or (self.settled and self.slope + self.spread + slack >= p)

    def below(self, p: float, slack: float = ORDER_SLACK) -> bool:
        """The finest slopes sit at a lower order: the whole interval (drift, scatter and the floor's noise) lies
        below ``p``, and the two finest slopes lie ``FAIL_MARGIN · min(p, 1)`` or more below it (two slopes that
        agree by chance, on noisy errors, are not enough to fail a scheme a little below its order)."""
        margin = FAIL_MARGIN * min(p, 1.0)
        return self.high + slack < p and max(self.slope, self.previous) <= p - margin

    def __str__(self) -> str:
        return f"{self.slope:.2f} ± {self.half:.2f}"


def finest_slopes(h: Sequence[float], e: Sequence[float], floor: float | Sequence[float],
                  within: Sequence[int]) -> FinestSlopes | None:
    """The order at the fine end of the grids ``within`` (successive grids, all above their floor): the finest local
    slope the floor can move by at most ``TRUSTED_NOISE`` (else the one it can move least), with its drift, the
    slopes' scatter and the floor's noise (:class:`FinestSlopes`); ``None`` with fewer than three grids."""
    h, e = np.asarray(h, float), np.asarray(e, float)
    fl = np.broadcast_to(np.asarray(floor, float), e.shape)
    grids = sorted(within, key=lambda i: -h[i])
    if len(grids) < 3:
        return None
    pairs = list(zip(grids[:-1], grids[1:]))
    slopes = [float(math.log(e[a] / e[b]) / math.log(h[a] / h[b])) for a, b in pairs]
    moved = [float((fl[a] / e[a] + fl[b] / e[b]) / math.log(h[a] / h[b])) for a, b in pairs]
    noise = [max(moved[j - 1], moved[j]) if j else moved[0] for j in range(len(pairs))]
    trusted = [j for j in range(1, len(pairs)) if noise[j] <= TRUSTED_NOISE]
    # the finest trusted slope, else the one the floor can move least
    n = trusted[-1] if trusted else min(range(1, len(pairs)), key=lambda j: (noise[j], -j))
    (a0, b0), (a, b) = pairs[n - 1], pairs[n]
    rho = math.sqrt(h[a0] * h[b0] / (h[a] * h[b]))         # the ratio of the two slopes' mean steps
    d = np.diff(slopes[:n + 1])
    zigzags = [min(abs(d[j]), abs(d[j + 1])) for j in range(len(d) - 1) if d[j] * d[j + 1] < 0]
    # a trend extrapolates; a last change that reverses the one before is noise, as large as it is
    trend = len(d) < 2 or d[-1] * d[-2] >= 0
    drift = abs(slopes[n] - slopes[n - 1]) / (max(rho - 1.0, 0.25) if trend else 1.0)
    return FinestSlopes(slopes[n], slopes[n - 1], drift, float(max(zigzags, default=0.0)), noise[n],
                        (float(h[a]), float(h[b])), slopes[:n + 1])


def fit_order(h: Sequence[float], e: Sequence[float], floor: float | Sequence[float] = 0.0,
              within: Sequence[int] | None = None) -> OrderFit:
    """Fit ``e ≈ C h^p`` on the points above ``floor`` (one floor, or one per grid), among the grids ``within``
    (default: all).

    A non-finite error (``nan``/``inf``: a stepper that diverged or returned garbage) is never "below the
    floor": the fit is then ``nan`` with ``nonfinite`` listing the offending grids.
    """
    h, e = np.asarray(h, float), np.asarray(e, float)
    floor = np.broadcast_to(np.asarray(floor, float), e.shape)
    inside = np.zeros(len(e), dtype=bool)
    inside[list(range(len(e))) if within is None else list(within)] = True
    excluded = np.flatnonzero(~inside).tolist()
    bad = np.flatnonzero(inside & ~np.isfinite(e)).tolist()
    if bad:
        return OrderFit(math.nan, math.nan, math.nan, [], np.flatnonzero(inside).tolist(), [], False, nonfinite=bad,
                        excluded=excluded)
    keep = inside & (e > floor)
    used, dropped = np.flatnonzero(keep).tolist(), np.flatnonzero(inside & ~keep).tolist()
    if len(used) == 0:
        return OrderFit(math.inf, math.inf, math.inf, used, dropped, [], False, exact=True, excluded=excluded)
    lh, le = np.log(h[keep]), np.log(e[keep])
    order = np.argsort(lh)
    lh, le = lh[order], le[order]
    local = (np.diff(le) / np.diff(lh)).tolist() if len(lh) > 1 else []
    if len(lh) < 2:
        return OrderFit(math.nan, math.nan, math.nan, used, dropped, local, True, excluded=excluded)
    from scipy.special import stdtrit   # the Student-t quantile (scipy.special: already loaded by scipy.linalg)

    slope, stderr = least_squares_slope(lh, le)
    half = float(stdtrit(len(lh) - 2, 0.975)) * stderr if len(lh) > 2 else math.nan
    spread = (max(local) - min(local)) if len(local) > 1 else 0.0
    return OrderFit(slope, slope - half, slope + half, used, dropped, local, spread > ASYMPTOTIC_SPREAD,
                    excluded=excluded)


def least_squares_slope(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """The least-squares slope of ``y`` on ``x`` and its standard error, as ``scipy.stats.linregress`` computes
    them (its formulas, without importing ``scipy.stats``: 0.6 s, paid again by every worker process).
    ``x`` must not be constant (a study's meshes are distinct)."""
    ssxm, ssxym, _, ssym = np.cov(x, y, bias=True).flat
    r = 0.0 if ssxm == 0.0 or ssym == 0.0 else min(1.0, max(-1.0, ssxym / math.sqrt(ssxm * ssym)))
    slope = ssxym / ssxm
    df = len(x) - 2
    stderr = math.sqrt((1.0 - r * r) * ssym / ssxm / df) if df > 0 else math.nan
    return float(slope), float(stderr)


__all__ = ["OrderFit", "FinestSlopes", "fit_order", "finest_slopes", "least_squares_slope", "ORDER_SLACK",
           "ASYMPTOTIC_SPREAD", "SETTLED", "TRUSTED_NOISE", "FAIL_MARGIN"]
