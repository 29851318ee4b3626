"""Unit timing: the CPU and wall seconds of each unit of a stage, measured where the unit ran (:func:`timed_unit`),
handed back in the unit's report (:data:`UNIT_TIME`), and the expected seconds of each unit read from a previous run
(:func:`expected_costs`), which order the shared queue."""

from __future__ import annotations

import os
import time
from typing import Callable

from ...execution.calibration import slices_after
from ...execution.timing import cpu_now, subject_cpu
from ...records.results import Report

#: ``Report.meta`` key under which :func:`timed_unit` hands a unit's times back (popped by ``run_units``)
UNIT_TIME = "unit_time"


def expected_costs(report: Report | None) -> dict[tuple[str, str], float]:
    """The wall seconds of every unit of ``report`` (a baseline, or a previous run's results:
    ``meta["stages"][k]["units"]``) by ``(stage, label)``: the expected costs that order the shared queue
    (:attr:`verimono.run.stages.RunContext.expected`).  Empty for ``None`` or a document without unit figures."""
    out: dict[tuple[str, str], float] = {}
    for stage in (report.meta.get("stages") or []) if report is not None else []:
        if not isinstance(stage, dict):
            continue
        for u in stage.get("units") or []:
            if isinstance(u, dict) and isinstance(u.get("wall"), (int, float)) and isinstance(u.get("label"), str):
                out[(str(stage.get("name")), u["label"])] = float(u["wall"])
    return out


def timed_unit(fn: Callable[..., Report], args: tuple) -> Report:
    """``fn(*args)`` with its times in ``meta[UNIT_TIME]``: ``cpu``, the CPU seconds of the process that ran
    it (:func:`verimono.execution.timing.cpu_now`: a worker process runs one unit at a time, and a subject that computes on
    threads of its own, XLA's, is counted), ``wall``, and ``pid``, so that the run does not count twice the
    units that ran in its own process (a serial run: :func:`run_stages` times those itself); and
    ``calibration_cpu``, slices of the calibration workload measured right after it in the same process
    (:func:`verimono.execution.calibration.slices_after`), what the stage's CPU time is stated against."""
    pid, c0, w0, (s0, n0) = os.getpid(), cpu_now(), time.perf_counter(), subject_cpu()
    rep = fn(*args)
    if isinstance(rep, Report):
        s1, n1 = subject_cpu()
        cpu = cpu_now() - c0
        rep.meta[UNIT_TIME] = {"cpu": cpu, "wall": time.perf_counter() - w0, "pid": pid,
                               "subject_cpu": s1 - s0, "subject_calls": n1 - n0,
                               "calibration_cpu": slices_after(cpu)}
    return rep


__all__ = ["UNIT_TIME", "timed_unit", "expected_costs"]
