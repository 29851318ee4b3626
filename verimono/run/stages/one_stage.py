"""One stage run: its report and its ``meta["stages"]`` entry (status, records, duration, CPU, units, calibration)
(:func:`_run_stage`), and the one record of a stage that raised (:func:`_stage_failure`)."""

from __future__ import annotations

import os
import time
import traceback

from ...checks.core import classify
from ...execution.calibration import slices_after
from ...execution.executors import SerialRunner
from ...execution.profiles import Profile
from ...execution.timing import cpu_now, subject_cpu
from ...records.results import FAILED, SKIPPED, Report
from ...records.verdicts import SUBJECT_EXITS, new_record
from .context import RunContext
from .current import _HERE, _running_stage
from .table import STAGES


def _stage_failure(name: str, exc: BaseException, duration: float) -> tuple[Report, str, str]:
    """The one record of a stage that raised, judged by the checks' exception policy."""
    status, message = classify(exc)
    rec = new_record("stage", name, status, message=message, duration=duration)
    if status == FAILED:
        rec.details["traceback"] = traceback.format_exc(limit=6)
        return Report([rec]), "error", message
    return Report([rec]), "skipped" if status == SKIPPED else status, message


def _run_stage(n: str, profile: Profile, context: RunContext, overlapped: list[str] | None = None
               ) -> tuple[Report, dict]:
    """One stage's report and its ``meta["stages"]`` entry (:func:`run_stages`)."""
    stage = STAGES[n]
    start = time.perf_counter()
    serial = context.executor is None or isinstance(context.executor, SerialRunner)
    # this process's part: all of it when the units run here; else this thread's (it hands out the units
    # and merges what comes back; a report warm-up thread of this process is not the stage's)
    own_cpu = cpu_now if serial else time.thread_time
    cpu0, (subj0, calls0), n_units = own_cpu(), subject_cpu(), len(context.unit_times)
    outer, _HERE.stage = _running_stage(), n      # which stage reads (StageResults) and runs units (run_units)
    try:
        rep = stage.fn(profile, context)
        if not isinstance(rep, Report):
            raise TypeError(f"stage {n} returned {type(rep).__name__}, expected a verimono.Report")
        # a stage whose records all skipped verified nothing: "skipped", never "passed"
        status = ("failed" if rep.failures else "undecided" if rep.undecided else
                  "passed" if rep.verified else "skipped")
        message = rep.summary()
    except (Exception, *SUBJECT_EXITS) as exc:  # noqa: BLE001 - a crash is a failure of the run, recorded
        rep, status, message = _stage_failure(n, exc, time.perf_counter() - start)
    finally:
        _HERE.stage = outer
    duration = time.perf_counter() - start
    units = context.unit_times[n_units:]
    if overlapped is not None:      # the other stages' units came back in between: this stage's only
        units = [u for u in units if u.get("run_stage") == n]
    elsewhere = [u for u in units if u.get("pid") != os.getpid()]
    cpu = own_cpu() - cpu0 + sum(u["cpu"] for u in elsewhere)
    subj1, calls1 = subject_cpu()
    subj = subj1 - subj0 + sum(u.get("subject_cpu", 0.0) for u in elsewhere)
    calls = calls1 - calls0 + sum(u.get("subject_calls", 0) for u in elsewhere)
    info = {"name": n, "status": status, "records": len(rep), "duration": duration, "cpu": cpu,
            "message": message}
    if overlapped is not None:
        info["overlapped"] = list(overlapped)
    if calls:
        info.update({"subject_cpu": subj, "subject_calls": calls})
    slices = [c for u in units for c in u.get("calibration_cpu") or []]
    if not slices or sum(u["cpu"] for u in units) < 0.5 * cpu:   # the stage's work is mostly not its units'
        slices += slices_after(cpu)
    info["calibration_cpu"] = [round(c, 5) for c in slices]
    if units:
        info["units"] = [{"label": u["label"], "cpu": round(u["cpu"], 4), "wall": round(u["wall"], 4)}
                         for u in units]
    for r in rep.results:
        r.details.setdefault("stage", n)
        cx = r.counterexample if isinstance(r.counterexample, dict) else {}
        if isinstance(cx.get("problem"), str) and cx["problem"] in _reference_names():
            r.details.setdefault("reference", cx["problem"])  # `--reference NAME` reproduces it
    return rep, info


def _reference_names() -> frozenset[str]:
    """Names ``verimono run --reference NAME`` accepts (the reference catalog's)."""
    from verimono.reference import names   # the catalog builds every reference: on first use only

    return names()
