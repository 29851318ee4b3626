"""What a record says: the one record builder and the one exception policy.

Every :class:`~verimono.records.results.CheckResult` of verimono is made by :func:`new_record` — the laws'
records (through :func:`verimono.checks.core.record`), the operator search's verdicts, the speed checks, the
records standing for a unit of work that did not finish (:mod:`verimono.execution.executors`), a unit out of
time (:mod:`verimono.execution.timeouts`), a call blocked in native code (:mod:`verimono.execution.watchdog`)
and a stage that raised (:mod:`verimono.run.stages`); the schema reader (:mod:`verimono.records.schema`) only
reads records back.  And every exception met while verifying — in a sample of a search, a law, a unit, a stage
— is judged by :func:`classify`.

Both live here, in the records layer, rather than in the check core (:mod:`verimono.checks.core`, which
re-exports them): the execution machinery (budgets, watchdog, executors) sits below the checks and makes
records too (a unit that raised, a call that never returned), so the one policy must be importable from
there without the execution layer importing the checks it runs.  It needs nothing but the records and the
typed errors of :mod:`verimono.core.errors`.
"""

from __future__ import annotations

import math
from typing import Any

from ..core.errors import NotApplicable, StageUnavailable, UnitTimeout, UnverifiedSolution
from .results import FAILED, SKIPPED, STATUSES, UNDECIDED, CheckResult


def new_record(check: str, subject: str, status: str, *, worst: float | None = None, bound: float | None = None,
               counterexample: dict[str, Any] | None = None, message: str = "", seed: int | None = None,
               details: dict[str, Any] | None = None, duration: float | None = None) -> CheckResult:
    """The record ``check[subject]`` with ``status``: the one place a record is made.

    What it enforces, whoever builds the record: a check name and a subject that are non-empty strings (the
    gate's key), a known status, a reason for every record that is neither passed nor failed by its ratio
    (an undecided or skipped record without a message verifies nothing and says nothing), and its own
    ``details`` dict (never the caller's, which later records may be built from).  A pass with a non-finite
    ratio is failed (:class:`CheckResult`)."""
    if not isinstance(check, str) or not check:
        raise TypeError(f"a record's check name must be a non-empty string, got {check!r}")
    if not isinstance(subject, str) or not subject:
        raise TypeError(f"a record's subject must be a non-empty string (its name), got {subject!r}")
    if status not in STATUSES:
        raise ValueError(f"status must be one of {STATUSES}, got {status!r}")
    if status in (UNDECIDED, SKIPPED) and not message:
        raise ValueError(f"a {status} record must say why ({check}[{subject}])")
    return CheckResult(check, subject, status, worst=worst, bound=bound, counterexample=counterexample,
                       message=message, seed=seed, details=dict(details or {}), duration=duration)


# -- a unit out of time ------------------------------------------------------------------------------

#: ``details["undecided_reason"]`` of a unit stopped by its time budget when nothing showed the subject at fault
TIME_BUDGET_REASON = "time budget"
#: a call still running when its unit's budget ran out counts as one that does not return when it had run
#: this many times the slowest evaluation of the same law that returned ...
HANG_MULTIPLE = 20.0
#: ... and at least this fraction of the unit's whole budget: a call in flight for a moment when the budget
#: ran out (the budget spent by the harness, or by many quick evaluations) is not a hang, however quick the
#: evaluations before it were (20 x a 4 ms sample is 0.08 s, which a busy machine's scheduler can add alone)
HANG_FRACTION = 0.5
#: ... and at least this many seconds (for the first call of a unit under a smaller budget, the whole budget): a
#: Python process pauses that long without being stuck — a garbage collection inside a microsecond resolvent kept
#: it "in flight" 15 ms at a 30 ms budget here, and a busy machine's scheduler adds as much (at load 13 on 2 cores a
#: quick sample after many quicker ones was in flight past a 20–50 ms budget: a correct projection failed)
HANG_MIN_SECONDS = 0.1


def never_returned(in_flight: float | None, slowest: float, budget: float | None = None) -> bool:
    """Whether a call that was still running ``in_flight`` seconds when its unit's budget (``budget`` seconds)
    ran out counts as one that never returns: longer than :data:`HANG_MULTIPLE` x the slowest evaluation of
    the same law that returned (``slowest`` seconds; 0 when none did), longer than :data:`HANG_FRACTION`
    of the budget and longer than :data:`HANG_MIN_SECONDS` — or, for the first call (none returned before it)
    under a budget shorter than that, than the whole budget: a call that started with the unit and outlived it.
    A call after others returned is judged against :data:`HANG_MIN_SECONDS` whatever the budget: under a 20 ms
    budget a scheduler's pause alone outlasts it.  ``None`` (nothing was in flight: the budget ran out between
    evaluations, in the harness) is no hang."""
    if in_flight is None:
        return False
    least = HANG_MIN_SECONDS if slowest > 0.0 else min(HANG_MIN_SECONDS, budget or HANG_MIN_SECONDS)
    floor = 0.0 if budget is None or not math.isfinite(budget) else max(HANG_FRACTION * budget, least)
    return in_flight > max(HANG_MULTIPLE * slowest, floor)


def timeout_verdict(text: str, *, evaluated: int = 0, held: bool = True, in_flight: float | None = math.inf,
                    slowest: float = 0.0, budget: float | None = None, what: str = "samples",
                    **_: Any) -> tuple[str, str, dict[str, Any]]:
    """``(status, message, details)`` of a unit its budget stopped (``text``: what the
    :class:`~verimono.core.errors.UnitTimeout` says) — the policy of every unit out of time, the operator
    search's, a stepper law's, a stage unit's alike:

    * *failed* when a violation had been seen (``held`` false): the subject is at fault whatever the time;
    * *failed* when the call in flight counts as one that never returns (:func:`never_returned`: the first
      call, or one far slower than every evaluation before it, that had used at least half the budget and
      a tenth of a second — for the first call, the whole budget when that is shorter);
    * else *undecided* (``details["undecided_reason"] == "time budget"``): the evaluations that finished all
      held, or none finished and no call of the subject had run for long — a correct subject on a slow or
      busy machine, or a budget spent by the harness, is never failed.

    ``in_flight``: seconds the call running when the budget ran out had run (``None``: none was running;
    the default, ``inf``, counts the whole unit as one call: a unit that states no progress)."""
    what = what[:-1] if evaluated == 1 and what.endswith("s") else what
    details: dict[str, Any] = {"evaluated": evaluated}
    if in_flight is not None and math.isfinite(in_flight):
        details.update(in_flight=in_flight, slowest=slowest)
    if not held:
        return FAILED, f"timed out: {text} (after {evaluated} {what}, not all of which held)", details
    if never_returned(in_flight, slowest, budget):
        if evaluated:
            return FAILED, (f"timed out: {text}; the evaluation in flight ran {in_flight:.1f} s, more than "
                            f"{HANG_MULTIPLE:g}x the slowest of the {evaluated} {what} before it ({slowest:.3g} s): "
                            "a call that does not return"), details
        return FAILED, f"timed out: {text}", details
    details["undecided_reason"] = TIME_BUDGET_REASON
    if evaluated:
        return UNDECIDED, (f"time budget exhausted after {evaluated} {what}, all of which held ({text}): too few "
                           "for a verdict"), details
    why = ("no call of the subject was running" if in_flight is None else
           f"the call in flight had run only {in_flight:.3g} s")
    return UNDECIDED, (f"time budget exhausted before any {what[:-1] if what.endswith('s') else what} was "
                       f"evaluated ({text}; {why}): no verdict"), details


#: what a subject raises to end the program it runs in (``sys.exit()``, a generator's close): not a status of the
#: harness's own, but a failure of the subject like any exception it raises — caught where the subject's code
#: runs (a law, a unit, a stage), so that a subject cannot end ``verimono check`` with a status of its choosing
#: (``sys.exit(0)`` used to exit 0 with no results).  ``KeyboardInterrupt`` is not among them: Ctrl-C (and
#: SIGTERM, which the run raises as it) is the user's, and stops the run.
SUBJECT_EXITS = (SystemExit, GeneratorExit)


def classify(exc: BaseException) -> tuple[str, str]:
    """``(status, message)`` for an exception raised while verifying — the one policy of every record,
    every sample of a search, every unit of work and every stage of a run:

    * :class:`NotApplicable` (the law's hypotheses do not hold here) and :class:`StageUnavailable`:
      skipped, with the reason;
    * ``NotImplementedError`` (a member the subject lacks, met at run time): skipped;
    * :class:`UnverifiedSolution` (verimono's own solvers gave no verified answer): undecided — a limit of
      the harness is never a failure of the subject, and never a pass;
    * :class:`UnitTimeout`: by what the budget saw (:func:`timeout_verdict`, from the evidence the limit
      and the unit attached, ``exc.evidence``): failed when a violation was seen or a call did not return,
      undecided (time budget) otherwise;
    * ``SystemExit`` and ``GeneratorExit`` (:data:`SUBJECT_EXITS`): a failure of the subject, which would end
      its caller's program;
    * anything else: a failure of the subject (it raised on a valid input), with the exception's type.

    Misuse (:class:`verimono.InvalidCheckArgument`) is not classified: the drivers let it propagate to the
    caller."""
    if isinstance(exc, (NotApplicable, StageUnavailable)):
        return SKIPPED, str(exc) or type(exc).__name__
    if isinstance(exc, NotImplementedError):
        return SKIPPED, f"not available: {exc}"
    if isinstance(exc, UnverifiedSolution):
        return UNDECIDED, f"verimono's own solvers gave no verified answer: {exc}"
    if isinstance(exc, UnitTimeout):
        status, message, _ = timeout_verdict(str(exc), **getattr(exc, "evidence", {}))
        return status, message
    if isinstance(exc, SystemExit):
        return FAILED, (f"SystemExit({exc.code!r}): the subject called sys.exit() (or raised SystemExit), which "
                        "would end the program that calls it")
    if isinstance(exc, GeneratorExit):
        return FAILED, "GeneratorExit: the subject raised GeneratorExit outside a generator's close"
    return FAILED, f"{type(exc).__name__}: {exc}"


def record_of_exception(check: str, subject: str, exc: BaseException, *, prefix: str = "",
                        **kw: Any) -> CheckResult:
    """The record of ``check[subject]`` whose evaluation raised ``exc`` (:func:`classify`); ``prefix`` goes
    before the policy's message (``"raised "``); a record that is not a skip names the exception's type in
    ``details["exception"]``."""
    status, message = classify(exc)
    details = dict(kw.pop("details", None) or {})
    if isinstance(exc, UnitTimeout):
        evidence = getattr(exc, "evidence", {})
        details.update(timeout_verdict(str(exc), **evidence)[2])
        if evidence.get("searched"):       # what a search stopped short had reached (engine.times.reached)
            details["searched"] = evidence["searched"]
        if evidence.get("harness_error"):
            details["harness_error"] = evidence["harness_error"]
    if status != SKIPPED:
        details.setdefault("exception", type(exc).__name__)
    if isinstance(exc, ValueError) and "read-only" in str(exc):
        message += READ_ONLY_HINT
    return new_record(check, subject, status, message=prefix + message, details=details, **kw)


#: what a failure NumPy reports as a write into a read-only array adds: the arrays verimono hands a subject that are
#: not its own are read-only (a Problem's x0: every stepper checked on a problem shares it), and NumPy's message
#: names neither the array nor the fix (probe7: ``x = np.asarray(problem.x0); x += ...`` failed 7 records so)
READ_ONLY_HINT = (" — the subject wrote into an array it was given that is not its own (a Problem's x0 is read-only: "
                  "every stepper checked on the problem shares it); work on a copy, e.g. x = np.array(problem.x0)")


__all__ = ["SUBJECT_EXITS", "new_record", "classify", "record_of_exception", "READ_ONLY_HINT", "timeout_verdict", "never_returned", "HANG_MULTIPLE",
           "HANG_FRACTION", "HANG_MIN_SECONDS", "TIME_BUDGET_REASON"]
