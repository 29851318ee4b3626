"""Running the stages of a run (:func:`run_stages`): each after those it reads (:mod:`.ordering`), the groups of
stages that may overlap at once on the shared queue (:mod:`.together`), the others one after another
(:mod:`.one_stage`), their reports merged in the stages' order."""

from __future__ import annotations

from typing import Callable, Iterable

from ...core.errors import UnknownStage
from ...execution.profiles import Profile
from ...records.results import Report
from .context import RunContext
from .one_stage import _run_stage
from .ordering import _dependencies_first, _some_run_at_once
from .results import StageResults
from .table import STAGES, Stage, default_stages
from .together import _can_share, _run_together


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
