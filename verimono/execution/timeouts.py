"""Time budgets for units of work: a resolvent or stepper that never returns must not hang a run.

A *unit* is one law on one operator, or one check of one stepper.  Its budget is the run configuration's
(:mod:`verimono.execution.config`, chosen at the entry point and shipped to the run's worker processes): its
explicit seconds (``verimono run/check --timeout S``, or a :func:`budget` block; ``inf``: no limit), else its
profile's ``unit_budget`` (:mod:`verimono.execution.profiles`), stated in *calibration units*: multiples of
:func:`verimono.execution.calibration.calibrate`, a fixed NumPy-and-Python workload.  In seconds that is ``units x`` the
calibration measured in this process (:func:`calibration`: measured once, best of 3, about 0.2 s, then
cached; ``verimono run`` supplies the one it measures at its start), so a slower or busier machine — where
the workload, like everything else, takes longer — gets proportionally more time, and a unit is stopped
for not finishing, not for running on a loaded runner.  Stage budgets (:func:`stage_budget`) are stated the
same way; a budget beyond the platform's timers (:data:`TIMER_LIMIT`, about 73 years) is no limit.
:func:`time_limit` enforces a budget with ``SIGALRM`` (a one-shot real-time timer): the unit's code is
interrupted where it is — inside a user's Python loop too — and :class:`verimono.UnitTimeout` is raised at
the ``with`` block, naming the unit and the elapsed time.  :func:`run_unit` turns that into a record so the
run goes on, by the one policy of a unit out of time (:func:`verimono.records.verdicts.timeout_verdict`, which
:func:`verimono.records.verdicts.classify` applies to every ``UnitTimeout``): *undecided* (time budget, with
how many samples were evaluated) when everything the law inside had evaluated held (:func:`note_progress`)
and no call in flight had run long — a correct subject on a slow machine — and *failed* when the law had
seen a violation, or for a call that never returns: one in flight longer than :data:`HANG_MULTIPLE` x any
that returned before it, half the budget and a tenth of a second.  (The operator laws' search bounds itself
the same way, :mod:`verimono.checks.engine.search`.)

The interrupt is raised as an internal ``BaseException`` while it travels through the unit's code, so a
check's own ``except Exception`` (which turns an operator's error into a failed sample) or hypothesis'
shrinking cannot swallow or replay it; and it is raised only where that cannot corrupt anything
(:mod:`verimono.execution.interrupts`): never inside hypothesis's engine, a garbage-collector callback, a
finalizer or this machinery — there it waits, a few milliseconds at a time, for the unit's own code, or for
the next :func:`checkpoint`.  Whatever the block raises once interrupted (a library failing in its cleanup)
is the timeout, never a failure of the subject, and the internal interrupt never leaves the block.  The
timer works only in the main thread of a POSIX process (elsewhere the unit runs unbounded, which the record
says).

A call blocked in native code (``os.system``, a C extension that retries after the signal) runs the
interrupt only once it returns.  Every armed limit is therefore also watched by :mod:`verimono.execution.watchdog`, a
process-level limit: a call still inside its limit a grace of ``max(2 s, half the budget)`` after the
deadline is blocked there, and the process is ended where verimono owns it — a ``process:N`` worker answers
a failed record naming the call and exits (the run goes on), a serial ``verimono check``/``run`` writes what
finished, marked incomplete, and exits 1 — while the Python API, in the user's interpreter, warns and waits
for the call (bounded only with ``check_stepper(..., executor="process:N")``, :mod:`verimono.checks.isolated`).
"""

from __future__ import annotations

import signal
import sys
import threading
import time
from contextlib import contextmanager
from typing import Any, Callable, Iterator

from ..core.errors import InvalidCheckArgument, UnitTimeout
from . import calibration as _calibration
from . import config as _config
from .profiles import Profile, get_profile
from ..records.verdicts import (HANG_FRACTION, HANG_MULTIPLE, TIME_BUDGET_REASON, never_returned,
                                SUBJECT_EXITS, record_of_exception)
from . import watchdog
from .interrupts import DEFER_STEP, interruptible, safe_to_interrupt

#: budgets longer than this (about 73 years) are no limit: the platform's timers refuse longer ones
#: (``setitimer``, the watchdog's wait and :mod:`faulthandler`'s timer stop near 9.2e9 s, the nanoseconds of a
#: 64-bit integer), and the watchdog waits for up to twice the budget
TIMER_LIMIT = threading.TIMEOUT_MAX / 4


class _Expired(BaseException):
    """Raised by the timer inside the unit; becomes :class:`UnitTimeout` at the ``time_limit`` boundary."""


def _positive(seconds: float | None, what: str = "timeout") -> float | None:
    """``seconds`` as a float > 0 (``inf``: no limit); ``nan``, 0, negatives and non-numbers are refused."""
    if seconds is None:
        return None
    try:
        s = float(seconds)
    except (TypeError, ValueError):
        raise InvalidCheckArgument(f"{what} must be a number of seconds > 0 (or inf), got {seconds!r}") from None
    if not s > 0:     # nan compares false
        raise InvalidCheckArgument(f"{what} must be a number of seconds > 0 (or inf), got {seconds!r}")
    return s


def unlimited(seconds: float | None) -> bool:
    """Whether a budget of ``seconds`` is no limit at all: ``None``, ``inf``, or beyond :data:`TIMER_LIMIT`
    (``--timeout 1e10`` made the timer raise ``OverflowError``, recorded as failures of correct subjects)."""
    return seconds is None or not seconds <= TIMER_LIMIT


@contextmanager
def budget(seconds: float | None) -> Iterator[None]:
    """Within the block, every unit's budget is ``seconds`` (``None``: back to the profile default;
    ``math.inf``: no limit, as ``--timeout inf``): the run configuration's ``budget``
    (:func:`verimono.execution.config.using`)."""
    with _config.using(budget=_positive(seconds)):
        yield


def explicit_budget() -> float | None:
    """The explicit seconds per unit of the run configuration (:func:`budget`, ``--timeout``), ``None`` when
    the profile's budget applies."""
    return _config.current().budget


def calibration() -> float:
    """Seconds of the calibration workload in this process (:func:`verimono.execution.calibration.calibration`: measured
    once and cached; :func:`verimono.execution.calibration.set_calibration` supplies one measured elsewhere)."""
    return _calibration.calibration()


def in_seconds(units: float) -> float:
    """Seconds of ``units`` calibration units on this machine: ``units x`` :func:`calibration`."""
    return float(units) * calibration()


def _profile() -> Profile | None:
    """The effort of the run configuration's profile (``None``: a user's own hypothesis profile)."""
    return _config.current().effort


def budget_source() -> dict[str, object]:
    """Where the budget of a unit started now comes from: ``{"seconds": S, "source": "explicit"}`` inside a
    :func:`budget` block; else ``{"seconds": S, "source": "profile <name>", "units": U, "calibration": C}``
    with ``S = U x C``; ``{"seconds": None, ...}`` when there is none (an unknown profile)."""
    explicit = explicit_budget()
    if explicit is not None:
        return {"seconds": explicit, "source": "explicit"}
    profile = _profile()
    if profile is None:
        return {"seconds": None, "source": "none"}
    cal = calibration()
    return {"seconds": profile.unit_budget * cal, "source": f"profile {profile.name}", "units": profile.unit_budget,
            "calibration": cal}


def current_budget() -> float | None:
    """Seconds a unit started now may take: the innermost :func:`budget` (explicit seconds), else the active
    profile's ``unit_budget`` calibration units x :func:`calibration`; ``None`` for an unknown profile."""
    explicit = explicit_budget()
    if explicit is not None:
        return explicit
    profile = _profile()
    return None if profile is None else in_seconds(profile.unit_budget)


def stage_budget(stage: str, profile: str | Profile | None = None) -> float | None:
    """Seconds stage ``stage`` may take at ``profile`` (default: the active one): its budget in calibration
    units (:data:`verimono.execution.profiles.STAGE_BUDGETS` x the profile's ``stage_budget_scale``) x
    :func:`calibration`; ``None`` when no budget is stated for it."""
    p = profile if isinstance(profile, Profile) else get_profile(profile or _config.current().profile)
    units = p.stage_budget_units(stage)
    return None if units is None else in_seconds(units)


def supported() -> bool:
    """Whether :func:`time_limit` can interrupt here (POSIX timer, main thread)."""
    return hasattr(signal, "setitimer") and threading.current_thread() is threading.main_thread()


class _Limit:
    """One armed :func:`time_limit`: its budget, its unit, when it started, the frame that opened it (where
    :func:`verimono.execution.interrupts.safe_to_interrupt` stops reading the stack), whether its deadline has
    passed (``due``) and how many times its interrupt was raised into the block (``raised``)."""

    __slots__ = ("seconds", "unit", "start", "boundary", "due", "raised", "closed", "stopped_at", "stated")

    def __init__(self, seconds: float, unit: str, boundary: Any, stated: float | None = None) -> None:
        self.seconds, self.unit, self.boundary = seconds, unit, boundary
        self.stated = seconds if stated is None else stated     # the budget the block is a part of
        self.start, self.due, self.raised, self.closed = time.perf_counter(), False, 0, False
        self.stopped_at: float | None = None

    def expired(self, **evidence: Any) -> UnitTimeout:
        """The :class:`UnitTimeout` of this limit, with the evidence :func:`verimono.records.verdicts.
        timeout_verdict` judges (the whole block counted as one call in flight, until its unit says more;
        ``stopped_at``: the :func:`time.perf_counter` of the interrupt, which is when a call in flight stopped —
        not when the exception, unwinding through a library's frames, reached the limit)."""
        elapsed = time.perf_counter() - self.start
        stopped_at = self.stopped_at if self.stopped_at is not None else time.perf_counter()
        note = f"; {evidence['harness_error']} after the interrupt" if evidence.get("harness_error") else ""
        exc = UnitTimeout(f"{self.unit} exceeded its time budget of {self.stated:g} s (stopped after "
                          f"{elapsed:.1f} s){note}")
        exc.evidence = {"budget": self.stated, "elapsed": elapsed, "in_flight": stopped_at - self.start,
                        "stopped_at": stopped_at, **evidence}
        return exc

    def interrupt(self) -> None:
        """Raise the interrupt into the block (again after :data:`SWALLOWED_STEP`, should the code swallow it)."""
        self.raised += 1
        if self.stopped_at is None:
            self.stopped_at = time.perf_counter()
        signal.setitimer(signal.ITIMER_REAL, SWALLOWED_STEP)
        raise _Expired(self)


#: the armed limits, innermost last
_LIMITS: list[_Limit] = []
#: seconds after an interrupt before it is raised again, should the code have swallowed it (an ``except
#: BaseException`` of its own); the block's end cancels it
SWALLOWED_STEP = 0.05


@contextmanager
def time_limit(seconds: float | None, unit: str, *, part_of: float | None = None) -> Iterator[None]:
    """Run the block for at most ``seconds``; :class:`UnitTimeout` naming ``unit`` when it takes longer.
    ``part_of``: the whole budget of which ``seconds`` is what is left (a law's later phase), which the
    timeout states and its verdict is judged against (:func:`verimono.records.verdicts.never_returned`).

    Nested limits keep the tighter one: an outer limit that expires first still fires (as the outer
    unit's timeout).  ``seconds=None``, ``inf``, a budget beyond the platform's timers (:data:`TIMER_LIMIT`)
    or an unsupported context (:func:`supported`) runs unbounded.  The interrupt is raised only where that is
    safe (:mod:`verimono.execution.interrupts`: never inside hypothesis's engine, a gc callback, a finalizer or
    verimono's own machinery; deferred by :data:`~verimono.execution.interrupts.DEFER_STEP` until the code is
    the unit's again, or stopped at a :func:`checkpoint`); a block whose deadline passed while the interrupt
    waited and that finished meanwhile keeps its result.  Whatever the block raises after the interrupt — a
    library failing in its own cleanup — is this :class:`UnitTimeout` too (``evidence["harness_error"]`` names
    it), as is a block that returns after swallowing it: the internal interrupt never leaves the block.  Each
    armed limit is also watched by :mod:`verimono.execution.watchdog`: a block still running :func:`verimono.
    watchdog.grace` seconds after the deadline is blocked in native code, where the timer cannot reach it.
    """
    seconds = _positive(seconds)
    if unlimited(seconds) or not supported():
        yield
        return
    outer_left, _ = signal.getitimer(signal.ITIMER_REAL)
    if outer_left and outer_left <= seconds:     # the outer unit's budget is the tighter one: leave it alone
        yield
        return
    lim = _Limit(seconds, unit, sys._getframe(2), part_of)   # 2: past contextlib's __enter__, the `with` statement's frame

    def fire(signum, frame):
        if lim.closed:           # a signal that arrived as the limit closed: nothing to stop, nothing to re-arm
            return                # (re-armed here, it would fire under the restored handler: SIG_DFL ends the process)
        lim.due = True
        if safe_to_interrupt(frame, lim.boundary):
            lim.interrupt()
        signal.setitimer(signal.ITIMER_REAL, DEFER_STEP)    # not here: try again in a moment

    previous = signal.signal(signal.SIGALRM, fire)
    _LIMITS.append(lim)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        with watchdog.limit(seconds, unit):
            yield
        if lim.raised:                               # it returned after swallowing the interrupt
            raise lim.expired(harness_error="a return (the interrupt was swallowed)")
    except _Expired:                                 # this limit's (or a stale one's: it never leaves a limit)
        raise lim.expired() from None
    except (KeyboardInterrupt, SystemExit, GeneratorExit, UnitTimeout):
        raise
    except BaseException as exc:
        if not lim.raised:
            raise
        # the block raised something else after the interrupt: a library that failed while it was stopped
        raise lim.expired(harness_error=f"{type(exc).__name__}: {exc}") from None
    finally:
        lim.closed = True
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        _LIMITS.remove(lim)
        if outer_left:                               # re-arm the outer unit's timer with what it has left
            left = outer_left - (time.perf_counter() - lim.start)
            signal.setitimer(signal.ITIMER_REAL, max(left, 1e-3))


def interrupted() -> bool:
    """Whether the budget's interrupt has been raised into the code running now (the innermost limit's): an
    exception met after it — a library failing while it was stopped — is the timeout's, not the subject's."""
    return bool(_LIMITS) and _LIMITS[-1].raised > 0


def checkpoint() -> None:
    """A safe point: stop here if the innermost limit's deadline has passed while its interrupt waited for
    the code to leave a place it must not be raised in (:mod:`verimono.execution.interrupts`).  The operator
    search calls it before each sample."""
    if _LIMITS and _LIMITS[-1].due:
        _LIMITS[-1].interrupt()


def note_progress(evaluated: int, held: bool, what: str = "samples", searched: Callable[[], dict] | None = None) -> None:
    """State what the law running inside the current :func:`run_unit` has evaluated so far: ``evaluated``
    ``what`` (samples, partitions), every one of which held when ``held``; the next evaluation starts now.
    Should the unit's budget stop it later, the record is *undecided* (time budget, ``evaluated`` ``what``)
    instead of failed — too few for a verdict, none against the subject — unless the evaluation in flight
    then counts as a call that does not return (:func:`never_returned`).  ``searched``: what the search has
    covered so far (a function returning the record's ``details["searched"]``, called only if the budget stops
    the unit).  Outside a unit it does nothing."""
    if _PROGRESS:
        progress, now = _PROGRESS[-1], time.perf_counter()
        progress.update(evaluated=int(evaluated), held=bool(held), what=what, at=now,
                        slowest=max(progress.get("slowest", 0.0), now - progress["at"]))
        if searched is not None:
            progress["searched"] = searched


#: the progress of the units running now, innermost last (:func:`note_progress`)
_PROGRESS: list[dict] = []


def run_unit(fn: Callable[[], object], *, check: str, subject: str, seconds: float | None = None):
    """``fn()`` under the unit budget (``seconds``, else :func:`current_budget`).  A timeout becomes a
    :class:`verimono.CheckResult` ``check[subject]`` naming the unit and the elapsed time, judged by the one
    policy of a unit out of time (:func:`verimono.records.verdicts.timeout_verdict`) on what the law inside
    stated through :func:`note_progress`: *undecided* (``details["undecided_reason"] == "time budget"``)
    when everything it evaluated held and the evaluation in flight had not run long; *failed* when a
    violation had been seen or the call in flight counts as one that does not return — a subject whose
    first call never returns (a unit that states no progress counts as one call).

    A call blocked in native code, which the timer cannot stop, is left to :mod:`verimono.execution.watchdog`; the
    outcome is passed to :func:`verimono.execution.watchdog.finished`, so that a process ended on such a call later
    still writes this record."""
    out = _run_unit(fn, check=check, subject=subject, seconds=seconds)
    watchdog.finished(out)
    return out


def _run_unit(fn: Callable[[], object], *, check: str, subject: str, seconds: float | None):
    limit = current_budget() if seconds is None else seconds
    start = time.perf_counter()
    progress: dict = {"at": start}
    _PROGRESS.append(progress)
    try:
        with watchdog.scope(check=check, subject=subject), time_limit(limit, f"{check} on {subject}"):
            return fn()
    except UnitTimeout as exc:
        elapsed = time.perf_counter() - start
        details: dict[str, object] = {"timeout": limit, "elapsed": elapsed}
        if seconds is None:
            details["budget"] = budget_source()
        exc.evidence = {**getattr(exc, "evidence", {}), "evaluated": progress.get("evaluated", 0),
                        "held": progress.get("held", True), "what": progress.get("what", "samples"),
                        "in_flight": _stopped_at(exc) - progress["at"], "slowest": progress.get("slowest", 0.0),
                        "budget": limit}
        if progress.get("searched") is not None:     # the resolution the stopped search had reached
            exc.evidence["searched"] = progress["searched"]()
        return record_of_exception(check, subject, exc, details=details, duration=elapsed)
    except SUBJECT_EXITS as exc:     # sys.exit() in the subject: its failure, never the end of the run
        return record_of_exception(check, subject, exc, duration=time.perf_counter() - start)
    finally:
        _PROGRESS.pop()


def _stopped_at(exc: UnitTimeout) -> float:
    """When the limit's interrupt stopped the code (now, for a timeout without that evidence)."""
    return getattr(exc, "evidence", {}).get("stopped_at") or time.perf_counter()


__all__ = ["budget", "current_budget", "budget_source", "stage_budget", "calibration", "in_seconds", "time_limit",
           "run_unit", "note_progress", "never_returned", "supported", "explicit_budget", "unlimited", "checkpoint",
           "interrupted",
           "interruptible", "TIME_BUDGET_REASON", "HANG_MULTIPLE", "HANG_FRACTION", "TIMER_LIMIT"]
