"""Timing that holds on a busy machine, deterministically tested: the gate's noise-aware stage-time rule,
and the exit status of a run whose only undecided records are speeds the machine was too noisy to judge.  (The estimator and the decision rule:
``tests/test_performance.py``; verdicts on real timings: the benchmark tier.)"""

from __future__ import annotations

import copy

from verimono import timing
from verimono.gate import CALIBRATION_DRIFT, TIMING_GROWTH, compare
from verimono.results import PASSED, UNDECIDED, CheckResult, Report


# -- the gate: stage times judged only on a quiet machine ------------------------------------------------------


def run_report(duration: float, calibrations: list[float], cpu_waiting: float | None = 0.01) -> Report:
    rep = Report([CheckResult("monotone", "Box", PASSED, worst=0.5, bound=1.0)])
    stage = {"name": "operator_laws", "duration": duration, "status": "passed", "records": 1}
    if cpu_waiting is not None:
        stage["cpu_waiting"] = cpu_waiting
    rep.meta.update({"command": "run", "profile": "ci", "target": None, "calibrations": calibrations,
                     "calibration": min(calibrations), "stages": [stage]})
    return Report.from_dict(rep.to_dict())


BASE = run_report(4.0, [0.05, 0.051])


def stage_changes(cur: Report):
    comp = compare(BASE, cur)
    return comp.regressions, [c for c in comp.others if c.kind == "timing"]


def test_a_3x_stage_slowdown_on_a_quiet_machine_regresses():
    regs, _ = stage_changes(run_report(12.0, [0.05, 0.051]))
    assert [c.key for c in regs] == ["stage operator_laws"]
    # still caught with the largest drift the rule accepts: units taken at the slower calibration
    regs, _ = stage_changes(run_report(12.0, [0.05, 0.05 * CALIBRATION_DRIFT]))
    assert [c.key for c in regs] == ["stage operator_laws"]
    regs, _ = stage_changes(run_report(4.0 * 1.9, [0.05, 0.05]))           # below 2x: nothing
    assert not regs


def test_a_grown_stage_time_on_a_busy_machine_is_not_judged():
    # other work shared the cores during the stage (PSI): the growth is reported, not a regression
    regs, others = stage_changes(run_report(12.0, [0.05, 0.051], cpu_waiting=0.7))
    assert not regs and len(others) == 1 and "not judged" in others[0].message and "70%" in others[0].message
    # the machine's speed changed between the run's start and end: no single unit describes the stage
    regs, others = stage_changes(run_report(16.0, [0.05, 0.08], cpu_waiting=None))
    assert not regs and "calibrations at the run's start and end differ by 1.60x" in others[0].message
    # without PSI and with agreeing calibrations the stage time is judged (the calibration alone as evidence)
    regs, _ = stage_changes(run_report(12.0, [0.05, 0.051], cpu_waiting=None))
    assert [c.key for c in regs] == ["stage operator_laws"]


def test_a_timing_noise_undecided_record_is_a_change_not_a_regression():
    base = Report([CheckResult("performance_per_step", "box n=3", PASSED, worst=0.8, bound=1.0,
                               details={"timing_ratio": 1.2, "timing_interval": [1.18, 1.22]}),
                   CheckResult("law", "Box", PASSED)])
    base.meta.update({"command": "run", "profile": "ci"})
    cur = Report.from_dict(copy.deepcopy(base.to_dict()))
    cur.results[0].status = UNDECIDED
    cur.results[0].details.update({"undecided_reason": timing.NOISE_REASON, "timing_interval": [1.1, 1.7]})
    comp = compare(base, cur)
    assert comp.ok and any(c.kind == "status" and "undecided" in c.message for c in comp.others)
    cur.results[1].status = UNDECIDED            # undecided for another reason: still a regression
    assert [c.key for c in compare(base, cur).regressions] == ["law[Box]"]
    assert TIMING_GROWTH == 2.0


# -- the exit status and summary of a run -----------------------------------------------------------------------


def test_speed_that_could_not_be_judged_does_not_fail_the_run(tmp_path, capsys):
    from verimono.cli import EXIT_OK, EXIT_UNDECIDED, _exit_status, _finish

    noisy = CheckResult("performance_lcs_step", "DiodeBridge", UNDECIDED, worst=1.1, bound=1.0,
                        details={"undecided_reason": timing.NOISE_REASON})
    rep = Report([CheckResult("law", "Box", PASSED), noisy])
    rep.meta.update({"command": "run", "profile": "ci"})
    assert _exit_status(rep) == EXIT_OK
    assert _finish(rep, tmp_path, None) == EXIT_OK
    out = capsys.readouterr().out
    assert "speed could not be judged here: 1 timing record undecided" in out
    rep.add(CheckResult("law", "Ball", UNDECIDED, message="the search cannot draw inputs this large"))
    assert _exit_status(rep) == EXIT_UNDECIDED      # any other undecided record still exits 2
    rep.add(CheckResult("law", "Cone", "failed"))
    assert _exit_status(rep) == 1
