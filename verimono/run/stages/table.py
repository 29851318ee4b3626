"""The table of stages: what a stage is (:class:`Stage`), the stages registered so far (:data:`STAGES`, by name, in
registration order) and those a run that names none runs (:func:`default_stages`).  Every other module of the run
reads it; :func:`verimono.run.stages.register_stage` writes it.  (A stage's ``context`` is a
:class:`verimono.run.stages.RunContext`, typed ``Any`` here: that module reads this one.)"""

from __future__ import annotations

import dataclasses
from typing import Any, Callable

from ...execution.profiles import Profile
from ...records.results import Report


@dataclasses.dataclass(frozen=True)
class Stage:
    """A stage: ``fn(profile, context) -> Report``; ``default``: part of a run that names no stage (a stage on
    request runs only when named, ``--stage NAME``, or when ``verimono check`` chooses it for its target)."""
    name: str
    fn: Callable[[Profile, Any], Report]          # (profile, context: a RunContext) -> Report
    description: str = ""
    default: bool = True
    #: ``prepare(profile, context)``, run in this process before the worker processes start (:func:`prepare_stages`):
    #: what the stage's units will unpickle is then imported once, here, and inherited by forked workers
    prepare: Callable[[Profile, Any], None] | None = None
    #: the stage may run at once with the other such stages next to it in the run, its units in one queue with
    #: theirs (:attr:`RunContext.schedule`): its work is in its units and none of its records measures time.  A
    #: timed stage (performance), and a stage registered without saying so, runs alone, as before
    overlap: bool = False
    #: stages whose results this one reads (``context.costs``, ``context.partitions``): when they run in the
    #: same run, it starts once they have ended (reading one not declared: :class:`StageResults`)
    after: tuple[str, ...] = ()
    #: the :class:`RunContext` fields this stage writes for later stages (``"costs"``, ``"partitions"``)
    writes: tuple[str, ...] = ()


STAGES: dict[str, Stage] = {}


def default_stages() -> list[str]:
    """The stages a run that names none runs, in registration order."""
    return [n for n, s in STAGES.items() if s.default]
