"""Work–precision: which stepper gives the accuracy you need for the least work.

:func:`work_precision` runs every stepper over its controls — the step sizes of a fixed-grid stepper
(``stepper(problem, t_grid)``, uniform grids), the tolerances of a :class:`verimono.Adaptive` one — and
records, per run, the errors against the exact solution (``sup``, ``l2``, ``final``, at the stepper's own
nodes: :mod:`verimono.core.convergence`, :mod:`verimono.core.adaptive`), the number of steps and the CPU
time, timed as the performance stage times (:mod:`verimono.execution.timing`): each call's *own time* (wall
time minus its wait for a CPU), in *rounds* in which every run is timed once, the order of the runs rotating
from round to round, after one untimed warm-up run of each (the error run: JIT compilation and caches are not
the work judged); per run the median over rounds with its order-statistics bounds (the sign-test interval,
one-sided ``1 - α/4`` each — ``α/2`` per side split over the two looks below —, α =
:data:`verimono.execution.timing.ALPHA`).  That is DiffEqDevTools'
``WorkPrecisionSet`` (error against the time of the fastest of ``numruns`` solves, per tolerance), with an
interval instead of a minimum.

**The verdict** "A is at least as accurate as B for the same work, within the measured noise"
(:meth:`WorkPrecisionSet.compare`).  At a work ``W`` a stepper is credited with the best error among its
runs that cost at most ``W`` and, between two of its runs, the diagram's line (``log error`` linear in
``log work``) where that is better (:func:`envelope`); errors below the round-off floor count at the floor.
Over the range of work where both were measured — from the larger of their cheapest runs to the smaller of
their costliest (the overlap of their CPU-time ranges, or of their step-count ranges) — A *holds* when its credited error, its work taken at the upper ends of its time intervals, is nowhere above
B's with B's at the lower ends (A at least as accurate even with the noise against it); it *fails* when,
somewhere, A's credited error with its work at the lower ends is above B's with B's at the upper ends (B
more accurate for the same work even with the noise in A's favour); otherwise the noise cannot decide, and
the rounds are measured again once up to ``max_rounds`` (each look at ``α/2``, as
:func:`verimono.execution.timing.judge`), then the verdict is *undecided* with ``undecided_reason = "timing
noise"`` — which does not fail a run.  Against the number of steps there is no noise: holds or fails.  No
extrapolation: curves measured over disjoint ranges of work (a high-order stepper whose tightest run costs
less than a low-order one's loosest) are not compared — neither was run at the other's work — and the verdict
is *undecided* with ``undecided_reason = "work ranges do not overlap"`` (:data:`WORK_RANGE_REASON`), naming
both ranges and which controls would make them meet.

Records: ``work_precision[A vs B on P]`` (CPU time) and ``work_precision_steps[A vs B on P]`` for the first
stepper A against each other B, the set in ``details["work_precision"]`` (the report's diagram).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Callable, Sequence

import numpy as np

from ..core._jsonable import to_jsonable
from ..core._validate import states_shape_error
from ..core.adaptive import DEFAULT_TOLERANCES, Adaptive, own_errors, own_run
from ..core.arrays import as_float64
from ..core.convergence import exact_on, grid_errors
from ..core.display import render
from ..core.errors import InvalidCheckArgument, InvalidProblem
from ..core.grids import uniform_grid
from ..core.naming import subject_name
from ..core.problem import Problem
from ..core.tolerances import roundoff_floor
from ..execution import timing
from ..records.results import FAILED, PASSED, UNDECIDED, CheckResult, Report
from ..records.verdicts import new_record

NORMS = ("sup", "l2", "final")
#: rounds of the first look (9: the fewest whose order-statistics bounds at 97.5% one-sided leave out one
#: outlying round on each side) and the budget of a second look (:mod:`verimono.run.performance`'s)
ROUNDS, MAX_ROUNDS = 9, 27
WORKS = ("time", "steps")
#: why a comparison is undecided when the two curves were measured over disjoint ranges of work
WORK_RANGE_REASON = "work ranges do not overlap"


@dataclasses.dataclass
class Curve:
    """One stepper's work–precision curve: per control its steps, errors, and own CPU seconds (median over
    rounds, with bounds)."""

    stepper: str
    control: str
    controls: list[float]
    steps: list[int]
    errors: dict[str, list[float]]
    seconds: list[float]
    low: list[float]
    high: list[float]
    samples: list[list[float]]

    def work(self, kind: str, side: str = "median") -> np.ndarray:
        if kind == "steps":
            return np.asarray(self.steps, dtype=float)
        return np.asarray({"median": self.seconds, "low": self.low, "high": self.high}[side], dtype=float)


def envelope(work: np.ndarray, err: np.ndarray, at: np.ndarray) -> np.ndarray:
    """The error a stepper is credited with at each work in ``at``: the best error among its runs that cost at
    most that, and between two runs the diagram's line (``log err`` linear in ``log work``) where that is
    better; ``inf`` below its cheapest run (it cannot be run that cheaply)."""
    order = np.argsort(work, kind="stable")
    w, e = work[order], err[order]
    out = np.full(len(at), np.inf)
    for i, W in enumerate(at):
        ran = w <= W
        if not ran.any():
            continue
        best = float(e[ran].min())
        if W < w[-1]:
            k = int(np.searchsorted(w, W, side="right"))       # w[k-1] <= W < w[k]
            a, b = w[k - 1], w[k]
            if b > a:
                s = (math.log(W) - math.log(a)) / (math.log(b) - math.log(a))
                best = min(best, math.exp((1 - s) * math.log(e[k - 1]) + s * math.log(e[k])))
        out[i] = best
    return out


@dataclasses.dataclass
class WorkPrecisionSet:
    """The curves of several steppers on one problem (module docstring)."""

    problem: str
    curves: list[Curve]
    norm: str
    floor: float
    rounds: int
    alpha: float
    clock: str = timing.CLOCK

    def curve(self, name: str) -> Curve:
        for c in self.curves:
            if c.stepper == name:
                return c
        raise KeyError(f"no curve of {name!r}; the steppers are {[c.stepper for c in self.curves]}")

    def compare(self, a: str, b: str, work: str = "time", norm: str | None = None) -> tuple[str, str, float]:
        """``(status, message, worst)``: whether ``a`` is at least as accurate as ``b`` for the same work
        (module docstring); ``worst`` is the largest ratio of A's error to B's over the overlap, the noise
        against A (≤ 1: it holds)."""
        if work not in WORKS:
            raise InvalidCheckArgument(f"work must be one of {WORKS}, got {work!r}")
        norm = norm or self.norm
        A, B = self.curve(a), self.curve(b)
        eA = np.maximum(np.asarray(A.errors[norm], float), self.floor)
        eB = np.maximum(np.asarray(B.errors[norm], float), self.floor)
        if not (np.all(np.isfinite(eA)) and np.all(np.isfinite(eB))):
            return FAILED, "a non-finite error: nothing to compare", math.inf
        what = "CPU time" if work == "time" else "number of steps"
        sides = ("high", "low") if work == "time" else ("median", "median")
        wA_bad, wB_good = A.work(work, sides[0]), B.work(work, sides[1])          # the noise against A
        wA_good, wB_bad = A.work(work, sides[1]), B.work(work, sides[0])          # the noise for A
        if np.any(wA_bad <= 0) or np.any(wB_bad <= 0) or not (np.all(np.isfinite(wA_bad)) and np.all(np.isfinite(wB_bad))):
            return UNDECIDED, f"the {what} could not be bounded (too few rounds)", math.nan
        mA, mB = A.work(work), B.work(work)
        lo, hi = max(mA.min(), mB.min()), min(mA.max(), mB.max())
        if lo > hi:        # measured over disjoint ranges: neither is credited with what it was not run at
            return UNDECIDED, (f"{a} ran at {what} {mA.min():.3g}-{mA.max():.3g} and {b} at {mB.min():.3g}-"
                               f"{mB.max():.3g}: the curves share no range of work, so no comparison for the same "
                               f"{what} was measured ({WORK_RANGE_REASON}; give {a} {'tighter' if mA.max() < lo else 'looser'} "
                               f"controls, or {b} {'looser' if mA.max() < lo else 'tighter'} ones)"), math.nan
        every = np.concatenate([wA_bad, wB_good, wA_good, wB_bad])

        def ratios(wa: np.ndarray, wb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            """A's credited error over B's at the works both were measured at (``wa``, ``wb``: the sides)."""
            s_lo, s_hi = max(wa.min(), wb.min()), min(wa.max(), wb.max())
            if s_lo > s_hi:              # the noise leaves no common range on this side
                return np.array([math.inf]), np.array([s_lo])
            at = np.unique(np.concatenate([[s_lo, s_hi], every[(every >= s_lo) & (every <= s_hi)]]))
            return envelope(wa, eA, at) / envelope(wb, eB, at), at

        against, _ = ratios(wA_bad, wB_good)             # the noise against A
        favour, at_f = ratios(wA_good, wB_bad)           # the noise for A
        favour = np.where(np.isfinite(favour), favour, 0.0)   # no common range with the noise for A: no failure seen
        worst = float(against.max())
        k = int(np.argmax(favour))
        rng = f"{what} {lo:.3g}-{hi:.3g}, where both were measured"
        if worst <= 1.0:
            noise = ", within the measured noise" if work == "time" else ""
            return PASSED, (f"{a} is at least as accurate as {b} for the same {what}{noise} ({norm} error at most "
                            f"{worst:.3g}x {b}'s over {rng})"), worst
        if favour[k] > 1.0:
            noise = f" even with the timing noise in {a}'s favour" if work == "time" else ""
            return FAILED, (f"{b} is more accurate than {a} for the same {what}: at {at_f[k]:.3g} its {norm} error is "
                            f"{favour[k]:.3g}x smaller{noise} (over {rng})"), worst
        return UNDECIDED, (f"the timing noise cannot decide whether {a} is at least as accurate as {b} for the same "
                           f"{what}: with the noise against {a} its {norm} error reaches {worst:.3g}x {b}'s, with the "
                           f"noise for it {favour.max():.3g}x (over {rng})"), worst

    def verdicts(self, subject: str | None = None) -> list[dict[str, Any]]:
        """The comparisons of the first stepper (or ``subject``) against each other, on both works: dicts with
        ``subject`` ("A vs B on P"), ``baseline``, ``work``, ``status``, ``message``, ``worst``."""
        first = subject or self.curves[0].stepper
        out = []
        for c in self.curves:
            if c.stepper == first:
                continue
            for work in WORKS:
                status, msg, worst = self.compare(first, c.stepper, work)
                out.append({"subject": f"{first} vs {c.stepper} on {self.problem}", "baseline": c.stepper,
                            "work": work, "status": status, "message": msg, "worst": worst})
        return out

    def records(self, subject: str | None = None) -> list[CheckResult]:
        """The verdicts as records: ``work_precision`` (CPU time; the set in ``details["work_precision"]``)
        and ``work_precision_steps``; a time verdict left to the noise is undecided for ``"timing noise"``."""
        out = []
        for v in self.verdicts(subject):
            details: dict[str, Any] = {"work": v["work"], "norm": self.norm, "baseline": v["baseline"]}
            if v["status"] == UNDECIDED and WORK_RANGE_REASON in v["message"]:
                details["undecided_reason"] = WORK_RANGE_REASON
            elif v["status"] == UNDECIDED and v["work"] == "time" and "noise" in v["message"]:
                details["undecided_reason"] = timing.NOISE_REASON
            if v["work"] == "time":
                details["work_precision"] = self.to_dict()
            worst = v["worst"]
            out.append(new_record("work_precision" if v["work"] == "time" else "work_precision_steps",
                                  v["subject"], v["status"], worst=worst if math.isfinite(worst) else None,
                                  bound=1.0 if math.isfinite(worst) else None, message=v["message"],
                                  details=details))
        return out

    def __repr__(self) -> str:
        lines = [f"WorkPrecisionSet({self.problem}; {self.norm} error; {self.rounds} rounds, clock {self.clock})"]
        for c in self.curves:
            lines.append(f"  {c.stepper} ({c.control}s)")
            for i, x in enumerate(c.controls):
                lines.append(f"    {x:>10.3g}  {c.steps[i]:>7d} steps  {c.errors[self.norm][i]:.3e}  "
                             f"{c.seconds[i]:.3e} s [{c.low[i]:.3e}, {c.high[i]:.3e}]")
        for r in self.records():
            lines.append(f"  {r.status}: {r.message}")
        return "\n".join(lines)

    def _repr_html_(self) -> str | None:
        return render("work_precision_html", self.to_dict())

    def plot(self, ax: Any = None) -> Any:
        """The report's diagram (error against CPU time, with the time intervals) as a matplotlib figure."""
        return render("work_precision_figure", self.to_dict(), ax)

    def to_dict(self) -> dict[str, Any]:
        return to_jsonable({**dataclasses.asdict(self), "verdicts": self.verdicts()})

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "WorkPrecisionSet":
        curves = [Curve(**c) for c in d["curves"]]
        return cls(d["problem"], curves, d["norm"], float(d["floor"]), int(d["rounds"]), float(d["alpha"]),
                   d.get("clock", timing.CLOCK))


class _Run:
    """One (stepper, control): its error run, then its timed calls."""

    def __init__(self, stepper: Any, problem: Problem, control: float) -> None:
        self.stepper, self.problem, self.control = stepper, problem, control
        if isinstance(stepper, Adaptive):
            self.call: Callable[[], Any] = lambda: own_run(stepper, problem, control)
        else:
            grid = uniform_grid(problem.T, float(control))
            self.grid = grid
            self.call = lambda: stepper(problem, grid)

    def errors(self) -> tuple[dict[str, float], int, float]:
        if isinstance(self.stepper, Adaptive):
            run = own_run(self.stepper, self.problem, self.control)
            e, scale = own_errors(run, self.problem)
            return e, run.steps, scale
        x = np.asarray(as_float64(self.stepper(self.problem, self.grid)), dtype=float)
        if x.shape != (len(self.grid),) + self.problem.x0.shape:
            raise states_shape_error(subject_name(self.stepper), x.shape, len(self.grid), self.problem.x0.shape)
        ref = exact_on(self.problem, self.grid)
        return grid_errors(self.grid, x, ref), len(self.grid) - 1, float(np.max(np.abs(ref)))


def _controls_of(stepper: Any, problem: Problem, given: Any) -> tuple[str, list[float]]:
    if isinstance(stepper, Adaptive):
        kind = stepper.control
        cs = given or stepper.tolerances or (DEFAULT_TOLERANCES if kind == "tolerance" else problem.steps)
    else:
        kind, cs = "step", given or problem.steps
    if not cs or len(cs) < 2:
        raise InvalidCheckArgument(f"{subject_name(stepper)} needs at least two {kind}s for a curve")
    return kind, [float(c) for c in cs]


def work_precision(steppers: Sequence[Any], problem: Problem, *, controls: Any = None, norm: str = "sup",
                   rounds: int = ROUNDS, max_rounds: int = MAX_ROUNDS, alpha: float = timing.ALPHA
                   ) -> WorkPrecisionSet:
    """The work–precision set of ``steppers`` on ``problem`` (module docstring).

    ``steppers``: fixed-grid steppers (``stepper(problem, t_grid)``; their controls are step sizes, default
    ``problem.steps``) and :class:`verimono.Adaptive` ones (tolerances, default their own); ``controls``: one
    list for all, or a dict ``{stepper name: list}``.  The problem needs an exact solution.  ``rounds`` timed
    rounds, once more up to ``max_rounds`` when a comparison of the first stepper is left to the noise."""
    if isinstance(steppers, (str, bytes)) or not hasattr(steppers, "__iter__"):
        raise InvalidCheckArgument(f"work_precision takes a list of steppers, got {type(steppers).__name__}")
    steppers = list(steppers)
    for s in steppers:
        if not callable(s) or isinstance(s, type):
            raise InvalidCheckArgument(f"work_precision: a stepper must be callable, got {s!r:.60}")
    if not isinstance(problem, Problem):
        raise InvalidCheckArgument(f"work_precision takes one verimono.Problem, got {type(problem).__name__}")
    for what, v in (("rounds", rounds), ("max_rounds", max_rounds)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
            raise InvalidCheckArgument(f"{what} must be a whole number, got {v!r}")
    if isinstance(alpha, bool) or not isinstance(alpha, (int, float, np.floating)) or not 0.0 < alpha < 1.0:
        raise InvalidCheckArgument(f"alpha (the tests' level) must be a number in (0, 1), got {alpha!r}")
    if controls is not None and (isinstance(controls, (str, bytes)) or not hasattr(controls, "__iter__")):
        raise InvalidCheckArgument(f"controls must be a list (or a dict of lists by stepper name), got {controls!r:.60}")
    if len(steppers) < 2:
        raise InvalidCheckArgument("work_precision compares at least two steppers")
    names = [subject_name(s) for s in steppers]
    if len(set(names)) != len(names):
        raise InvalidCheckArgument(f"the steppers' names must differ (they label the curves): {names}")
    if problem.exact is None:
        raise InvalidProblem(f"{problem.name} has no exact solution: work_precision measures errors against it")
    if norm not in NORMS:
        raise InvalidCheckArgument(f"norm must be one of {NORMS}, got {norm!r}")
    if rounds < 1 or max_rounds < rounds:
        raise InvalidCheckArgument(f"rounds must be ≥ 1 and max_rounds ≥ rounds, got {rounds}, {max_rounds}")
    runs: list[tuple[int, _Run]] = []
    info = []
    scale = 1.0
    for i, s in enumerate(steppers):
        given = controls.get(names[i]) if isinstance(controls, dict) else controls
        kind, cs = _controls_of(s, problem, given)
        errs, steps = [], []
        for c in cs:
            r = _Run(s, problem, c)
            e, n, sc = r.errors()              # the untimed warm-up run
            errs.append(e)
            steps.append(n)
            scale = max(scale, sc)
            runs.append((i, r))
        info.append((kind, cs, steps, {k: [e[k] for e in errs] for k in NORMS}))
    samples: list[list[float]] = [[] for _ in runs]

    def more(k: int) -> None:
        done = len(samples[0])
        for rnd in range(done, done + k):
            order = list(range(len(runs)))
            shift = (rnd * 7) % len(order)                    # rotate the order from round to round
            order = order[shift:] + order[:shift]
            if rnd % 2:
                order.reverse()
            for j in order:
                samples[j].append(timing.timed(runs[j][1].call)[1].own)

    def build(a: float) -> WorkPrecisionSet:
        curves = []
        for i, s in enumerate(steppers):
            kind, cs, steps, errors = info[i]
            idx = [j for j, (owner, _) in enumerate(runs) if owner == i]
            med, low, high = zip(*(timing.median_interval(samples[j], a) for j in idx))
            curves.append(Curve(names[i], kind, cs, steps, errors, list(med), list(low), list(high),
                                [list(samples[j]) for j in idx]))
        return WorkPrecisionSet(problem.name, curves, norm, roundoff_floor(scale), len(samples[0]), a)

    looks = 1 if max_rounds == rounds else 2
    more(rounds)
    wp = build(alpha / 2 / looks)
    if looks == 2 and any(r.status == UNDECIDED and r.details.get("undecided_reason") for r in wp.records()):
        more(max_rounds - rounds)
        wp = build(alpha / 2 / looks)
    return wp


def compare_report(steppers: Sequence[Any], problems: Sequence[Problem], **kw: Any) -> Report:
    """The records of :func:`work_precision` on every problem (``verimono compare``)."""
    report = Report()
    for p in problems:
        wp = work_precision(steppers, p, **kw)
        for rec in wp.records():
            report.add(rec)
    return report


__all__ = ["work_precision", "WorkPrecisionSet", "Curve", "compare_report", "ROUNDS", "MAX_ROUNDS"]
