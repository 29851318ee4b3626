"""Planted slowdowns against the speed verdicts of the ``performance`` stage (wall-clock: the benchmark tier).

Each test times real code with :mod:`verimono.run.performance`'s records at the stage's ``ci`` sizes (9 interleaved
rounds, up to 27 when the interval straddles the target) and checks the verdict the record gives:

* a planted 3x slowdown — of the DiodeBridge ``simulate`` kernel (0.8x the floor loop → ~2.4x against a
  2x target; caught here under load 12) and of the per-step loop ``solve`` (1.2-1.3x the bare loop → ~3.6x against 1.5x) — is **never
  passed**.  On a quiet machine it is **failed**; under load it may be ``undecided``, but only with the noise
  evidence to show for it (reason ``"timing noise"``, a wide spread of the rounds);
* the correct code is never failed (passed, or undecided with the noise evidence);
* the old gross regressions (a 20x stepper, a kernel that sleeps, a lost vectorisation) still fail.

Run them idle and under ``../shared/tools/stress -n 2 -- python -m pytest -m timing tests/benchmarks/test_bench_planted.py``.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from verimono import performance, timing
from verimono.records.results import FAILED, PASSED, UNDECIDED
from verimono.core.stepping import solve

#: wall-clock: the ``timing`` tier (``pytest -m timing``, on a quiet machine), never in the default test run
pytestmark = [pytest.mark.benchmark, pytest.mark.timing]

CI = performance.SIZES["ci"]
#: the evidence of a quiet measurement: the per-round ratios' interquartile range within 10% of their median
#: (a 3x slowdown then sits far outside any interval the rule draws)
QUIET_SPREAD = 0.10


def caught(rec) -> None:
    """A planted slowdown: never passed; failed when its rounds were quiet; undecided only with noise shown."""
    d = rec.details
    assert d["identical"], rec.message
    assert rec.status in (FAILED, UNDECIDED), f"a planted 3x slowdown passed: {rec}"
    if rec.status == UNDECIDED:
        assert d["undecided_reason"] == timing.NOISE_REASON and d["noise"]["spread"] > QUIET_SPREAD, rec.message
    if d["spread"] <= QUIET_SPREAD:
        assert rec.status == FAILED, f"quiet rounds (spread {d['spread']:.1%}) but not failed: {rec}"


def not_failed(rec) -> None:
    """Correct code: never failed on timing; undecided only with noise shown."""
    d = rec.details
    assert rec.status in (PASSED, UNDECIDED), f"correct code failed its performance record: {rec}"
    if rec.status == UNDECIDED:
        assert d["undecided_reason"] == timing.NOISE_REASON and d["noise"]["spread"] > QUIET_SPREAD, rec.message


def simulate_kernel_3x(monkeypatch):
    """The LCS kernel path of ``simulate`` (box relation, uniform grid) doing its work three times."""
    from verimono.lcs.system import LinearRelationSystem

    kernel = LinearRelationSystem._simulate_kernel

    def thrice(self, *args, **kw):
        kernel(self, *args, **kw)
        kernel(self, *args, **kw)
        return kernel(self, *args, **kw)

    monkeypatch.setattr(LinearRelationSystem, "_simulate_kernel", thrice)


def solve_3x(problem, t):
    """The per-step loop three times: every step costs three."""
    solve(problem, t)
    solve(problem, t)
    return solve(problem, t)


def test_a_3x_slower_lcs_kernel_fails_its_record(monkeypatch):
    pytest.importorskip("verimono.lcs")
    simulate_kernel_3x(monkeypatch)
    caught(performance.check_lcs_step(steps=CI.lcs_steps, rounds=CI.lcs_rounds, max_rounds=CI.max_rounds))


@pytest.mark.parametrize("kind, n", [("t|x|", 1), ("box", 3), ("ball", 10)])
def test_a_3x_slower_per_step_loop_fails_its_record(kind, n):
    caught(performance.check_per_step(kind, n, steps=CI.per_step_steps, rounds=CI.per_step_rounds,
                                      max_rounds=CI.max_rounds, stepper=solve_3x))


def test_the_correct_lcs_kernel_is_not_failed():
    pytest.importorskip("verimono.lcs")
    not_failed(performance.check_lcs_step(steps=CI.lcs_steps, rounds=CI.lcs_rounds, max_rounds=CI.max_rounds))


@pytest.mark.parametrize("kind, n", [("t|x|", 1), ("box", 3), ("ball", 10)])
def test_the_correct_per_step_loop_is_not_failed(kind, n):
    not_failed(performance.check_per_step(kind, n, steps=CI.per_step_steps, rounds=CI.per_step_rounds,
                                          max_rounds=CI.max_rounds))


# -- gross regressions ---------------------------------------------------------------------------------------


def slow_solve(problem, t):
    """``solve`` doing 20 times the work: a per-step regression the records must catch."""
    for _ in range(19):
        solve(problem, t)
    return solve(problem, t)


def test_a_slowed_stepper_fails_the_per_step_record():
    rec = performance.check_per_step("box", 3, steps=2000, rounds=9, stepper=slow_solve)
    assert rec.status == FAILED and rec.details["identical"]
    assert rec.details["interval"][0] > 5 * performance.PER_STEP_TARGET and rec.worst > 1
    assert "target ≤ 1.5x" in rec.message and "missed with confidence" in rec.message


def test_a_slowed_operator_kernel_fails_the_per_step_record(monkeypatch):
    """A kernel that *sleeps* 20 µs a step: the own-time clock counts what the code waits on itself (only the
    wait for a CPU is taken out), so a regression that blocks is not hidden."""
    if timing.CLOCK != "own":
        pytest.skip("the CPU-time fallback clock does not count sleeping (schedstat unavailable)")
    import verimono.core.stepping as stepping

    kernel = stepping.resolvent_kernel

    def sleepy(op, x0):
        step = kernel(op, x0)

        def slow(x, lam, t):
            time.sleep(2e-5)
            return step(x, lam, t)
        return slow

    monkeypatch.setattr(stepping, "resolvent_kernel", sleepy)
    rec = performance.check_per_step("t|x|", 1, steps=1000, rounds=9)
    assert rec.status == FAILED and rec.details["identical"], rec


def test_a_lost_vectorisation_fails_the_ensemble_record():
    def row_by_row(problem, t):  # the batch solved one member at a time: right values, no speed-up
        if problem.x0.ndim == 1:
            return solve(problem, t)
        import verimono as vm

        return np.stack([solve(vm.Problem(problem.operator, x, problem.T, initial_jump=problem.initial_jump), t).x
                         for x in problem.x0], axis=1)

    op, kw = performance.ensemble_case("box")
    rec = performance.check_ensemble(op, "box", batch=100, steps=5, rounds=9, problem_kw=kw, stepper=row_by_row)
    assert rec.status == FAILED and rec.details["identical"]
    assert rec.details["ratio"] < 3 and rec.details["timing_ratio"] > 1 / 3


# -- the gate on stage times --------------------------------------------------------------------------------


def test_a_3x_slower_stage_is_a_gate_regression_busy_machine_or_not(monkeypatch):
    """Three real runs of a stage doing a fixed amount of work (the calibration workload, about 1 s idle): the
    baseline, the same again, and three times the work.  The same work never regresses; 3x the work
    regresses whether the machine was busy or not (its CPU time against the calibration's CPU time sampled
    beside it: :mod:`verimono.run.gate`)."""
    from verimono.execution.executors import Unit
    from verimono.run.execute import execute
    from verimono.run.gate import compare
    from verimono.records.results import CheckResult, Report
    from verimono.run.stages import STAGES, RunContext, Stage

    work = {"repeats": 17}

    def stage(profile, context):
        units = [Unit("bench_work", f"part {k}", _calibration_work, (work["repeats"] // 4 + (k < work["repeats"] % 4),))
                 for k in range(4)]
        out = Report([CheckResult("work", "fixed", PASSED)])
        for rep in context.run_units(profile, units):
            out.extend(rep)
        return out

    monkeypatch.setitem(STAGES, "bench_work", Stage("bench_work", stage, "a fixed amount of work"))

    def run():
        return execute(command="run", profile_name="ci", stages=["bench_work"], context=RunContext())

    base, same = run(), run()
    work["repeats"] *= 3
    slow = run()
    assert compare(base, same).ok, [str(c) for c in compare(base, same).changes]
    regs = compare(base, slow).regressions
    assert [c.key for c in regs if "CPU time" in c.message] == ["stage bench_work"], [str(c) for c in compare(base, slow).changes]


def _calibration_work(repeats: int):
    from verimono.records.results import Report

    for _ in range(repeats):
        timing.workload()
    return Report()


def test_a_3x_slower_stepper_is_a_gate_regression_and_the_same_stepper_is_not():
    """The issue's case through `verimono check`'s own path (a TimedStepper in the convergence and trajectory
    stages, serially here): a stepper that does its work three times regresses by the CPU time of its calls,
    the unchanged stepper does not."""
    from verimono.execution.timing import TimedStepper
    from verimono.run.execute import execute
    from verimono.run.gate import compare
    from verimono.run.stages import RunContext

    repeat = {"n": 1}

    def my_stepper(problem, t):
        for _ in range(repeat["n"] - 1):
            solve(problem, t)
        return solve(problem, t)

    def run():                  # the whole catalog, as `verimono check`: 0.2-0.5 s of the subject's CPU per stage idle
        ctx = RunContext(stepper=TimedStepper(my_stepper))
        return execute(command="check", profile_name="ci", stages=["convergence", "trajectory_laws"], context=ctx,
                       target="test:my_stepper")

    base, same = run(), run()
    repeat["n"] = 3
    slow = run()
    assert compare(base, same).ok, [str(c) for c in compare(base, same).changes]
    regs = [str(c) for c in compare(base, slow).regressions]
    assert any("test:my_stepper in stage" in m and "in its calls" in m for m in regs), \
        [str(c) for c in compare(base, slow).changes]
