"""The run's checkpoint (``results.json.partial``) made from pieces written once per stage
(:class:`verimono.run.execute._Checkpoint`) is the document the whole partial report writes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from verimono.records.results import CheckResult, Report, load
from verimono.run.execute import _Checkpoint

BASELINE = Path(__file__).resolve().parents[2] / "reports" / "baseline.json"


def _numpy_record() -> CheckResult:
    """A record whose fields hold what a check's do before they are saved: NumPy scalars and arrays, non-finite
    floats (written as strings), a nested tuple."""
    return CheckResult("resolvent_nonexpansive", "planted", "failed", worst=np.float64(1.5), bound=1.0,
                       message="x", details={"x": np.array([1.0, np.nan]), "k": np.int64(3), "inf": np.inf,
                                             "flag": np.bool_(True), "pair": (np.float32(0.5), None)})


def _document(text: str) -> dict:
    doc = json.loads(text)
    doc.pop("created")
    doc["meta"].pop("created", None)
    return doc


def test_the_pieces_joined_are_the_partial_reports_document():
    base = load(BASELINE)
    stages = [Report(base.results[:40], base.studies[:3], {}, base.trajectories[:2]),
              Report([_numpy_record()]),                                   # no study, no trajectory: empty pieces
              Report(base.results[40:90], base.studies[3:5], {}, base.trajectories[2:4])]
    previous = Report(base.results[90:95], base.studies[5:6], {"stages": [{"name": "before"}]}, [])
    saved, partial = _Checkpoint(previous), Report(meta={"run_id": "r", "stages": [{"name": "s"}]}).extend(previous)
    for rep in stages:
        saved.add(rep)
        partial.extend(rep)
        meta = {"run_id": "r", "stages": [{"name": "s"}]}
        assert _document(saved.text(dict(meta))) == _document(Report(partial.results, partial.studies, dict(meta),
                                                                      partial.trajectories).to_json())
    text = saved.text({"run_id": "r"})
    assert list(json.loads(text)) == list(json.loads(partial.to_json()))   # the keys in the schema's order
    back = Report.from_json(text)
    assert back.counts == partial.counts and back.counts["failed"] == 1 and len(back.studies) == 6


def test_an_empty_checkpoint_is_a_readable_document():
    back = Report.from_json(_Checkpoint(None).text({"run_id": "r"}))
    assert len(back) == 0 and back.studies == [] and back.trajectories == []


def test_a_resumed_run_has_the_finished_convergence_stages_grids_and_costs(tmp_path):
    """``verimono run --resume`` after the convergence stage: the trajectory laws judge the stepper on the
    convergence studies' grids too (``context.partitions``); rebuilt from the results file they are the grids
    the uninterrupted run had (without them, 21 trajectory_laws worst ratios of a resumed ci run differed)."""
    from verimono.execution.profiles import get_profile
    from verimono.reference import catalog
    from verimono.run.stages import RunContext, run_stages
    from verimono.run.stages.builtin import restore_convergence

    problems = [p for p in catalog() if p.name in ("moving half-space", "linear x' = -Mx")]
    ran = RunContext(problems=problems, seed=0)
    report = run_stages(["convergence"], get_profile("ci"), ran)
    assert sorted(ran.partitions) == sorted(p.name for p in problems)
    report.meta["incomplete"] = True
    path = tmp_path / "results.json"
    path.write_text(report.to_json())
    resumed = RunContext(problems=problems, seed=0)
    restore_convergence(load(path), resumed)
    assert resumed.partitions == ran.partitions
    assert sorted(resumed.costs) == sorted(ran.costs)
    nothing = RunContext(problems=problems, seed=0)      # a run that had not finished its convergence stage
    restore_convergence(Report(meta={"stages": [{"name": "operator_laws", "units": []}]}), nothing)
    assert nothing.partitions == {} and nothing.costs == {}


def test_a_stage_is_saved_before_the_console_says_it_finished():
    """``[2/7] operator_laws: passed`` was printed before that stage's checkpoint was written: a run killed
    (SIGKILL) in between — seen in a SIGKILL 10 s into a ci run — showed the stage finished, and ``--resume`` ran it again
    ("finished: convergence").  The checkpoint (``on_done``) now comes first."""
    from verimono.records.verdicts import new_record
    from verimono.run.execute import execute
    from verimono.run.progress import Progress
    from verimono.run.stages import STAGES, RunContext, register_stage

    events = []

    class _Line(Progress):
        def done(self, stage, report, info):
            events.append(("line", stage.name))

    class _Calibrated:
        def times(self):
            return 0.1, [0.1]

    for name in ("ck_a", "ck_b"):
        register_stage(name)(lambda profile, context, name=name: Report([new_record("square", name, "passed")]))
    try:
        execute(command="run", profile_name="ci", stages=["ck_a", "ck_b"], context=RunContext(seed=0),
                progress=_Line(enabled=False), calibration=_Calibrated(),
                on_done=lambda stage, rep, info: events.append(("saved", stage.name)))
    finally:
        for name in ("ck_a", "ck_b"):
            STAGES.pop(name, None)
    assert events == [("saved", "ck_a"), ("line", "ck_a"), ("saved", "ck_b"), ("line", "ck_b")]
