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
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Callable, Iterable

from ...core.errors import StageUnavailable, UnknownStage
from ...lcs.siconos import PACKAGED_DATA, siconos_root
from ...execution.profiles import Profile
from ...records.results import Report
from .context import RunContext
from .one_stage import _run_stage
from .ordering import _dependencies_first, _some_run_at_once
from .results import StageResults
from .table import STAGES, Stage, default_stages
from .together import _can_share, _run_together
from .unit_timing import UNIT_TIME, expected_costs, timed_unit


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


def run_stages(names: Iterable[str] | None, profile: Profile, context: RunContext,
               on_start: Callable[[Stage, int, int], None] | None = None,
               on_done: Callable[[Stage, Report, dict], None] | None = None) -> Report:
    """Run the stages ``names`` (``None``: the default ones, in registration order) and merge their reports.

    On worker processes (2 or more, :attr:`RunContext.schedule` ``"shared"``) the stages next to each other in
    ``names`` that may overlap (:attr:`Stage.overlap`) run at once, their units in one queue over the workers
    (:mod:`verimono.execution.schedule`); the report is the same as one stage after another gives — each
    stage's records in its units' order, the stages in ``names``' order, ``on_done`` called in that order as
    each stage and those before it have ended — but a stage's ``duration`` is then the wall time from its start
    to its end while it shared the workers (``info["overlapped"]``: the stages it ran with); its ``cpu`` is its
    units' CPU seconds plus its own thread's, as before."""
    names = default_stages() if names is None else list(names)
    for n in names:
        if n not in STAGES:
            raise UnknownStage(f"unknown stage {n!r}; registered stages: {', '.join(STAGES)}")
    names = _dependencies_first(names)
    total = Report(meta={"stages": []})

    def finish(n: str, rep: Report, info: dict) -> None:
        total.extend(rep)
        total.meta["stages"].append(info)
        if on_done:
            on_done(STAGES[n], rep, info)

    shared = _can_share(context)
    results = [f for f in (context.costs, context.partitions) if isinstance(f, StageResults)]
    for f in results:
        f.run = tuple(names)
    try:
        _run_groups(names, shared, profile, context, on_start, finish)
    finally:
        for f in results:
            f.run = ()
    return total


def _run_groups(names: list[str], shared: bool, profile: Profile, context: RunContext,
                on_start: Callable[[Stage, int, int], None] | None, finish: Callable[[str, Report, dict], None]
                ) -> None:
    """:func:`run_stages`'s loop: each group of stages that may overlap at once, else one after another."""
    i = 0
    while i < len(names):
        group = [names[i]]     # a stage named twice runs twice, one run after the other (a group keys by name)
        while shared and STAGES[group[0]].overlap and i + len(group) < len(names) \
                and STAGES[names[i + len(group)]].overlap and names[i + len(group)] not in group:
            group.append(names[i + len(group)])
        if len(group) > 1 and _some_run_at_once(group) and context.executor.start_all():
            _run_together(group, i, len(names), profile, context, on_start, finish)
        else:
            for k, n in enumerate(group):
                if on_start:
                    on_start(STAGES[n], i + k, len(names))
                finish(n, *_run_stage(n, profile, context))
        i += len(group)


def locate_data(explicit: str | os.PathLike | None = None) -> Path:
    """The data folder of the siconos stage: ``explicit``, else ``$VERIMONO_SHARED`` if it is a folder, else
    the Siconos data shipped in the package (``verimono/data``); a given folder must hold that layout."""
    env = os.environ.get("VERIMONO_SHARED")
    if explicit is not None:
        path = Path(explicit)
    elif env and Path(env).is_dir():
        path = Path(env)
    else:
        return PACKAGED_DATA
    try:
        siconos_root(path)
    except FileNotFoundError as exc:
        raise StageUnavailable(f"data folder {path}: {exc}") from None
    return path


__all__ = ["STAGES", "Stage", "StageResults", "default_stages", "RunContext", "register_stage", "run_stages", "prepare_stages", "locate_data", "timed_unit", "UNIT_TIME", "expected_costs"]
