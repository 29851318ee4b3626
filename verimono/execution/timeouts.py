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
same way.  :func:`time_limit` enforces a budget with ``SIGALRM`` (a one-shot real-time timer): the unit's
code is interrupted where it is — inside a user's Python loop too — and :class:`verimono.UnitTimeout` is
raised at the ``with`` block, naming the unit and the elapsed time.  :func:`run_unit` turns that into a
record so the run goes on: *undecided* (time budget, with how many samples were evaluated) when the law
inside had stated (:func:`note_progress`) that everything it evaluated held — a correct subject on a slow
machine — and *failed* otherwise: a call that never returns (nothing returned before it, or it ran
:data:`HANG_MULTIPLE` x longer than any that did), or a law that had seen a violation.  (The
operator laws' search bounds itself the same way, :mod:`verimono.checks.search`.)

The interrupt is raised as an internal ``BaseException`` while it travels through the unit's code, so a
check's own ``except Exception`` (which turns an operator's error into a failed sample) or hypothesis'
shrinking cannot swallow or replay it.  The timer works only in the main thread of a POSIX process
(elsewhere the unit runs unbounded, which the record says).

A call blocked in native code (``os.system``, a C extension that retries after the signal) runs the
interrupt only once it returns.  Every armed limit is therefore also watched by :mod:`verimono.execution.watchdog`, a
process-level limit: a call still inside its limit a grace of ``max(2 s, half the budget)`` after the
deadline is blocked there, and the process is ended where verimono owns it — a ``process:N`` worker answers
a failed record naming the call and exits (the run goes on), a serial ``verimono check``/``run`` writes what
finished, marked incomplete, and exits 1 — while the Python API, in the user's interpreter, warns and waits
for the call (bounded only with ``check_stepper(..., executor="process:N")``, :mod:`verimono.checks.isolated`).
"""

from __future__ import annotations

import math
import signal
import threading
import time
from contextlib import contextmanager
from typing import Callable, Iterator

from ..core.errors import InvalidCheckArgument, UnitTimeout
from . import calibration as _calibration
from . import config as _config
from .profiles import Profile, get_profile
from ..records.results import FAILED, UNDECIDED
from ..records.verdicts import new_record
from . import watchdog

#: ``details["undecided_reason"]`` of a law stopped by its budget after samples that all held
TIME_BUDGET_REASON = "time budget"
#: a call still running when its unit's budget ran out, after this many times the slowest evaluation of the same
#: law that returned, is one that does not return: a failure of the subject, not a law out of time
HANG_MULTIPLE = 20.0


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
    """Whether a budget of ``seconds`` is no limit at all (``None`` or ``inf``)."""
    return seconds is None or math.isinf(seconds)


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


@contextmanager
def time_limit(seconds: float | None, unit: str) -> Iterator[None]:
    """Run the block for at most ``seconds``; :class:`UnitTimeout` naming ``unit`` when it takes longer.

    Nested limits keep the tighter one: an outer limit that expires first still fires (as the outer
    unit's timeout).  ``seconds=None``, ``inf`` or an unsupported context (:func:`supported`) runs unbounded.
    Each armed limit is also watched by :mod:`verimono.execution.watchdog`: a block still running :func:`verimono.
    watchdog.grace` seconds after the deadline is blocked in native code, where the timer cannot reach it.
    """
    seconds = _positive(seconds)
    if unlimited(seconds) or not supported():
        yield
        return
    start = time.perf_counter()
    outer_left, _ = signal.getitimer(signal.ITIMER_REAL)
    if outer_left and outer_left <= seconds:     # the outer unit's budget is the tighter one: leave it alone
        yield
        return
    token = object()

    def fire(signum, frame):
        raise _Expired(token)

    previous = signal.signal(signal.SIGALRM, fire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        with watchdog.limit(seconds, unit):
            yield
    except _Expired as exc:
        if exc.args and exc.args[0] is token:
            elapsed = time.perf_counter() - start
            raise UnitTimeout(f"{unit} exceeded its time budget of {seconds:g} s (stopped after "
                              f"{elapsed:.1f} s)") from None
        raise
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        if outer_left:                               # re-arm the outer unit's timer with what it has left
            left = outer_left - (time.perf_counter() - start)
            signal.setitimer(signal.ITIMER_REAL, max(left, 1e-3))


def never_returned(in_flight: float | None, slowest: float) -> bool:
    """Whether a call that was still running ``in_flight`` seconds when its unit's budget ran out counts as one
    that never returns: longer than :data:`HANG_MULTIPLE` x the slowest evaluation of the same law that
    returned (``slowest`` seconds).  ``None`` (nothing was in flight: the budget ran out between evaluations)
    is no hang."""
    return in_flight is not None and in_flight > HANG_MULTIPLE * slowest


def note_progress(evaluated: int, held: bool, what: str = "samples") -> None:
    """State what the law running inside the current :func:`run_unit` has evaluated so far: ``evaluated``
    ``what`` (samples, partitions), every one of which held when ``held``; the next evaluation starts now.
    Should the unit's budget stop it later, the record is *undecided* (time budget, ``evaluated`` ``what``)
    instead of failed — too few for a verdict, none against the subject — unless the evaluation in flight
    then had run longer than :data:`HANG_MULTIPLE` x the slowest one before it (:func:`never_returned`: a
    call that does not return fails).  Outside a unit it does nothing."""
    if _PROGRESS:
        progress, now = _PROGRESS[-1], time.perf_counter()
        progress.update(evaluated=int(evaluated), held=bool(held), what=what, at=now,
                        slowest=max(progress.get("slowest", 0.0), now - progress["at"]))


#: the progress of the units running now, innermost last (:func:`note_progress`)
_PROGRESS: list[dict] = []


def run_unit(fn: Callable[[], object], *, check: str, subject: str, seconds: float | None = None):
    """``fn()`` under the unit budget (``seconds``, else :func:`current_budget`).  A timeout becomes a
    :class:`verimono.CheckResult` ``check[subject]`` naming the unit and the elapsed time: *undecided*
    (``details["undecided_reason"] == "time budget"``) when the law inside stated, through
    :func:`note_progress`, that everything it evaluated before held; *failed* otherwise — a subject whose
    first call never returns, or a law that had already seen a violation.

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
        evaluated, what = progress.get("evaluated", 0), progress.get("what", "samples")
        what = what[:-1] if evaluated == 1 and what.endswith("s") else what
        if not evaluated:
            return new_record(check, subject, FAILED, message=f"timed out: {exc}", duration=elapsed, details=details)
        in_flight, slowest = time.perf_counter() - progress["at"], progress["slowest"]
        details.update(evaluated=evaluated, in_flight=in_flight, slowest=slowest)
        if not progress.get("held"):
            return new_record(check, subject, FAILED, message=f"timed out: {exc} (after {evaluated} {what}, not all "
                                                               "of which held)", duration=elapsed, details=details)
        if never_returned(in_flight, slowest):
            return new_record(check, subject, FAILED, duration=elapsed, details=details,
                               message=f"timed out: {exc}; the evaluation in flight ran {in_flight:.1f} s, more than "
                                       f"{HANG_MULTIPLE:g}x the slowest of the {evaluated} {what} before it "
                                       f"({slowest:.3g} s): a call that does not return")
        details["undecided_reason"] = TIME_BUDGET_REASON
        return new_record(check, subject, UNDECIDED, duration=elapsed, details=details,
                           message=f"time budget exhausted after {evaluated} {what}, all of which held ({exc}): "
                                   "too few for a verdict")
    finally:
        _PROGRESS.pop()


__all__ = ["budget", "current_budget", "budget_source", "stage_budget", "calibration", "in_seconds", "time_limit",
           "run_unit", "note_progress", "never_returned", "supported", "explicit_budget", "unlimited",
           "TIME_BUDGET_REASON", "HANG_MULTIPLE"]
