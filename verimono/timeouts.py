"""Time budgets for units of work: a resolvent or stepper that never returns must not hang a run.

A *unit* is one law on one operator, or one check of one stepper.  Its budget is, in order: the innermost
:func:`budget` block, in seconds (``verimono run/check --timeout S`` opens one around the whole run), else
the active profile's ``unit_budget`` (:mod:`verimono.profiles`), stated in *calibration units*: multiples of
:func:`verimono.calibration.calibrate`, a fixed NumPy-and-Python workload.  In seconds that is ``units x`` the
calibration measured in this process (:func:`calibration`: measured once, best of 3, about 0.2 s, then
cached; ``verimono run`` supplies the one it measures at its start), so a slower or busier machine — where
the workload, like everything else, takes longer — gets proportionally more time, and a unit is stopped
for not finishing, not for running on a loaded runner.  Stage budgets (:func:`stage_budget`) are stated the
same way.  :func:`time_limit` enforces a budget with ``SIGALRM`` (a one-shot real-time timer): the unit's
code is interrupted where it is — inside a user's Python loop too — and :class:`verimono.UnitTimeout` is
raised at the ``with`` block, naming the unit and the elapsed time.  :func:`run_unit` turns that into a
*failed* record so the run goes on.

The interrupt is raised as an internal ``BaseException`` while it travels through the unit's code, so a
check's own ``except Exception`` (which turns an operator's error into a failed sample) or hypothesis'
shrinking cannot swallow or replay it.  Limits: only in the main thread of a POSIX process (elsewhere the
unit runs unbounded, which the record says), and code blocked inside one long C call is interrupted only
when it returns to Python.
"""

from __future__ import annotations

import math
import signal
import threading
import time
from contextlib import contextmanager
from typing import Callable, Iterator

from .errors import InvalidCheckArgument, UnitTimeout
from . import calibration as _calibration
from .profiles import Profile, UnknownProfile, active_profile, get_profile
from .results import FAILED, CheckResult

_OVERRIDE: list[float | None] = []


class _Expired(BaseException):
    """Raised by the timer inside the unit; becomes :class:`UnitTimeout` at the ``time_limit`` boundary."""


def _positive(seconds: float | None, what: str = "timeout") -> float | None:
    if seconds is None:
        return None
    try:
        s = float(seconds)
    except (TypeError, ValueError):
        raise InvalidCheckArgument(f"{what} must be a number of seconds > 0, got {seconds!r}") from None
    if not (s > 0 and math.isfinite(s)):
        raise InvalidCheckArgument(f"{what} must be a number of seconds > 0, got {seconds!r}")
    return s


@contextmanager
def budget(seconds: float | None) -> Iterator[None]:
    """Within the block, every unit's budget is ``seconds`` (``None``: back to the profile default)."""
    _OVERRIDE.append(_positive(seconds))
    try:
        yield
    finally:
        _OVERRIDE.pop()


def calibration() -> float:
    """Seconds of the calibration workload in this process (:func:`verimono.calibration.calibration`: measured
    once and cached; :func:`verimono.calibration.set_calibration` supplies one measured elsewhere)."""
    return _calibration.calibration()


def in_seconds(units: float) -> float:
    """Seconds of ``units`` calibration units on this machine: ``units x`` :func:`calibration`."""
    return float(units) * calibration()


def _profile() -> Profile | None:
    try:
        return get_profile(active_profile())
    except UnknownProfile:
        return None


def budget_source() -> dict[str, object]:
    """Where the budget of a unit started now comes from: ``{"seconds": S, "source": "explicit"}`` inside a
    :func:`budget` block; else ``{"seconds": S, "source": "profile <name>", "units": U, "calibration": C}``
    with ``S = U x C``; ``{"seconds": None, ...}`` when there is none (an unknown profile)."""
    if _OVERRIDE and _OVERRIDE[-1] is not None:
        return {"seconds": _OVERRIDE[-1], "source": "explicit"}
    profile = _profile()
    if profile is None:
        return {"seconds": None, "source": "none"}
    cal = calibration()
    return {"seconds": profile.unit_budget * cal, "source": f"profile {profile.name}", "units": profile.unit_budget,
            "calibration": cal}


def current_budget() -> float | None:
    """Seconds a unit started now may take: the innermost :func:`budget` (explicit seconds), else the active
    profile's ``unit_budget`` calibration units x :func:`calibration`; ``None`` for an unknown profile."""
    if _OVERRIDE and _OVERRIDE[-1] is not None:
        return _OVERRIDE[-1]
    profile = _profile()
    return None if profile is None else in_seconds(profile.unit_budget)


def stage_budget(stage: str, profile: str | Profile | None = None) -> float | None:
    """Seconds stage ``stage`` may take at ``profile`` (default: the active one): its budget in calibration
    units (:data:`verimono.profiles.STAGE_BUDGETS` x the profile's ``stage_budget_scale``) x
    :func:`calibration`; ``None`` when no budget is stated for it."""
    p = profile if isinstance(profile, Profile) else get_profile(profile or active_profile())
    units = p.stage_budget_units(stage)
    return None if units is None else in_seconds(units)


def supported() -> bool:
    """Whether :func:`time_limit` can interrupt here (POSIX timer, main thread)."""
    return hasattr(signal, "setitimer") and threading.current_thread() is threading.main_thread()


@contextmanager
def time_limit(seconds: float | None, unit: str) -> Iterator[None]:
    """Run the block for at most ``seconds``; :class:`UnitTimeout` naming ``unit`` when it takes longer.

    Nested limits keep the tighter one: an outer limit that expires first still fires (as the outer
    unit's timeout).  ``seconds=None`` or an unsupported context (:func:`supported`) runs unbounded.
    """
    seconds = _positive(seconds)
    if seconds is None or not supported():
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


def run_unit(fn: Callable[[], object], *, check: str, subject: str, seconds: float | None = None):
    """``fn()`` under the unit budget (``seconds``, else :func:`current_budget`); a timeout becomes a
    *failed* :class:`verimono.CheckResult` ``check[subject]`` naming the unit and the elapsed time."""

    limit = current_budget() if seconds is None else seconds
    start = time.perf_counter()
    try:
        with time_limit(limit, f"{check} on {subject}"):
            return fn()
    except UnitTimeout as exc:
        elapsed = time.perf_counter() - start
        details: dict[str, object] = {"timeout": limit, "elapsed": elapsed}
        if seconds is None:
            details["budget"] = budget_source()
        return CheckResult(check, subject, FAILED, message=f"timed out: {exc}", duration=elapsed, details=details)


__all__ = ["budget", "current_budget", "budget_source", "stage_budget", "calibration", "in_seconds", "time_limit",
           "run_unit", "supported"]
