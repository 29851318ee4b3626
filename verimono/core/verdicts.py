"""The verdict of a convergence study, as a numerical analyst would sign it (``thm:main``'s order, or a claim's).

The data: the sup-norm error ``e_i`` of each grid, its floor (round-off in the stepper's precision, plus what a
stated ``solve_tol`` accumulates), the expected order ``p``.  Grids are read coarse to fine; a grid is *usable*
when its error lies above its floor, and the *local slope* of a refinement is ``log(e_i/e_{i+1}) / log(h_i/h_{i+1})``
between successive usable grids.

* **Exact** — every error at its floor, down to the coarsest grid the study could try: the scheme reproduces the
  solution at the nodes to round-off (it exceeds every order).
* **Too coarse a look** — fewer than ``MIN_GRIDS`` usable grids: the study coarsens first
  (:mod:`verimono.core.grid_design`); with fewer than three after that, the verdict is *undecided* with what was
  tried: no asymptotic range above the floor within the budget, a limit of the study, never the stepper's.
* **Falling short** — a refinement whose local slope is below ``SHORTFALL · p`` while its finer error lies
  ``STALL_MARGIN`` times above the floor (a *stall* when the slope is below ``STALL_FRACTION · min(p, 1)``: the
  error stopped falling).  When the finest refinement falls short after coarser ones that did not, the regime
  changed at the fine end: the study refines once or twice more before any verdict.  If the shortfall persists,
  the stepper fails ("the errors stall at 4.69e-3 over the last 3 refinements"); if the errors resume, the pause
  was pre-asymptotic and the verdict rests on the grids after it; if no finer grid could be tried (fixed grids,
  a step range), it is undecided.  "Reaches" never rests on a finest local slope near 0.
* **The order at the fine end** — a claimed order is met only when the finest local slopes reach it
  (:func:`verimono.core.order_fit.finest_slopes`, on the usable grids after the last shortfall, the finest
  ``WINDOW`` of them): the finest slope the floor cannot move, with an interval of its drift (where the slopes
  follow a trend, how far they can still move) and its scatter (how far they jump).  Passed when the interval
  reaches ``p`` (its lower end, or its upper end once the slopes have settled); failed when it lies below ``p``
  and the two finest slopes lie ``FAIL_MARGIN · min(p, 1)`` below it ("order 2.03 measured, 3 claimed": a scheme
  of order ``q`` claimed as ``q + 1``); in between the slopes still move — the study refines, and without a finer
  grid the verdict is undecided.  A fit over the window averages the coarse end with the fine end (local slopes
  3.50, 2.14, 2.03 fit as 2.46 [1.46, 3.46], which passed a claim of 3): it is reported, and decides only for
  erratic slopes (noise, on at least four refinements, after every refinement the study could make).
* **Exact to a floor nobody stated** — errors at no more than ``FLOOR_LEVEL`` of the solution's scale on every
  grid, flat within ``FLAT_SPAN`` and not falling, or (an inner solve's noise, which spreads them anywhere below its
  tolerance) without a trend either way (least-squares slope within ``± SHORTFALL · min(p, 1)``), are an inner
  solve's tolerance or rounding: exact to that floor, a pass said as such.
* **A floor nobody stated, reached** — errors that stop falling at no more than ``SOLVE_LEVEL`` times the
  solution's scale (not flat on every grid) are the mark of an inner solve's tolerance, not of a discretisation:
  without a stated ``solve_tol`` the verdict is *undecided* with the advice to state it (``Stepper(...,
  solve_tol=τ)``, ``verimono check --solve-tol τ``), never failed; a stall well above that level still fails.
* A non-finite error on a grid the study was given fails (the stepper diverged); on a grid it added itself it is
  left out (an explicit scheme outside its stability region at ``K = 2``).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Sequence

import numpy as np

from .order_fit import (ASYMPTOTIC_SPREAD, ORDER_SLACK, FinestSlopes, OrderFit, finest_slopes, fit_order,
                        least_squares_slope)
from .problem import Order

PASSED, FAILED, UNDECIDED = "passed", "failed", "undecided"
#: a refinement falls short when its local slope is below this fraction of the order (far above the floor)
SHORTFALL = 0.5
#: ... and stalls when below this fraction of min(p, 1): the errors stopped falling
STALL_FRACTION = 0.25
#: a shortfall is judged only on errors this many times above their floor (closer to it, rounding and an inner
#: solve's tolerance flatten any scheme's errors)
STALL_MARGIN = 100.0
#: errors that stop falling at no more than this fraction of the solution's scale, on the grids where they stop,
#: are an inner solve's floor the user did not state: undecided with that advice, never failed
SOLVE_LEVEL = 1e-6
#: errors flat on every grid (spread by at most ``FLAT_SPAN``, not falling at a quarter of the order) at no more
#: than this fraction of the solution's scale are a floor — an inner solve's tolerance, rounding accumulated
#: over many steps —, not a discretisation error: the scheme is exact to that floor (a passing verdict).  A
#: discretisation error that stays put (a wrong limit) is far above it: 1e-8 is 1e4 times round-off in float64
#: and below what any step of the catalog's studies leaves to a consistent scheme of order 1 or more
FLOOR_LEVEL = 1e-8
#: ... flat: the largest error at most this many times the smallest
FLAT_SPAN = 10.0
#: a fit rests on at most this many grids, the finest (the asymptotic range is at the fine end)
WINDOW = 5
#: below this many grids above the floor the study coarsens, when it may (grid_design.MIN_GRIDS)
MIN_GRIDS = 4


@dataclasses.dataclass
class Decision:
    """A study's verdict: ``status`` (passed, failed, undecided), the ``message`` a reader signs, the grids the
    fit rests on (``window``, indices of the study's grids) and its ``fit``, ``worst`` (the record's ratio, > 1
    failing), and ``action`` — ``"coarsen"`` or ``"refine"``: what the study would try next, budget permitting."""

    status: str
    message: str
    worst: float = 0.0
    window: list[int] = dataclasses.field(default_factory=list)
    fit: OrderFit | None = None
    action: str | None = None

    @property
    def ok(self) -> bool:
        return self.status == PASSED


@dataclasses.dataclass
class StudyData:
    """What a verdict is decided from (a :class:`verimono.core.convergence.ConvergenceStudy` provides it)."""

    mesh: Sequence[float]
    steps: Sequence[int]
    errors: Sequence[float]
    floors: Sequence[float]
    expected: Order | None
    scale: float = 1.0
    solve_tol: float | None = None
    claimed: float | None = None
    #: indices of the grids the study added itself (coarsening, refining)
    added: Sequence[int] = ()
    #: how many times the study refined beyond the grids it was given
    refined: int = 0
    #: whether the study may still coarsen / refine (the verdict then asks for it instead of deciding)
    can_coarsen: bool = False
    can_refine: bool = False
    #: what the stepper raised on a grid the study added, by grid index
    failures: dict[int, str] = dataclasses.field(default_factory=dict)


def decide(d: StudyData) -> Decision:
    """The verdict on ``d`` (module docstring)."""
    e, h, fl = np.asarray(d.errors, float), np.asarray(d.mesh, float), np.asarray(d.floors, float)
    exp = d.expected
    added = set(d.added)
    bad = [i for i in range(len(e)) if not math.isfinite(e[i]) and i not in added]
    if bad:
        where = ", ".join(f"{e[i]} at h={h[i]:.3g}" for i in bad[:4])
        return Decision(FAILED, f"non-finite error: sup error {where} (the stepper diverged or returned non-finite "
                                "values)", math.inf)
    if exp is None:
        return Decision(PASSED, "no expected order stated")
    at = "the stated solve tolerance" if d.solve_tol else "round-off"
    grids = sorted((i for i in range(len(e)) if math.isfinite(e[i])), key=lambda i: -h[i])     # coarse to fine
    if exp.exact:
        worst = max((e[i] for i in grids), default=0.0)
        ok = all(e[i] <= fl[i] for i in grids)
        if not ok and _flat_floor(d, h, e, fl, grids, None) is not None:
            return _exact_to_detected(d, h, e, fl, grids, _skipped(d, added, e))
        ratio = max((e[i] / fl[i] for i in grids if fl[i] > 0), default=0.0)
        return Decision(PASSED if ok else FAILED,
                        f"errors at {at} (max {worst:.2e} ≤ floor {max(fl):.2e})" if ok else
                        f"expected exact at the nodes, max error {worst:.2e} > floor {max(fl):.2e}", ratio)
    p = float(exp.value)
    what = "claimed" if d.claimed is not None else "expected"
    skipped = _skipped(d, added, e)
    given = [i for i in grids if i not in added]
    exact_on_given = bool(given) and all(e[i] <= fl[i] for i in given)
    usable = _usable_run(grids, e, fl)
    if usable and _flat_floor(d, h, e, fl, grids, p) is not None:
        if d.can_coarsen:
            return Decision(UNDECIDED, "errors flat at a floor: coarser grids needed", action="coarsen")
        return _exact_to_detected(d, h, e, fl, grids, skipped)
    if not usable:
        if d.can_coarsen:
            return Decision(UNDECIDED, "every error at the floor: coarser grids needed", action="coarsen")
        return _exact(d, e, fl, grids, grids, skipped)
    if len(usable) < MIN_GRIDS and d.can_coarsen:
        return Decision(UNDECIDED, "too few grids above the floor: coarser grids needed", action="coarsen")
    slopes = [_slope(h, e, a, b) for a, b in zip(usable[:-1], usable[1:])]
    stall_slope = STALL_FRACTION * min(p, 1.0)
    # a finer grid at the floor after the usable run: the errors fell to the floor, nothing stalls at the fine end
    to_floor = usable[-1] != grids[-1]
    can_refine = d.can_refine and not to_floor
    short = [j for j, s in enumerate(slopes) if s < SHORTFALL * p and e[usable[j + 1]] > STALL_MARGIN * fl[usable[j + 1]]]
    finest_short = bool(short) and short[-1] == len(slopes) - 1 and not to_floor
    erratic = False
    if finest_short and len(short) < len(slopes):
        # the regime changed at the fine end: refine before any verdict
        if can_refine:
            return Decision(UNDECIDED, "the finest refinement falls short: a finer grid needed", action="refine")
        trailing = len(slopes) - max(j for j in range(len(slopes)) if j not in short) - 1
        if d.refined == 0 or trailing >= 2:     # no finer grid tried, or the shortfall persisted on a finer one
            return _short_at_the_end(d, h, e, usable, slopes, short, p, what, stall_slope, skipped)
        erratic = True          # it resumed on a finer grid, then fell short again: the fit's interval decides
    elif finest_short and slopes[-1] < stall_slope and can_refine:
        # no grid shows the order and the finest stalls: a plateau not yet resolved may resume on finer grids
        return Decision(UNDECIDED, "the errors stall from the coarsest grid on: a finer grid needed", action="refine")
    paused = bool(short) and not finest_short
    tail = usable[short[-1] + 1:] if paused else usable      # the grids after the last pause
    window = (tail if len(tail) >= 3 else usable)[-WINDOW:]
    if len(window) < 3:
        if can_refine:
            return Decision(UNDECIDED, "too few grids to fit: a finer grid needed", action="refine")
        if exact_on_given:
            return _exact(d, e, fl, given, grids, skipped)
        return Decision(UNDECIDED, f"too few points above {at} to estimate an order ({len(usable)} of {len(grids)} "
                                   f"grids above the floor: {_tried(d, grids)}): no asymptotic range above the floor "
                                   f"within the study's budget{skipped}; give a step range where the errors lie above "
                                   f"{max(fl):.2e}", window=window)
    fit = fit_order(h, e, fl, within=window)
    fine = finest_slopes(h, e, fl, window)
    if paused:
        # after a pause the errors resume at the order, or catch up with it first (a pause and the refinement after
        # it then merge into one at the order): the reading whose slopes agree best
        paused_at = {usable[j + 1] for j in short} - {usable[-1]}
        steady = [i for i in usable if i not in paused_at]
        if len(steady) >= 3:
            fine = min(fine, finest_slopes(h, e, fl, steady[-WINDOW:]), key=lambda f: f.spread)
    win_slopes = slopes[len(slopes) - len(window) + 1:]
    # erratic slopes (up and down, on at least four refinements) after every refinement the study could make
    noisy = len(window) >= 4 and (erratic or (fine.erratic and len(fine.slopes) >= 4 and not can_refine))
    note = ""
    noise = (" (erratic local slopes, coarse to fine: " + ", ".join(f"{s:.2f}" for s in win_slopes)
             + (": the errors fell short, resumed on a finer grid and fell short again" if erratic else "")
             + "; judged on the fit's interval)")
    if paused and window[0] == tail[0]:
        note = (f" (pre-asymptotic: the errors paused at {e[tail[0]]:.3g} (h = {h[tail[0]]:.3g}) and resumed; "
                f"judged on the {len(window)} grids from there)")
    elif paused:
        note = (f" (the errors paused at {e[tail[0]]:.3g} (h = {h[tail[0]]:.3g}) and resumed, on too few grids to fit "
                "alone; judged on all)")
    at_end = _at_the_end(fine)
    # never on a finest refinement falling short (unless the slopes are erratic)
    guard = not (finest_short and not erratic)
    if guard and fine.reaches(p):
        # the order at the fine end is said where the fit over the window tells another story
        said = f"; {at_end}" if fit.pre_asymptotic or abs(fit.slope - fine.slope) > ORDER_SLACK else ""
        return Decision(PASSED, f"measured {fit}, {what} {p:g}{said}{note}{skipped}", _ratio(p, fine.high),
                        window, fit)
    if guard and noisy and not fine.below(p) and _fit_holds(fit, p):
        return Decision(PASSED, f"measured {fit}, {what} {p:g}{noise}{skipped}", _ratio(p, fit.high), window, fit)
    if paused and len(tail) < 3 and can_refine:     # the errors resumed after a pause: see them go on
        return Decision(UNDECIDED, "too few grids after the pause: a finer grid needed", action="refine")
    if exact_on_given:          # never failed on the coarse grids the study added below exact ones
        return _exact(d, e, fl, given, grids, skipped)
    if finest_short and not erratic and win_slopes[-1] < stall_slope:
        return _not_falling(d, h, e, usable, slopes, p, what, skipped, fit, window)
    if not fine.below(p):
        # the interval of the finest slope holds p but is wide: the slopes still move (pre-asymptotic), or are noise
        if can_refine:
            return Decision(UNDECIDED, "the finest local slopes still move: a finer grid needed", action="refine")
        return Decision(UNDECIDED, f"{at_end}, {what} {p:g}: the local slopes still move, and no finer grid could "
                                   "be tried (fixed grids, the end of the step range or of the study's budget, or the "
                                   f"floor: {_tried(d, grids)}); the fit over "
                                   f"h = {h[window[0]]:.3g} ... {h[window[-1]]:.3g} measures {fit}, which averages the "
                                   f"coarse end with the fine end{noise if noisy else note}{skipped}", window=window,
                                   fit=fit)
    return _measured_below(d, h, e, fit, fine, window, p, what, stall_slope, skipped)


def _at_the_end(fine: FinestSlopes) -> str:
    """The order at the fine end, as a numerical analyst reads it off the local slopes."""
    return (f"order {fine} at the fine end (local slopes, coarse to fine: "
            + ", ".join(f"{s:.2f}" for s in fine.slopes[-4:]) + f"; the finest on h {fine.h[0]:.3g} -> {fine.h[1]:.3g})")


def _fit_holds(fit: OrderFit, p: float) -> bool:
    """Erratic slopes (noise, not a trend) are averaged by the fit: its interval reaches ``p`` and its slope lies
    within ``ASYMPTOTIC_SPREAD`` of it (an interval alone, on four or five noisy grids, reaches almost anything)."""
    return fit.reaches(p) and fit.slope + ORDER_SLACK >= p - ASYMPTOTIC_SPREAD


def shortfall_grids(d: StudyData) -> list[int]:
    """The grids at the fine end of a refinement whose errors fell short of the order far above the floor (a
    pause, a stall): where the stepper did not behave as its order says, and the step laws should look."""
    e, h, fl = np.asarray(d.errors, float), np.asarray(d.mesh, float), np.asarray(d.floors, float)
    if d.expected is None or d.expected.exact:
        return []
    p = float(d.expected.value)
    grids = sorted((i for i in range(len(e)) if math.isfinite(e[i])), key=lambda i: -h[i])
    usable = _usable_run(grids, e, fl)
    return [b for a, b in zip(usable[:-1], usable[1:])
            if _slope(h, e, a, b) < SHORTFALL * p and e[b] > STALL_MARGIN * fl[b]]


def _usable_run(grids: Sequence[int], e: np.ndarray, fl: np.ndarray) -> list[int]:
    """The longest run of successive grids (coarse to fine) whose errors lie above their floors, the finest of
    equal runs: the range an order can be read from (a grid at the floor between them is a coincidence or
    the end of the range; above-floor errors past it are rounding)."""
    runs, run = [], []
    for i in grids:
        if e[i] > fl[i]:
            run.append(i)
        elif run:
            runs.append(run)
            run = []
    if run:
        runs.append(run)
    return max(reversed(runs), key=len) if runs else []


def _exact(d: StudyData, e: np.ndarray, fl: np.ndarray, at_floor: Sequence[int], grids: Sequence[int],
           skipped: str) -> Decision:
    """Every error of ``at_floor`` at its floor: exact at the nodes (to the stated solve tolerance)."""
    coarse = [i for i in grids if i not in at_floor]
    aside = (f"; the coarser grids the study tried (K = {', '.join(str(d.steps[i]) for i in coarse)}) are "
             "pre-asymptotic" if coarse else "")
    where = f"every grid down to K = {d.steps[at_floor[0]]} cells" if at_floor else "every grid"
    if d.solve_tol:
        return Decision(PASSED, f"exact to the stated solve tolerance {d.solve_tol:g}: every error at its floor on "
                                f"{where} (max {max(e[i] for i in at_floor):.2e} ≤ {max(fl):.2e}){aside}{skipped}")
    return Decision(PASSED, f"errors at round-off on {where}: exceeds every order{aside}{skipped}")


def _flat_floor(d: StudyData, h: np.ndarray, e: np.ndarray, fl: np.ndarray, grids: Sequence[int],
               p: float | None) -> float | None:
    """The level of a floor the errors sit at on every grid (``FLOOR_LEVEL``), or ``None``: at least three grids,
    every error at most ``FLOOR_LEVEL`` of the solution's scale (errors at or below their round-off floor count as
    that floor), and either spread by at most ``FLAT_SPAN`` and (for an order ``p``) not falling at
    ``SHORTFALL · min(p, 1)``, or (for an order ``p``) without a trend either way: their least-squares slope in
    ``log h`` within ``± SHORTFALL · min(p, 1)``.  An inner solve stopped at its tolerance leaves errors anywhere
    below it, not flat: solve_nivp's trapezoidal rule on t|x| (exact for the quadratic solution) left a Newton
    solve's 8e-12 ... 9.5e-11 on K = 9 ... 2560 and 1e-16 on K = 2, 4 (slope -0.20), which were read as slopes
    ("measured 0.769 [0.170, 1.369]", passed; from x0 = -0.7 undecided; probe8).  Errors that rise with ``K``
    (an inner solve's ``K τ`` accumulating, slope -1) do not vanish as ``h → 0``: no floor (undecided, the advice
    to state ``solve_tol``)."""
    if len(grids) < 3:
        return None
    v = np.array([max(float(e[i]), float(fl[i])) for i in grids])
    top = float(v.max())
    if not (0.0 < top <= FLOOR_LEVEL * max(d.scale, 1e-300)):
        return None
    flat = top <= FLAT_SPAN * float(v.min())
    if p is None:
        return top if flat else None
    slope, _ = least_squares_slope(np.log(h[list(grids)]), np.log(v))
    band = SHORTFALL * min(p, 1.0)
    return top if slope < band and (flat or slope > -band) else None


def _exact_to_detected(d: StudyData, h: np.ndarray, e: np.ndarray, fl: np.ndarray, grids: Sequence[int],
                       skipped: str) -> Decision:
    """Every error at a floor the user did not state, not falling (:func:`_flat_floor`): exact to it, said as
    such."""
    v = [max(float(e[i]), float(fl[i])) for i in grids]
    top, low = max(v), min(v)
    said = (f"above the floor its stated solve tolerance {d.solve_tol:g} sets" if d.solve_tol else
            "a floor nobody stated")
    return Decision(PASSED, f"exact to the floor: the errors stay at {low:.2e} to {top:.2e} without falling (at most "
                            f"{top / max(d.scale, 1e-300):.1g} of the solution's scale {d.scale:.3g}) on every grid down "
                            f"to K = {d.steps[grids[0]]} cells, {said} — the level of an inner solve's tolerance or of "
                            "rounding, not of a discretisation (state it: verimono.Stepper(..., solve_tol=tau), verimono "
                            f"check --solve-tol tau){skipped}", 0.0)


def _measured_below(d, h, e, fit, fine, window, p, what, stall_slope, skipped) -> Decision:
    """The finest local slopes sit below the order, their whole interval below it: the order they show is
    reported (the fit over the window may still "reach" the order, pre-asymptotic from above)."""
    msg = (f"order {fine.slope:.2f} measured, {p:g} {what} ({_at_the_end(fine)}: its interval "
           f"[{fine.low:.2f}, {fine.high:.2f}] lies below {p:g}; fit {fit} on h = {h[window[0]]:.3g} ... "
           f"{h[window[-1]]:.3g}){skipped}")
    decision = Decision(FAILED, msg, _ratio(p, fine.high), window, fit)
    if fine.slope < stall_slope:
        return _unstated_floor(d, e, window[-2:], decision)
    return decision


def _not_falling(d, h, e, usable, slopes, p, what, skipped, fit, window) -> Decision:
    a, b = usable[-2], usable[-1]
    msg = (f"the errors stall far above the floor: {e[a]:.3g} -> {e[b]:.3g} over the finest refinement (h {h[a]:.3g} "
           f"-> {h[b]:.3g}) where order {p:g} predicts {e[a] * (h[b] / h[a]) ** p:.3g}; order {fit.slope:.2f} "
           f"measured, {p:g} {what}{skipped}")
    return _unstated_floor(d, e, [a, b], Decision(FAILED, msg, _ratio(p, max(slopes[-1], 0.0)), window, fit))


def _short_at_the_end(d, h, e, usable, slopes, short, p, what, stall_slope, skipped) -> Decision:
    """The finest refinement falls short after coarser ones that did not, and no finer grid can be tried: failed
    when the study refined and the shortfall persisted on a finer grid, undecided when it could not refine."""
    run = 0
    for j in reversed(range(len(slopes))):
        if j not in short:
            break
        run += 1
    tail = slopes[len(slopes) - run:]
    a, b = usable[len(slopes) - run], usable[-1]
    stalled = max(tail) < stall_slope
    change = (f"the errors {'stall' if stalled else 'fall short of the order'} far above the floor: {e[a]:.3g} -> "
              f"{e[b]:.3g} over the last {run} refinement{'s' if run > 1 else ''} (h {h[a]:.3g} -> {h[b]:.3g}; local "
              f"slope{'s' if run > 1 else ''} " + ", ".join(f"{x:.2f}" for x in tail)
              + f") where order {p:g} predicts {e[a] * (h[b] / h[a]) ** p:.3g}, after falling at order "
              f"{_mean(slopes[:len(slopes) - run]):.2f} on the coarser grids")
    if d.refined == 0:
        return Decision(UNDECIDED, f"{change}; no finer grid could be tried (fixed grids or the end of the step "
                                   f"range) to tell a stall from a pre-asymptotic pause{skipped}")
    more = f"refined {d.refined} more time{'s' if d.refined > 1 else ''}"
    if stalled:
        msg = f"{change}; {more}: the stall persists{skipped}"
        return _unstated_floor(d, e, [a, b], Decision(FAILED, msg, _ratio(p, max(slopes[-1], 0.0))))
    fit = fit_order(h, e, d.floors, within=usable[len(slopes) - run:])
    msg = (f"order {fit.slope:.2f} measured, {p:g} {what} (on the {run + 1} finest grids, h {h[a]:.3g} -> {h[b]:.3g}; "
           f"{change}; {more}: the shortfall persists){skipped}")
    return Decision(FAILED, msg, _ratio(p, fit.high if math.isfinite(fit.high) else fit.slope))


def _unstated_floor(d: StudyData, e: np.ndarray, where: Sequence[int], decision: Decision) -> Decision:
    """A failure of errors that stopped falling at an inner solve's level is undecided, with the advice."""
    if d.solve_tol or not where:
        return decision
    level = max(float(e[i]) for i in where)
    if level > SOLVE_LEVEL * max(d.scale, 1e-300):
        return decision
    return Decision(UNDECIDED, f"the errors stop falling at {level:.2e}, at most {SOLVE_LEVEL:g} of the solution's "
                               f"scale ({d.scale:.3g}): the level of an inner solve's tolerance, not of a discretisation. "
                               "State the accuracy of the stepper's inner solve (verimono.Stepper(..., solve_tol=tau), "
                               "verimono check --solve-tol tau) to have the errors judged against the floor it sets "
                               f"[{decision.message}]", decision.worst, decision.window, decision.fit)


def _slope(h, e, a, b) -> float:
    return float(math.log(e[a] / e[b]) / math.log(h[a] / h[b])) if h[a] != h[b] else math.nan


def _ratio(p: float, reached: float) -> float:
    if not math.isfinite(reached):
        return math.inf if reached != reached else 0.0
    return p / (reached + ORDER_SLACK) if reached + ORDER_SLACK > 0 else math.inf


def _interval(fit: OrderFit) -> str:
    return "n/a" if math.isnan(fit.low) else f"[{fit.low:.2f}, {fit.high:.2f}]"


def _mean(xs: Sequence[float]) -> float:
    return float(np.mean(xs)) if len(xs) else math.nan


def _tried(d: StudyData, grids: Sequence[int]) -> str:
    e = np.asarray(d.errors, float)
    shown = ", ".join(f"K={d.steps[i]}: {e[i]:.2e}" for i in grids[:8])
    return shown + (f" and {len(grids) - 8} more" if len(grids) > 8 else "")


def _skipped(d: StudyData, added: set, e: np.ndarray) -> str:
    left = sorted(i for i in added if not math.isfinite(e[i]))
    if not left:
        return ""
    h = np.asarray(d.mesh, float)
    why = "; ".join(f"h={h[i]:.3g}: {d.failures.get(i, 'non-finite error')}" for i in left[:3])
    return f" [left out: the coarse grids the study added where the stepper failed ({why})]"


__all__ = ["Decision", "StudyData", "decide", "shortfall_grids", "PASSED", "FAILED", "UNDECIDED", "SHORTFALL", "STALL_FRACTION",
           "STALL_MARGIN", "SOLVE_LEVEL", "FLOOR_LEVEL", "FLAT_SPAN", "WINDOW", "MIN_GRIDS"]
