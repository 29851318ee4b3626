"""The ``performance`` stage: its records, a slowed or wrong subject failing them, and the gate on ratios."""

from __future__ import annotations

import time

import numpy as np
import pytest

from verimono import performance
from verimono.gate import TIMING_GROWTH, compare
from verimono.profiles import get_profile
from verimono.results import FAILED, PASSED, Report
from verimono.stages import STAGES, RunContext
from verimono.stepping import solve

#: small enough for the test run; the memory study keeps the ci size (below ~75 000 steps its fixed
#: per-block buffers exceed one trajectory, so the record would fail by construction)
SMALL = performance.Sizes(per_step_steps=3000, per_step_rounds=3, ensemble_batch=300, ensemble_steps=10,
                          ensemble_rounds=2, lcs_steps=300, lcs_rounds=3,
                          memory_steps=performance.SIZES["ci"].memory_steps, lcs_batch=100, lcs_batch_steps=50,
                          lcs_batch_rounds=2)


def slow_solve(problem, t):
    """``solve`` doing 20 times the work: a per-step regression the records must catch."""
    for _ in range(19):
        solve(problem, t)
    return solve(problem, t)


def test_stage_records_names_and_statuses(monkeypatch):
    monkeypatch.setitem(performance.SIZES, "ci", SMALL)
    seen = []
    rep = STAGES["performance"].fn(get_profile("ci"), RunContext(progress=lambda d, n, label: seen.append(label)))
    assert isinstance(rep, Report)
    names = [r.check for r in rep]
    assert names == ["performance_per_step"] * 9 + ["performance_ensemble"] * 3 + \
        ["performance_lcs_step", "performance_lcs_batch", "performance_memory"]
    assert [r.subject for r in rep.by_check("performance_per_step")] == \
        [f"{k} n={n}" for k in ("t|x|", "box", "ball") for n in (1, 3, 10)]
    assert len({r.key for r in rep}) == len(rep)
    for r in rep:   # pass or fail is the benchmarks' business (timing); here: the records state it right
        d = r.details
        assert r.bound == 1.0 and r.status == (PASSED if r.worst <= 1.0 else FAILED), str(r)
        assert {"timing_ratio", "ratio", "target", "rounds", "subject_s", "baseline_s"} <= set(d)
        assert len(d["subject_s"]) == len(d["baseline_s"]) == d["rounds"]
        speedup = d["direction"] == ">="
        assert d["timing_ratio"] == pytest.approx(1 / d["ratio"] if speedup else d["ratio"])
        assert r.worst == pytest.approx(d["target"] / d["ratio"] if speedup else d["ratio"] / d["target"])
    assert seen[-1] == "" and len(seen) == len(rep) + 1
    Report.from_dict(rep.to_dict())  # serialisable into results.json


@pytest.mark.timing
def test_a_slowed_stepper_fails_the_per_step_record():
    rec = performance.check_per_step("box", 3, steps=2000, rounds=3, stepper=slow_solve)
    assert rec.status == FAILED and rec.details["identical"]
    assert rec.details["ratio"] > 5 * performance.PER_STEP_TARGET and rec.worst > 1
    assert "target ≤ 1.5x" in rec.message


@pytest.mark.timing
def test_a_slowed_operator_kernel_fails_the_per_step_record(monkeypatch):
    import verimono.stepping as stepping

    kernel = stepping.resolvent_kernel

    def sleepy(op, x0):
        step = kernel(op, x0)

        def slow(x, lam, t):
            time.sleep(2e-5)
            return step(x, lam, t)
        return slow

    monkeypatch.setattr(stepping, "resolvent_kernel", sleepy)
    rec = performance.check_per_step("t|x|", 1, steps=1000, rounds=3)
    assert rec.status == FAILED and rec.details["identical"], rec


@pytest.mark.timing
def test_a_lost_vectorisation_fails_the_ensemble_record():
    def row_by_row(problem, t):  # the batch solved one member at a time: right values, no speed-up
        if problem.x0.ndim == 1:
            return solve(problem, t)
        import verimono as vm

        return np.stack([solve(vm.Problem(problem.operator, x, problem.T, initial_jump=problem.initial_jump), t).x
                         for x in problem.x0], axis=1)

    op, kw = performance.ensemble_case("box")
    rec = performance.check_ensemble(op, "box", batch=100, steps=5, rounds=2, problem_kw=kw, stepper=row_by_row)
    assert rec.status == FAILED and rec.details["identical"]
    assert rec.details["ratio"] < 3 and rec.details["timing_ratio"] > 1 / 3


def test_a_ratio_past_its_target_fails_the_record():
    """The clock-free counterpart of the three timed tests above (tier ``timing``): the record's verdict from
    given round times — a subject 3x its baseline fails a ≤ 1.5x target, 1.2x passes; a batch only 10x
    faster fails a ≥ 30x speed-up target, 100x passes; the median of the rounds decides."""
    per_step = performance.PER_STEP_TARGET
    slow = performance.ratio_record("performance_per_step", "box n=3", [3.0, 2.9, 3.1], [1.0] * 3, target=per_step)
    assert slow.status == FAILED and slow.details["ratio"] == pytest.approx(3.0) and slow.worst == pytest.approx(2.0)
    assert "target ≤ 1.5x" in slow.message and slow.counterexample["ratio"] == pytest.approx(3.0)
    ok = performance.ratio_record("performance_per_step", "box n=3", [1.2, 9.0, 1.1], [1.0] * 3, target=per_step)
    assert ok.status == PASSED and ok.details["ratio"] == pytest.approx(1.2)       # one slow round: the median
    ens = performance.ENSEMBLE_TARGET
    lost = performance.ratio_record("performance_ensemble", "box B=100", [0.1] * 3, [1.0] * 3, target=ens, speedup=True)
    assert lost.status == FAILED and lost.details["ratio"] == pytest.approx(10.0) and lost.worst == pytest.approx(3.0)
    fast = performance.ratio_record("performance_ensemble", "box B=100", [0.01] * 3, [1.0] * 3, target=ens, speedup=True)
    assert fast.status == PASSED and fast.details["timing_ratio"] == pytest.approx(0.01)


def test_different_results_fail_the_record_without_raising():
    def off(problem, t):
        return solve(problem, t).x * (1 + 1e-15)

    rec = performance.check_per_step("ball", 3, steps=500, rounds=1, stepper=off)
    assert rec.status == FAILED and not rec.details["identical"] and "differ" in rec.message

    def off_batch(problem, t):
        x = solve(problem, t).x
        return x + 1e-12 if x.ndim == 3 else x

    op, kw = performance.ensemble_case("t|x|")
    rec = performance.check_ensemble(op, "t|x|", batch=50, steps=5, rounds=1, problem_kw=kw, stepper=off_batch)
    assert rec.status == FAILED and not rec.details["identical"] and "differs" in rec.message


def test_the_gate_flags_a_doubled_timing_ratio():
    base = Report([performance.ratio_record("performance_per_step", "box n=3", [1.1, 1.2, 1.0], [1.0] * 3,
                                            target=performance.PER_STEP_TARGET),
                   performance.ratio_record("performance_ensemble", "box B=1000", [0.01] * 3, [1.0] * 3,
                                            target=performance.ENSEMBLE_TARGET, speedup=True)])
    base = Report.from_dict(base.to_dict())

    def scaled(factor):
        cur = Report.from_dict(base.to_dict())
        for r in cur:
            r.details["timing_ratio"] *= factor
        return cur

    assert compare(base, scaled(0.95 * TIMING_GROWTH)).ok  # noise below the allowed growth
    regs = compare(base, scaled(1.05 * TIMING_GROWTH)).regressions
    assert sorted(c.key for c in regs) == ["performance_ensemble[box B=1000]", "performance_per_step[box n=3]"]
    assert all(c.kind == "timing" for c in regs)
    # a speed-up that more than halved (100x → 48x): regressed even while it still passes its target
    halved = performance.ratio_record("performance_ensemble", "box B=1000", [0.021] * 3, [1.0] * 3,
                                      target=performance.ENSEMBLE_TARGET, speedup=True)
    assert halved.status == PASSED
    cur = Report([base[0], halved])
    assert [c.key for c in compare(base, cur).regressions] == ["performance_ensemble[box B=1000]"]


def test_the_report_shows_the_measured_ratios():
    from verimono.report.html import render

    rep = Report([performance.ratio_record("performance_ensemble", "box B=1000", [0.01, 0.012, 0.011], [1.0] * 3,
                                           target=performance.ENSEMBLE_TARGET, speedup=True),
                  performance.ratio_record("performance_per_step", "box n=3", [2.0] * 3, [1.0] * 3,
                                           target=performance.PER_STEP_TARGET)])
    html = render(rep)
    section = html[html.index('<section id="performance">'):html.index('<section id="timings">')]
    assert "90.9x speed-up" in section and "≥ 30" in section and "83.3 – 100" in section
    assert "2x" in section and "≤ 1.5" in section and '<tr class="failed">' in section
    assert "No performance records" in render(Report())


@pytest.mark.slow
def test_the_memory_record_holds_in_a_fresh_process():
    """The study's peak is the study's, not the imports and caches of a process's first study: in a fresh
    process (as under ``--executor process:N``, whose workers ran the earlier stages, or ``--stage
    performance`` alone) the record failed at 2.2x one trajectory before its untraced warm-up."""
    import json
    import subprocess
    import sys

    code = ("import json; from verimono.performance import SIZES, check_memory; "
            "r = check_memory(steps=SIZES['ci'].memory_steps); print(json.dumps([r.status, r.details['ratio']]))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    status, ratio = json.loads(out.stdout.strip().splitlines()[-1])
    assert status == PASSED and ratio <= performance.MEMORY_TARGET, (status, ratio)


@pytest.mark.slow
def test_a_study_that_holds_whole_trajectories_fails_the_memory_record():
    """A stepper returning whole arrays (any user stepper: only verimono's own solve streams) makes the study
    hold a trajectory of every grid: the record must fail (2.3x measured), not pass on the coarse grids."""
    rec = performance.check_memory(steps=performance.SIZES["ci"].memory_steps,
                                   stepper=lambda problem, t: solve(problem, t))
    assert rec.status == FAILED and rec.details["ratio"] > performance.MEMORY_TARGET, rec


@pytest.mark.slow
def test_on_worker_processes_the_memory_record_runs_beside_the_timed_ones(monkeypatch):
    """With an idle worker the memory record (bytes, not seconds) runs there while the timed records run
    here; the records, their order and the memory verdict are those of the serial stage."""
    from verimono.executors import ProcessRunner

    monkeypatch.setitem(performance.SIZES, "ci", SMALL)
    runner = ProcessRunner(2)
    try:
        rep = STAGES["performance"].fn(get_profile("ci"), RunContext(executor=runner))
    finally:
        runner.close()
    assert [r.check for r in rep][-3:] == ["performance_lcs_step", "performance_lcs_batch", "performance_memory"]
    assert len(rep) == 15
    mem = rep.results[-1]
    assert mem.status == PASSED and mem.details["ratio"] <= performance.MEMORY_TARGET, str(mem)
