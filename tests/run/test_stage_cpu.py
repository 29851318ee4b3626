"""What a run records for the gate's CPU verdicts: each stage's CPU time, the part spent in the subject's calls,
and slices of the calibration workload measured beside its units (no durations asserted: the figures'
presence, their bookkeeping, and CPU time that is counted once)."""

from __future__ import annotations

import pickle
import time

import numpy as np
import pytest

import verimono as vm
from verimono.execution.executors import Unit
from verimono.execution.profiles import get_profile
from verimono.execution.timing import TimedStepper, subject_cpu
from verimono.records.results import CheckResult, Report
from verimono.run.stages import STAGES, RunContext, Stage, run_stages
from verimono.run.stages.registry import UNIT_TIME, timed_unit


def spin(seconds: float) -> None:
    t = time.process_time()
    while time.process_time() - t < seconds:
        pass


def stepper(problem, t):
    spin(0.02)
    return vm.solve(problem, t)


stepper.batched = True


def test_a_timed_stepper_is_the_stepper_with_its_claim_name_and_batching():
    timed = TimedStepper(vm.Stepper(stepper, scheme="any", order=2, name="mine"))
    assert timed.fn is stepper and timed.__name__ == "mine" and timed.claim.order == 2 and timed.batched
    again = pickle.loads(pickle.dumps(timed))
    assert isinstance(again, TimedStepper) and again.fn is stepper and again.claim == timed.claim
    assert TimedStepper(stepper).__name__ == "stepper" and TimedStepper(stepper).claim.proximal


def test_a_timed_stepper_counts_its_calls_cpu_once_nested_or_not():
    from verimono.reference import get

    p = get("t|x| (n=1)")
    t = np.linspace(0.0, p.T, 5)
    timed = TimedStepper(stepper)
    outer = TimedStepper(lambda problem, grid: [timed(problem, grid) for _ in range(2)][0])
    s0, n0 = subject_cpu()
    outer(p, t)
    s1, n1 = subject_cpu()
    assert n1 - n0 == 3
    assert 0.04 <= s1 - s0 < 1.0       # two spins of 0.02 s: counted once although the calls were nested


def _work(seconds: float, subject: bool) -> Report:
    if subject:
        from verimono.reference import get

        p = get("t|x| (n=1)")
        TimedStepper(stepper)(p, np.linspace(0.0, p.T, 3))
    spin(seconds)
    return Report([CheckResult("work", f"{seconds}", "passed")])


def test_a_unit_hands_back_its_cpu_time_and_calibration_slices():
    rep = timed_unit(_work, (0.3, True))
    t = rep.meta[UNIT_TIME]
    assert t["cpu"] >= 0.3 and t["wall"] >= 0.3 * 0.5 and t["subject_calls"] == 1 and t["subject_cpu"] >= 0.02
    assert len(t["calibration_cpu"]) == 2 and all(c > 0 for c in t["calibration_cpu"])   # one, +1 per 0.25 s


def test_a_stage_records_its_cpu_its_subjects_share_and_the_calibration_beside_it(monkeypatch):
    """Serially, the units run in this process: the stage's CPU time is this process's, counted once (not once
    more for each unit); the units' calibration slices are the stage's."""
    def stage(profile, context):
        units = [Unit("cpu_probe", f"unit {k}", _work, (0.05 * (k + 1), k == 1)) for k in range(3)]
        out = Report()
        for rep in context.run_units(profile, units):
            out.extend(rep)
        return out

    monkeypatch.setitem(STAGES, "cpu_probe", Stage("cpu_probe", stage, "spins"))
    rep = run_stages(["cpu_probe"], get_profile("dev"), RunContext())
    (info,) = rep.meta["stages"]
    units = sum(0.05 * (k + 1) for k in range(3))
    assert units <= info["cpu"] < units + 0.05 * 3 + 0.5     # the spins, their slices, a little bookkeeping
    assert info["subject_calls"] == 1 and 0.02 <= info["subject_cpu"] < info["cpu"]
    assert len(info["calibration_cpu"]) == 3 and [u["label"] for u in info["units"]] == ["unit 0", "unit 1", "unit 2"]
    assert all(UNIT_TIME not in r.details for r in rep.results)


def test_a_stage_without_units_is_calibrated_after_it(monkeypatch):
    monkeypatch.setitem(STAGES, "cpu_plain", Stage("cpu_plain", lambda profile, context: _work(0.05, False), "spin"))
    (info,) = run_stages(["cpu_plain"], get_profile("dev"), RunContext()).meta["stages"]
    assert info["cpu"] >= 0.05 and len(info["calibration_cpu"]) == 1 and "subject_cpu" not in info


@pytest.mark.slow
def test_units_in_worker_processes_add_their_cpu_time_to_the_stage(monkeypatch):
    from verimono.execution.executors import make_runner

    def stage(profile, context):
        out = Report()
        for rep in context.run_units(profile, [Unit("cpu_probe", f"u{k}", _work, (0.2, k == 0)) for k in range(2)]):
            out.extend(rep)
        return out

    monkeypatch.setitem(STAGES, "cpu_probe", Stage("cpu_probe", stage, "spins"))
    runner = make_runner("process:2")
    try:
        (info,) = run_stages(["cpu_probe"], get_profile("dev"), RunContext(executor=runner)).meta["stages"]
    finally:
        runner.close()
    assert info["cpu"] >= 0.4 and info["subject_calls"] == 1 and len(info["calibration_cpu"]) >= 2   # 1 + per 0.25 s
