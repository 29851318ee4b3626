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


def classify(exc: BaseException) -> tuple[str, str]:
    """``(status, message)`` for an exception raised while verifying — the one policy of every record,
    every sample of a search, every unit of work and every stage of a run:

    * :class:`NotApplicable` (the law's hypotheses do not hold here) and :class:`StageUnavailable`:
      skipped, with the reason;
    * ``NotImplementedError`` (a member the subject lacks, met at run time): skipped;
    * :class:`UnverifiedSolution` (verimono's own solvers gave no verified answer): undecided — a limit of
      the harness is never a failure of the subject, and never a pass;
    * :class:`UnitTimeout`: failed, naming the unit and its budget;
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
        return FAILED, f"timed out: {exc}"
    return FAILED, f"{type(exc).__name__}: {exc}"


def record_of_exception(check: str, subject: str, exc: BaseException, *, prefix: str = "",
                        **kw: Any) -> CheckResult:
    """The record of ``check[subject]`` whose evaluation raised ``exc`` (:func:`classify`); ``prefix`` goes
    before the policy's message (``"raised "``); a record that is not a skip names the exception's type in
    ``details["exception"]``."""
    status, message = classify(exc)
    details = dict(kw.pop("details", None) or {})
    if status != SKIPPED:
        details.setdefault("exception", type(exc).__name__)
    return new_record(check, subject, status, message=prefix + message, details=details, **kw)


__all__ = ["new_record", "classify", "record_of_exception"]
