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
* **Inferred from the rounding** (:func:`probe_rounding`), when no extent is seen: a domain unbounded in every probed
  direction shows none, yet its data may be large — a half-space whose boundary is written through a point ``10^8``
  *along* it computes ``a·(x − p)`` and rounds by ``eps·10^8`` on unit inputs, a magnitude no point a law touches
  shows (each law's inputs are of unit size).  What shows it is the subject's own rounding of an identity every
  projection obeys exactly, whatever its set: ``P(P x) = P x`` (idempotence), ``P`` the operator's
  ``project_domain`` (the projection onto ``cl dom F(t,·)``) or ``J_1`` where it is one (``J_1 x = J_1000 x``: a
  normal cone's resolvent is independent of the step).  Computed, the iterates ``P^k x`` of a correct projection
  settle — they repeat exactly within :data:`ROUNDING_ITERATES` steps (a rounding of an idempotent map has finitely
  many states near its set) — and the farthest they move from ``P x`` is its rounding, ``eps·S`` with ``S`` the
  magnitude it computes with.  A spread is taken as rounding only when the iterates repeat and it is less than
  ``PULLED`` times the projection's own move ``|P x − x|``: a contraction (``0.9·P``) never repeats, a reflection
  (``2P − I``) returns to ``x``, a move as large as the projection's own; neither is rounding.
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

from ...core.operator_protocol import provides, stated_data_scale
from ...core.tolerances import EPS_BY_PRECISION, LARGEST_BY_PRECISION, judged_at_scale
from ...records.results import FAILED, PASSED, UNDECIDED, CheckResult
from ...records.verdicts import new_record

#: the far radii of the probe: every third decade from 10^3 up to ``sqrt(largest)·10^-3`` of the precision the law
#: was judged at (squares of the probe's points stay finite), and never beyond 10^60 (float64: 20 radii, float32: 5)
PROBE_DECADE_STEP = 3
PROBE_TOP = 1e60
#: the coordinate directions ``±e_i`` probed (the first ones) and the seeded random directions besides them
PROBE_COORDINATES = 4
PROBE_RANDOM = 4
#: the iterates ``P^k x`` of a projection followed for an exact repeat (:func:`probe_rounding`); float32 iterates
#: that bounce within a rounding band of ``10^7`` ulps repeat within 41 steps (the half-space offset 1e8)
ROUNDING_ITERATES = 64
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


def _projection(op: Any, x: np.ndarray, t: float) -> Callable[[np.ndarray], np.ndarray] | None:
    """The operator's projection onto ``cl dom F(t,·)`` at ``x``: ``project_domain`` when it provides one, else ``J_1``
    when ``J_1 x = J_1000 x`` bit for bit (a normal cone: ``J_λ`` does not depend on ``λ``), else ``None``."""
    from ..members import point, resolvent       # the probe's own import (module docstring of _size)
    if provides(op, "project_domain"):
        return lambda z: point(op.project_domain(z.copy(), t), z, "project_domain")
    try:
        if not np.array_equal(resolvent(op, x, 1.0, t), resolvent(op, x, 1e3, t)):
            return None
    except Exception:     # noqa: BLE001 - a point the resolvent refuses tells nothing of its rounding
        return None
    return lambda z: resolvent(op, z, 1.0, t)


def probe_rounding(op: Any, n: int, horizon: float, precision: str | None) -> tuple[float, dict[str, Any]]:
    """The magnitude a projection of the operator computes with, seen in its own rounding of ``P(P x) = P x`` at the
    probe's unit points (module docstring): the largest spread ``max_k |P^k x − P x|`` of iterates that repeat exactly,
    below ``PULLED·|P x − x|``, divided by the precision's ``eps``; and the evidence."""
    eps = EPS_BY_PRECISION.get(precision or "float64", EPS_BY_PRECISION["float64"])
    best, where, calls = 0.0, None, 0
    for t in sorted({0.0, 0.5 * float(horizon), float(horizon)}):
        for i, d in enumerate(_directions(n)):
            P = _projection(op, d, t)
            calls += 2
            if P is None:
                continue
            try:
                first = P(d)
                move = float(np.max(np.abs(first - d)))
                seen, cur, spread, repeated = {first.tobytes()}, first, 0.0, False
                for _ in range(ROUNDING_ITERATES):
                    cur = P(cur)
                    calls += 1
                    spread = max(spread, float(np.max(np.abs(cur - first))))
                    if cur.tobytes() in seen:
                        repeated = True
                        break
                    seen.add(cur.tobytes())
            except Exception:     # noqa: BLE001 - a projection that refuses its own values shows no rounding
                continue
            if repeated and 0.0 < spread < PULLED * move and spread / eps > best:
                best, where = spread / eps, {"direction": i, "t": t, "spread": spread, "move": move}
    return best, {"rounding": best, "seen_at": where, "calls": calls, "iterates": ROUNDING_ITERATES}


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
        if n > 0 and not memo[key][0] > 0.0:          # no extent seen: the projection's own rounding
            S, evidence = probe_rounding(op, n, horizon, precision)
            if S > 0.0:
                memo[key] = (S, {**memo[key][1], **evidence})
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
    seen = (f"its projection rounds like code computing at |x| = {S:.3g} (P(P x) = P x off by "
            f"{evidence['seen_at']['spread']:.3g}, its iterates repeating)" if evidence.get("rounding")
            else f"its domain reaches |x| = {S:.3g} (J_1 of far points)")
    out = new_record(rec.check, rec.subject, UNDECIDED, seed=rec.seed, details=details,
                      counterexample=rec.counterexample,
                      message=(f"{rec.message} — but within the rounding of the operator's own scale: {seen}, "
                               f"where correct code rounds by "
                               f"rtol·(1 + {S:.3g}), and at that scale the law "
                               f"{'holds' if again.status == PASSED else 'is ' + again.status}; state the "
                               f"operator's data_scale (operator_from_resolvent(..., data_scale=...)) to decide"))
    out.duration = rec.duration
    return out


__all__ = ["finite_failure", "stated_scale", "inferred_scale", "probe_extent", "probe_rounding",
           "judged_at_data_scale"]
