"""The order of a scheme from its errors: the least-squares slope of ``log e`` against ``log h`` with a 95% interval.

The order in each norm is the slope of ``log e`` against ``log |Δ|`` (``|Δ| = max_k h_k``) by least squares —
valid for any step ratio — with a 95% Student-t confidence interval.  Errors at the floor of a grid are
dropped; if every error is there the scheme is exact on the grids.  A fit may be restricted to a window of the
grids (``within``: the grids a verdict rests on, :mod:`verimono.core.verdicts`); the others are ``excluded``.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Sequence

import numpy as np

#: local slopes that spread by more than this are not yet in the asymptotic regime
ASYMPTOTIC_SPREAD = 0.25
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


__all__ = ["OrderFit", "fit_order", "least_squares_slope", "ORDER_SLACK", "ASYMPTOTIC_SPREAD"]
