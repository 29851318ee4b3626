"""A unit of work — one independent piece of a stage, ``fn(*args) -> Report`` — the record that stands for a
unit that did not finish, and the run configuration units run under.

A unit that raises is judged by the one exception policy (:func:`verimono.records.verdicts.classify`: a limit
of verimono's own solvers is undecided, anything else the subject raised is failed, :func:`unit_raised`); one
whose worker died or that overran the executor's timeout is one failed record (:func:`unit_failure`); both
are ``unit[<stage>: <label>]``.
"""

from __future__ import annotations

import dataclasses
from typing import Any, Callable

from . import config as _config
from . import watchdog
from .config import RunConfig
from ..records.results import FAILED, Report
from ..records.verdicts import classify, new_record

#: the check name of the record that stands for a unit that crashed, died or timed out
UNIT_CHECK = watchdog.UNIT_CHECK


@dataclasses.dataclass
class Unit:
    """One independent piece of a stage: ``fn(*args) -> Report``; ``label`` names it in progress and in
    the failed record that stands for it if it cannot finish."""

    stage: str
    label: str
    fn: Callable[..., Report]
    args: tuple = ()


def unit_record(unit: Unit, status: str, message: str, *, exception: str | None = None,
                traceback_text: str | None = None, duration: float | None = None) -> Report:
    """The report of a unit that did not finish: one record ``unit[<stage>: <label>]`` with ``status``."""
    details: dict[str, Any] = {}
    if exception:
        details["exception"] = exception
    if traceback_text:
        details["traceback"] = traceback_text
    return Report([new_record(UNIT_CHECK, f"{unit.stage}: {unit.label}", status, message=message,
                              duration=duration, details=details)])


def unit_failure(unit: Unit, message: str, *, traceback_text: str | None = None,
                 duration: float | None = None) -> Report:
    """The report of a unit that did not finish for a reason of its own — its worker died, it ran past the
    executor's timeout: one failed record ``unit[<stage>: <label>]``."""
    return unit_record(unit, FAILED, message, traceback_text=traceback_text, duration=duration)


def raised(exc: BaseException) -> tuple[str, str]:
    """``(status, message)`` of a unit that raised ``exc``: the one exception policy
    (:func:`verimono.records.verdicts.classify`) — a limit of verimono's own solvers is undecided in a unit as
    in a law, a failure of the subject is ``raised <type>: <message>``."""
    status, message = classify(exc)
    return status, ("raised " + message if status == FAILED else message)


def unit_raised(unit: Unit, exc: BaseException, *, traceback_text: str | None = None,
                duration: float | None = None) -> Report:
    """The report of a unit that raised ``exc`` (:func:`raised`)."""
    status, message = raised(exc)
    return unit_record(unit, status, message, exception=type(exc).__name__, traceback_text=traceback_text,
                       duration=duration)


def config_for(profile: RunConfig | str | None) -> RunConfig:
    """The run configuration units run under: ``profile`` itself, or the current one
    (:func:`verimono.execution.config.current`) with the profile named ``profile`` (``None``: as it is)."""
    if isinstance(profile, RunConfig):
        return profile
    cfg = _config.current()
    return cfg if profile is None or profile == cfg.profile else dataclasses.replace(cfg, profile=profile)


__all__ = ["Unit", "UNIT_CHECK", "unit_record", "unit_failure", "unit_raised", "raised", "config_for"]
