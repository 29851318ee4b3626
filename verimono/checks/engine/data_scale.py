"""The operator's own scale: the magnitude of the data it computes with, stated or inferred from its domain.

A correct resolvent rounds at the magnitude of what it computes with, which the points a law touches need not
show: the projection onto a ball of radius ``r`` centred at ``c`` forms ``x − c`` and returns
``c + r (x − c)/|x − c|``, exact to ``eps·(|c| + r)`` whatever ``|x|`` (``verimono.core.tolerances``, "the
operator's own scale").  The one tolerance rule takes that magnitude ``S`` as one more scale.

* **Stated** (:func:`stated_scale`): an operator's ``data_scale`` (``verimono.operator_from_resolvent(...,
  data_scale=S)``, ``operator_from_prox(..., data_scale=S)``, or the attribute of any :class:`verimono.Operator`).
  Every law is then judged at it (the record's ``details["data_scale"]`` says so): the user vouches for the
  magnitude, and a violation smaller than its rounding cannot be told from correct code.
* **Inferred** (:func:`inferred_scale`), only for a law that failed at the points' scale: the extent of
  ``cl dom F(t,·)`` seen through the resolvent itself.  ``J_1`` of far points ``R d`` (``R = 10^3, 10^6, ...``,
  directions ``±e_i`` and seeded random ones, ``t`` at both ends of the horizon) is pulled onto the domain;
  where it stops growing with ``R`` (``|J(R d)| ≤ R/2`` and ``|J(10^3 R d)| ≤ 2|J(R d)|``: the domain is bounded
  that way) its size is an extent of the data.  In directions where the domain is unbounded ``J(R d)`` grows with
  ``R`` and tells nothing; a full-domain operator (``J`` linear in ``x``, a soft threshold) has no extent, ``S = 0``.
* **The verdict** (:func:`judged_at_data_scale`): a law that failed is run once more at the inferred ``S``; if it
  holds there, its violation is within the rounding correct code at the operator's own scale makes, and the
  record is **undecided** — never passed (a wrong resolvent off by less than ``rtol·S`` is not acquitted), never
  failed (a correct one is not blamed) — with the violation, ``S``, the probe's evidence and how to decide
  (state ``data_scale``).  A failure that persists at ``S`` stays failed; a non-finite value (a NaN, an infinity,
  an exception) is never rounding and is not re-judged.  A violated inequality ``lhs ≤ rhs + slack`` between
  finite numbers whose bound ``rhs + slack`` is ``≤ 0`` has the ratio ``inf`` by convention
  (:func:`verimono.checks.core.ratio`), yet it is a finite failure: firm nonexpansiveness of a correct ball of
  radius 10^12 at points near its boundary, ``lhs 1e-10 > rhs -9.99e-08 + slack 4.04e-10`` (probe7, seed 0), is
  re-judged like any other (:func:`finite_failure`).
"""

from __future__ import annotations

import math
import weakref
from typing import Any, Callable

import numpy as np

from ...core.operator_protocol import stated_data_scale
from ...core.tolerances import LARGEST_BY_PRECISION, judged_at_scale
from ...records.results import FAILED, PASSED, UNDECIDED, CheckResult
from ...records.verdicts import new_record

#: the far radii of the probe: every third decade from 10^3 up to ``sqrt(largest)·10^-3`` of the precision the law
#: was judged at (squares of the probe's points stay finite), and never beyond 10^60 (float64: 20 radii, float32: 5)
PROBE_DECADE_STEP = 3
PROBE_TOP = 1e60
#: the coordinate directions ``±e_i`` probed (the first ones) and the seeded random directions besides them
PROBE_COORDINATES = 4
PROBE_RANDOM = 4
#: ``J(R d)`` is "pulled in" when ``|J(R d)| ≤ R·PULLED`` and saturated when the next radius' value is at most
#: ``SATURATED`` times it: a bounded extent.  A linear or soft-threshold resolvent grows by the radius' factor 10^3
PULLED, SATURATED = 0.5, 2.0


def stated_scale(op: Any) -> float | None:
    """The operator's stated ``data_scale`` (``None``: not stated): :func:`verimono.core.operator_protocol.stated_data_scale`,
    which :class:`verimono.Problem` judges its ``x0`` at too."""
    return stated_data_scale(op)


def _radii(precision: str | None) -> list[float]:
    top = min(PROBE_TOP, math.sqrt(LARGEST_BY_PRECISION.get(precision or "float64", LARGEST_BY_PRECISION["float64"]))
              * 1e-3)
    out, k = [], PROBE_DECADE_STEP
    while 10.0 ** k <= top:
        out.append(10.0 ** k)
        k += PROBE_DECADE_STEP
    return out


def _directions(n: int) -> list[np.ndarray]:
    out = []
    for i in range(min(n, PROBE_COORDINATES)):
        e = np.zeros(n)
        e[i] = 1.0
        out += [e, -e]
    rng = np.random.default_rng(20261129)
    for _ in range(PROBE_RANDOM):
        v = rng.standard_normal(n)
        out.append(v / np.linalg.norm(v))
    return out


def _size(op: Any, x: np.ndarray, t: float) -> float | None:
    """``|J_1 x|_∞`` (``None`` when the resolvent raises or returns anything but finite values of ``x``'s shape)."""
    # imported here: checks.core imports this module, and members imports the engine's samples, which import
    # hypothesis — a stepper battery on the references alone must not pay that import (tests/testing/test_plugin.py)
    from ..members import resolvent
    try:
        j = resolvent(op, x, 1.0, t)
    except Exception:     # noqa: BLE001 - a probe point the resolvent refuses tells nothing of the extent
        return None
    return float(np.max(np.abs(j), initial=0.0))


def probe_extent(op: Any, n: int, horizon: float, precision: str | None) -> tuple[float, dict[str, Any]]:
    """The largest bounded extent of ``cl dom F(t,·)`` seen through ``J_1`` of far points (module docstring), and the
    evidence: the direction, time and radius where it was seen, and how many calls the probe made."""
    radii = _radii(precision)
    best, where, calls = 0.0, None, 0
    for t in sorted({0.0, float(horizon)}):
        for i, d in enumerate(_directions(n)):
            prev = None
            for R in radii:
                s = _size(op, R * d, t)
                calls += 1
                if s is None:
                    break
                if prev is not None and prev[1] <= PULLED * prev[0] and s <= SATURATED * max(prev[1], 1e-300):
                    e = max(prev[1], s)
                    if e > best:
                        best, where = e, {"direction": i, "t": t, "radius": prev[0]}
                    break
                prev = (R, s)
    return best, {"extent": best, "seen_at": where, "calls": calls,
                  "radii": [radii[0], radii[-1]] if radii else [], "lam": 1.0}


#: inferred scales by operator (weakly: an operator's probe is made once for its battery)
_INFERRED: "weakref.WeakKeyDictionary[Any, dict]" = weakref.WeakKeyDictionary()


def inferred_scale(op: Any, horizon: float, precision: str | None) -> tuple[float, dict[str, Any]]:
    """:func:`probe_extent` of ``op`` (memoised per operator, horizon and precision)."""
    key = (float(horizon), precision or "float64")
    try:
        memo = _INFERRED.setdefault(op, {})
    except TypeError:       # an operator that cannot be weakly referenced: probed each time
        memo = {}
    if key not in memo:
        n = int(getattr(op, "dim", 0) or 0)
        memo[key] = probe_extent(op, n, horizon, precision) if n > 0 else (0.0, {"extent": 0.0, "calls": 0})
    return memo[key]


def finite_failure(rec: CheckResult) -> bool:
    """Whether a failed record's violation is between finite numbers: its ratio is finite, or its counterexample's
    inequality ``lhs ≤ rhs + slack`` has three finite sides (a bound ``rhs + slack ≤ 0``: the ratio is ``inf`` by
    convention, the violation finite).  A NaN, an infinity or an exception is not."""
    if rec.worst is not None and math.isfinite(rec.worst):
        return True
    cex = rec.counterexample if isinstance(rec.counterexample, dict) else {}
    sides = [cex.get(k) for k in ("lhs", "rhs", "slack")]
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in sides)


def judged_at_data_scale(rec: CheckResult, op: Any, horizon: float,
                         rerun: Callable[[], CheckResult]) -> CheckResult:
    """A failed record with a finite ratio, of an operator stating no scale, judged once more at its inferred scale
    (module docstring): undecided when the law holds there, else the failure (stating the scale it persisted at)."""
    if rec.status != FAILED or not finite_failure(rec) or stated_scale(op) is not None:
        return rec
    precision = rec.details.get("dtype")
    S, evidence = inferred_scale(op, horizon, precision)
    if not S > 0.0:
        return rec
    with judged_at_scale(S):
        again = rerun()
    if again.status == FAILED:
        rec.details["data_scale"] = {"inferred": S, **evidence, "fails_there_too": True,
                                     "worst_there": again.worst}
        return rec
    details = {**rec.details, "data_scale": {"inferred": S, **evidence, "there": again.status}}
    out = new_record(rec.check, rec.subject, UNDECIDED, seed=rec.seed, details=details,
                      counterexample=rec.counterexample,
                      message=(f"{rec.message} — but within the rounding of the operator's own scale: its domain "
                               f"reaches |x| = {S:.3g} (J_1 of far points), where correct code rounds by "
                               f"rtol·(1 + {S:.3g}), and at that scale the law "
                               f"{'holds' if again.status == PASSED else 'is ' + again.status}; state the "
                               f"operator's data_scale (operator_from_resolvent(..., data_scale=...)) to decide"))
    out.duration = rec.duration
    return out


__all__ = ["finite_failure", "stated_scale", "inferred_scale", "probe_extent", "judged_at_data_scale"]
