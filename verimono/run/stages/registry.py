"""The verification run as a list of *stages*: a small registry ``name → callable(profile, context) → Report``.

``verimono run`` runs every registered stage in order (or those named with ``--stage``), merges their
reports and records, per stage, its status, record count and duration in ``report.meta["stages"]``.

A stage never prints and never raises: :func:`run_stages` judges what a stage raised by the checks' one
exception policy (:func:`verimono.checks.core.classify`) — :class:`verimono.StageUnavailable`, data that
are absent, is one *skipped* record ``stage[<name>]``, so a missing battery is counted and the gate sees
the count of checks shrink; anything else, a crash, one *failed* record with its traceback.

To add a battery::

    from verimono.run.stages import register_stage

    @register_stage("my_laws", "what it verifies")
    def my_laws(profile, context):          # profile: verimono.execution.profiles.Profile; context: RunContext
        return check_something(context.stepper, seed=context.seed)     # a verimono.Report

This module is the registry: :func:`register_stage` writes the table of stages (:mod:`.table`: :class:`Stage`,
:data:`STAGES`, :func:`default_stages`) and :func:`prepare_stages` runs their ``prepare``.  It re-exports the names
that lived here before they had modules of their own, one job each:

- :mod:`.context` — :class:`RunContext`, what every stage may use, and its ``run_units``;
- :mod:`.results` — :class:`StageResults`, the results one stage writes for later ones, checking undeclared reads;
- :mod:`.current` — the stage the current thread runs;
- :mod:`.unit_timing` — :func:`timed_unit`, :data:`UNIT_TIME`, :func:`expected_costs`;
- :mod:`.ordering` — the stages in the order of what they read (``after=``);
- :mod:`.runner` — :func:`run_stages`, the run's loop over the stages;
- :mod:`.one_stage` — one stage's report and ``meta["stages"]`` entry, a stage that raised;
- :mod:`.together` — stages at once on the shared queue, each in a thread of its own;
- :mod:`.stopper` — stopping and joining those threads when the run is interrupted;
- :mod:`.data_folder` — :func:`locate_data`, the siconos stage's data folder.
"""

from __future__ import annotations

from typing import Callable, Iterable

from ...execution.profiles import Profile
from ...records.results import Report
from .context import RunContext
from .data_folder import locate_data
from .results import StageResults
from .runner import run_stages
from .table import STAGES, Stage, default_stages
from .unit_timing import UNIT_TIME, expected_costs, timed_unit
# names imported from this module before they had modules of their own: still importable here.  A test that
# patches one patches it where it is looked up (e.g. ``together._join_all``, ``runner._run_together``): a patch of
# this module's copy would not take effect.
from .ordering import _some_run_at_once  # noqa: F401
from .stopper import _SET_ASYNC_EXC, _Stopper, _join_all  # noqa: F401


def prepare_stages(names: Iterable[str] | None, profile: Profile, context: RunContext) -> None:
    """Each stage's ``prepare`` (:class:`Stage`) for the stages ``names`` (``None``: the default ones); one that
    raises is left to its stage, which meets the same error and records it."""
    for n in default_stages() if names is None else names:
        stage = STAGES.get(n)
        if stage is not None and stage.prepare is not None:
            try:
                stage.prepare(profile, context)
            except Exception:  # noqa: BLE001 - the stage itself reports it
                pass


def register_stage(name: str, description: str = "", *, default: bool = True,
                   prepare: Callable[[Profile, RunContext], None] | None = None, overlap: bool = False,
                   after: Iterable[str] = (), writes: Iterable[str] = ()) -> Callable:
    """Decorator registering ``fn(profile, context) -> Report`` as the stage ``name`` (replaces same name);
    ``default=False``: a stage on request; ``prepare``: run before the workers start; ``overlap``: may run at
    once with other such stages; ``after``: the stages it reads the results of — reading a result of a stage of
    the same run that is not declared there raises :class:`verimono.core.errors.UndeclaredStageRead` (a failed
    ``stage[name]`` record); ``writes``: the :class:`RunContext` results it writes (``"costs"``,
    ``"partitions"``) (:class:`Stage`)."""

    def deco(fn: Callable[[Profile, RunContext], Report]) -> Callable:
        STAGES[name] = Stage(name, fn, description or (fn.__doc__ or "").strip().split("\n")[0], default, prepare,
                             overlap, tuple(after), tuple(writes))
        return fn

    return deco


__all__ = ["STAGES", "Stage", "StageResults", "default_stages", "RunContext", "register_stage", "run_stages", "prepare_stages", "locate_data", "timed_unit", "UNIT_TIME", "expected_costs"]
