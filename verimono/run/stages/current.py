"""The stage the current thread runs (:func:`verimono.run.stages.run_stages` sets it around each stage): the reader
:class:`verimono.run.stages.StageResults` checks, and what ``RunContext.run_units`` tags each unit's times with."""

from __future__ import annotations

import threading


#: the stage the current thread runs (:func:`run_stages`), which ``run_units`` tags each unit's times with
_HERE = threading.local()


def _running_stage() -> str | None:
    return getattr(_HERE, "stage", None)
