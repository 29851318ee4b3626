"""Laws of steppers that choose their own steps (:class:`verimono.Adaptive`).

* ``tolerance_rate`` — the tolerance study (:func:`verimono.core.adaptive.tolerance_study`): the error falls
  like ``tol^rate`` and like ``N^-order`` as claimed, the number of steps responds to the tolerance, the
  errors do not stall (Theorem ``thm:main``: the limit of the scheme as the mesh vanishes is the solution —
  a controller that keeps its mesh when the tolerance falls does not converge).  One record, the study in
  ``details["tolerance_study"]``; ``worst = claimed / (upper end + slack)``.
* the laws local to steps — ``in_domain``, ``selections``, ``bounds_lg``, ``bounds_yb``, ``psi_interpolation`` —
  on the stepper's own partitions (:func:`own_partition_laws`): the paper's results hold for any partition
  (Section 5.1), so a stepper claiming ``scheme="proximal"`` obeys them on the partitions it chose.  They are
  judged on its runs at the loosest and the tightest tolerance, replayed (the stepper runs once per
  tolerance); records ``<law>[<stepper> on <problem> (own steps)]``.  A scheme claiming only convergence
  (``"any"``) is not bound by them (skipped with the reason); ``contraction`` compares two initial points on
  one partition, which a stepper choosing its steps per initial point does not give (not run).
* ``switching_times`` — an event-driven scheme (``fn`` returning ``(t, x, events)``) locates the switching
  times of the exact solution to its tolerance: at every tolerance each exact switching time in ``(0, T)``
  has a located event within ``EVENT_FACTOR · tol · max(1, T)`` and every located event one exact time
  within that (no missed, no spurious switching); ``worst`` = the largest distance over what is allowed.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..core.adaptive import (DEFAULT_TOLERANCES, OWN_ORDER_SLACK, RATE_SLACK, Adaptive, _controls, own_run,
                             tolerance_study)
from ..core.claims import Stepper
from ..core.errors import InvalidCheckArgument, NotApplicable
from ..core.naming import subject_name
from ..core.problem import Problem
from ..records.results import FAILED, PASSED, SKIPPED, UNDECIDED, CheckResult, Report
from ..records.verdicts import new_record
from ..execution.timeouts import note_progress, run_unit
from .core import Holds, Outcome, law, laws_of, record_of_exception, run
from .partitions import single
from . import bounds, trajectory_laws  # noqa: F401 - the laws local to steps join the registry

#: the laws local to steps judged on the stepper's own partitions (module docstring)
LOCAL_LAWS = ("in_domain", "selections", "bounds_lg", "bounds_yb", "psi_interpolation")
#: a located switching time may be off by this many times ``tol · max(1, T)``: an event located on the dense
#: output of a run whose error is ``~ tol`` is off by ``tol / |g'|`` for an event function ``g`` crossing
#: with speed ``|g'|`` (``√2`` at the extinction of t|x|, 1 at the switchings of the Example); 10 leaves room
#: for event functions crossing ten times slower
EVENT_FACTOR = 10.0


def require_adaptive(stepper: Any) -> Adaptive:
    if not isinstance(stepper, Adaptive):
        raise InvalidCheckArgument(f"{subject_name(stepper)} is not a verimono.Adaptive stepper: wrap it as "
                                   "verimono.Adaptive(fn, rate=..., order=...) (fn(problem, T, tol) -> (t, x))")
    return stepper


def _has_exact(p: Problem) -> str | None:
    return None if p.exact is not None else "the problem has no exact solution to measure the errors against"


def _once(decl: Any, stepper: Any, problem: Problem, **kw: Any) -> CheckResult:
    stepper = require_adaptive(stepper)
    p = single(problem)
    return run(decl, f"{subject_name(stepper)} on {subject_name(p)}", lambda: decl.evaluate(stepper, p, **kw),
               stepper=stepper, problem=p)


@law("tolerance_rate", "thm:main (the limit as the mesh vanishes) for a stepper choosing its steps",
     subject="stepper", driver=_once, requires=(Holds(_has_exact),), battery=False)
def check_tolerance_rate(stepper: Adaptive, problem: Problem, *, controls: Sequence[float] | None = None) -> Outcome:
    """The tolerance study's verdict (module docstring)."""
    # each run that returned is stated to the unit budget: stopped between runs, the record is undecided
    study = tolerance_study(stepper, problem, controls, on_run=lambda k: note_progress(k, True, "tolerance runs"))
    ok, msg = study.verdict()
    if ok is None:
        return Outcome(None, details={"tolerance_study": study.to_dict()}, message=msg, status=UNDECIDED)
    fit = study.fits["sup"]
    claim = study.rate if study.control == "tolerance" else study.order
    slack = RATE_SLACK if study.control == "tolerance" else OWN_ORDER_SLACK
    measured = (claim / (fit.high + slack) if claim is not None and fit.high == fit.high and fit.high + slack > 0
                else (0.0 if ok else float("inf")))
    # the verdict decides (it also judges the step counts and the stall); the ratio says by how much
    worst = min(measured, 1.0) if ok else max(measured, 1.0 + 1e-9)
    details = {"tolerance_study": study.to_dict()}
    return Outcome(0.0 if ok and fit.exact else worst, details=details, message=msg,
                   status=PASSED if ok else FAILED,
                   counter={} if ok else {"controls": study.controls, "steps": study.steps,
                                          "errors": study.errors["sup"], "message": msg})


class _Replay:
    """The stepper's own runs, handed to the laws as a stepper of a given partition: called on one of the
    runs' partitions (or a prefix of one, with ``T`` its last time: the shrinking of a failure) with the
    same initial point, it returns that run's states; anything else was not run (:class:`NotApplicable`)."""

    def __init__(self, runs: dict[str, Any], x0: np.ndarray) -> None:
        self.runs, self.x0 = runs, x0

    def __call__(self, problem: Problem, t_grid: Any) -> np.ndarray:
        t = np.asarray(t_grid, dtype=float)
        if not np.array_equal(np.asarray(problem.x0), self.x0):
            raise NotApplicable("the law needs a second initial point, on a partition the stepper chooses per run")
        for r in self.runs.values():
            if len(t) <= len(r.t) and np.array_equal(r.t[:len(t)], t):
                return r.x[:len(t)]
        raise NotApplicable("the law asked for a partition the stepper did not choose")


def own_partition_laws(stepper: Adaptive, problem: Problem, *, controls: Sequence[float] | None = None,
                       laws: Sequence[str] = LOCAL_LAWS, seed: int = 0) -> list[CheckResult]:
    """The laws local to steps on ``stepper``'s own partitions at the loosest and tightest of ``controls``
    (module docstring)."""
    stepper = require_adaptive(stepper)
    p = single(problem)
    unknown = [n for n in laws if n not in LOCAL_LAWS]
    if unknown:
        raise InvalidCheckArgument(f"{unknown} are not laws local to steps; those are {list(LOCAL_LAWS)}")
    subject = f"{subject_name(stepper)} on {subject_name(p)} (own steps)"
    if not stepper.claim.proximal:
        why = ("needs scheme='proximal': a stepper claiming only convergence (scheme='any') is not bound by the "
               "laws of the paper's iterates on its own partition")
        return [new_record(n, subject, SKIPPED, message=why) for n in laws]
    cs = list(_controls(controls or stepper.tolerances or DEFAULT_TOLERANCES, stepper.control))
    chosen = sorted({max(cs), min(cs)}, reverse=True)
    runs = {}
    try:
        for c in chosen:
            runs[f"own partition ({stepper.control} {c:g})"] = own_run(stepper, p, c)
            note_progress(len(runs), True, "runs")      # stated to the unit budget (check_adaptive)
    except Exception as exc:   # noqa: BLE001 - the stepper failed on a valid input: every law fails with it
        return [record_of_exception(n, subject, exc) for n in laws]
    replay = Stepper(_Replay(runs, p.x0), scheme="proximal", name=subject_name(stepper),
                     solve_tol=stepper.claim.solve_tol)
    grids = {k: r.t for k, r in runs.items()}
    out = []
    for name in laws:
        rec = laws_of("stepper")[name].public(replay, p, grids=grids, seed=seed)
        rec.subject = subject
        rec.details["partition"] = {k: len(g) - 1 for k, g in grids.items()}
        out.append(rec)
    return out


def _events(stepper: Adaptive, p: Problem, c: float) -> tuple[np.ndarray, Any]:
    r = own_run(stepper, p, c)
    if r.events is None:
        raise NotApplicable("the stepper reports no located events: return (t, x, events) to have its switching "
                            "times checked")
    return r.events, r


@law("switching_times", "the switching times of the exact solution, located to the stated tolerance",
     subject="stepper", driver=_once, battery=False)
def check_switching_times(stepper: Adaptive, problem: Problem, *, times: Sequence[float],
                          controls: Sequence[float] | None = None) -> Outcome:
    """Located events against the exact switching ``times`` (module docstring)."""
    exact = np.sort(np.asarray([s for s in times if 0.0 < s < problem.T], dtype=float))
    cs = list(_controls(controls or stepper.tolerances or DEFAULT_TOLERANCES, stepper.control))
    worst, where = 0.0, {}
    for c in cs:
        located, _ = _events(stepper, problem, c)
        located = located[(located > 0.0) & (located < problem.T)]
        allowed = EVENT_FACTOR * c * max(1.0, problem.T)
        for s in exact:                                    # a missed switching
            d = float(np.min(np.abs(located - s))) if located.size else float("inf")
            if d / allowed > worst:
                worst, where = d / allowed, {"control": c, "exact": float(s), "distance": d, "allowed": allowed,
                                             "kind": "missed or misplaced", "located": located.tolist()}
        for e in located:                                  # a spurious one
            d = float(np.min(np.abs(exact - e))) if exact.size else float("inf")
            if d / allowed > worst:
                worst, where = d / allowed, {"control": c, "located_event": float(e), "distance": d,
                                             "allowed": allowed, "kind": "spurious", "exact": exact.tolist()}
    if worst <= 1.0:
        return Outcome(worst, message=f"{len(exact)} switching times located within {EVENT_FACTOR:g} tol max(1, T) "
                                      f"at every tolerance (worst {worst:.3g} of what is allowed)")
    msg = (f"a switching time {where['kind']}: at {stepper.control} {where['control']:g} the nearest "
           f"{'located event' if where['kind'] != 'spurious' else 'exact switching'} is {where['distance']:.3g} away, "
           f"more than {EVENT_FACTOR:g} tol max(1, T) = {where['allowed']:.3g}")
    return Outcome(worst, counter={**where, "message": msg})


def check_adaptive(stepper: Adaptive, problems: Sequence[Problem] | None = None, *,
                   switching: dict[str, Sequence[float]] | None = None, laws: bool = True,
                   controls: Sequence[float] | None = None) -> Report:
    """The battery of an adaptive stepper: ``tolerance_rate`` on every problem with an exact solution, the
    laws local to steps on its own partitions, and ``switching_times`` where the switching times are known
    (``switching``: problem name → times; by default those of the reference catalog,
    :func:`verimono.reference.events.switching_times`)."""
    from verimono.reference.events import switching_times

    stepper = require_adaptive(stepper)
    if problems is None:
        from verimono.reference import catalog

        problems = catalog()
    problems = list(problems)
    if not problems:
        raise InvalidCheckArgument("check_adaptive was given an empty list of problems: it would verify nothing")
    report = Report()
    name = subject_name(stepper)
    for p in problems:
        # every check under the unit time budget, as every check of a grid stepper: a stepper that runs past it
        # is judged by the one policy of a unit out of time (undecided when every run that returned held)
        subject = f"{name} on {subject_name(p)}"
        report.add(run_unit(lambda: check_tolerance_rate(stepper, p, controls=controls), check="tolerance_rate",
                            subject=subject))
        if laws:
            out = run_unit(lambda: own_partition_laws(stepper, p, controls=controls), check=LOCAL_LAWS[0],
                           subject=f"{subject} (own steps)")
            for rec in (out if isinstance(out, list) else _each_law(out)):
                report.add(rec)
        times = (switching or {}).get(p.name, switching_times(p) if switching is None else None)
        if times is not None and p.exact is not None:
            report.add(run_unit(lambda: check_switching_times(stepper, p, times=times, controls=controls),
                                check="switching_times", subject=subject))
    return report


def _each_law(timed_out: CheckResult) -> list[CheckResult]:
    """The records of the laws local to steps whose shared runs ran out of the unit budget: one per law, each
    with the timeout's status and message (the record keys stay those of a finished battery)."""
    out = []
    for n in LOCAL_LAWS:
        rec = new_record(n, timed_out.subject, timed_out.status, message=timed_out.message,
                         details=dict(timed_out.details), duration=timed_out.duration)
        out.append(rec)
    return out


__all__ = ["check_tolerance_rate", "check_switching_times", "own_partition_laws", "check_adaptive", "LOCAL_LAWS",
           "EVENT_FACTOR", "require_adaptive"]
