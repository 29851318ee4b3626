"""Timing that holds on a busy machine, deterministically tested: time budgets in calibration units
(:mod:`verimono.execution.timeouts`), the gate's noise-aware stage-time rule, and the exit status of a run whose only
undecided records are speeds the machine was too noisy to judge.  (The estimator and the decision rule:
``tests/run/test_performance.py``; verdicts on real timings: the benchmark tier.)"""

from __future__ import annotations

import copy
import time

import pytest

from verimono import calibration, timeouts, timing
from verimono.execution import config as run_config
from verimono.run.gate import CALIBRATION_DRIFT, TIMING_GROWTH, compare
from verimono.execution.profiles import STAGE_BUDGETS, get_profile
from verimono.records.results import PASSED, UNDECIDED, CheckResult, Report


@pytest.fixture
def calibrated():
    """This process's calibration set to 0.1 s for the test, then forgotten (measured again when needed)."""
    timing.set_calibration(0.1)
    yield 0.1
    timing.set_calibration(None)


# -- budgets in calibration units --------------------------------------------------------------------------


def test_unit_budgets_are_calibration_units_times_this_machines_calibration(calibrated, monkeypatch):
    monkeypatch.setattr(run_config, "_STACK", [run_config.RunConfig(profile="ci")])   # the run's configuration
    ci = get_profile("ci")
    assert timeouts.current_budget() == pytest.approx(ci.unit_budget * 0.1)
    src = timeouts.budget_source()
    assert src == {"seconds": pytest.approx(ci.unit_budget * 0.1), "source": "profile ci", "units": ci.unit_budget,
                   "calibration": 0.1}
    timing.set_calibration(0.3)                    # a machine three times slower gets three times the seconds
    assert timeouts.current_budget() == pytest.approx(ci.unit_budget * 0.3)
    assert timeouts.stage_budget("performance") == pytest.approx(STAGE_BUDGETS["performance"] * 0.3)
    assert timeouts.stage_budget("performance", "thorough") == pytest.approx(STAGE_BUDGETS["performance"] * 3.0)
    assert timeouts.stage_budget("no such stage") is None
    with timeouts.budget(5.0):                     # --timeout S: explicit seconds, whatever the calibration
        assert timeouts.current_budget() == 5.0 and timeouts.budget_source() == {"seconds": 5.0, "source": "explicit"}
    assert timeouts.current_budget() == pytest.approx(ci.unit_budget * 0.3)


def test_the_calibration_is_measured_once_and_cached(monkeypatch):
    calls = []
    monkeypatch.setattr(calibration, "calibrate", lambda repeats=3: calls.append(repeats) or 0.05)
    timing.set_calibration(None)
    try:
        assert timeouts.calibration() == 0.05 and timeouts.calibration() == 0.05 and calls == [3]
        assert timeouts.in_seconds(100) == pytest.approx(5.0)
    finally:
        timing.set_calibration(None)
    with pytest.raises(ValueError):
        timing.set_calibration(0.0)


def _in_fresh_python(code: str) -> str:
    import subprocess
    import sys

    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120).stdout


def test_the_first_calibration_is_measured_in_a_forked_copy_and_its_copy_always_reaped():
    """The command line starts its first calibration before its imports (:class:`PendingCalibration`): a
    forked copy measures it (a fresh interpreter: one thread, Linux), answers once, and is reaped — also when
    the answer is never taken; a copy that cannot answer leaves the measurement to this process."""
    import sys

    if not sys.platform.startswith("linux"):
        pytest.skip("the copy is forked on Linux only (elsewhere it is measured in the process: next test)")
    out = _in_fresh_python(
        "import os\n"
        "from verimono.execution.calibration import PendingCalibration, calibrate\n"
        "p = PendingCalibration()\n"
        "forked = p._pid is not None\n"
        "v = p.result()\n"
        "assert v == p.result()\n"                                   # answered once, kept
        "here = calibrate()\n"
        "print(forked, 0.3 < v / here < 3.0)\n"                      # the same workload: the same size
        "q = PendingCalibration(); pid = q._pid; q.close()\n"         # never taken: ended and reaped
        "try:\n    os.waitpid(pid, 0); print('unreaped')\nexcept ChildProcessError:\n    print('reaped')\n"
        "import verimono.execution.calibration as c\n"
        "parent = os.getpid()\n"
        "c.calibrate_times = lambda repeats=3: (0.042, [0.04] * repeats) if os.getpid() == parent else 1 / 0\n"
        "print(PendingCalibration().result())\n")               # the copy failed: measured here
    assert out.split() == ["True", "True", "reaped", "0.042"]


def test_with_another_thread_running_the_first_calibration_is_measured_here(monkeypatch):
    import threading

    calls = []
    monkeypatch.setattr(calibration, "calibrate_times", lambda repeats=3: calls.append(repeats) or (0.05, [0.04]))
    stop = threading.Event()
    other = threading.Thread(target=stop.wait)
    other.start()
    try:
        p = calibration.PendingCalibration()
        assert p._pid is None and calls == []          # no fork while a thread runs: nothing started
        assert p.result() == 0.05 and p.result() == 0.05 and calls == [3]
        p.close()
    finally:
        stop.set()
        other.join()


@pytest.mark.parametrize("seconds, agreeing_with, runs, best", [
    ([0.060, 0.050, 0.055], None, 3, 0.050),        # no earlier calibration: best of 3
    ([0.062, 0.050, 0.055], 0.060, 1, 0.062),       # the first repeat agrees within 5%: the ends agree
    ([0.080, 0.058, 0.050], 0.060, 2, 0.058),       # a slow repeat does not, the next one does
    ([0.080, 0.070, 0.075], 0.060, 3, 0.070),       # none agrees: best of 3, as without one
    ([0.050, 0.049, 0.030], 0.060, 3, 0.030),       # faster than the start by more than 5%: repeated too
])
def test_the_end_calibration_stops_repeating_once_it_agrees_with_the_start(monkeypatch, seconds, agreeing_with,
                                                                            runs, best):
    """Repeats of the workload end at the first within AGREEMENT of ``agreeing_with`` (a scripted clock)."""
    clock, ran = iter(t for s in seconds for t in (0.0, s)), []
    monkeypatch.setattr(calibration.time, "perf_counter", lambda: next(clock))
    monkeypatch.setattr(calibration, "workload", lambda: ran.append(1))
    assert calibration.calibrate(agreeing_with=agreeing_with) == best
    assert len(ran) == runs


@pytest.mark.parametrize("walls, owns, agreeing_with, runs, best", [
    ([0.060, 0.050, 0.055], [0.060, 0.050, 0.055], None, 3, (0.050, 0.050)),       # no earlier one: best of 3
    ([0.062, 0.050, 0.055], [0.061, 0.050, 0.055], (0.060, 0.060), 1, (0.062, 0.061)),   # both agree at once
    ([0.062, 0.058, 0.055], [0.080, 0.059, 0.055], (0.060, 0.060), 2, (0.058, 0.059)),   # own disagrees once
    ([0.080, 0.058, 0.055], [0.061, 0.058, 0.055], (0.060, 0.060), 2, (0.058, 0.058)),   # wall disagrees once
    ([0.080, 0.070, 0.075], [0.080, 0.070, 0.075], (0.060, 0.060), 3, (0.070, 0.070)),   # never: best of 3
    ([0.050, 0.049, 0.030], [0.050, 0.049, 0.030], (0.060, 0.060), 3, (0.030, 0.030)),   # faster by > 5%: too
])
def test_the_performance_stages_second_calibration_stops_once_both_clocks_agree(monkeypatch, walls, owns,
                                                                                 agreeing_with, runs, best):
    """``calibrate_both(agreeing_with=...)`` (the performance stage's calibration after its records) ends at the
    first repeat whose best wall and own figures are both within AGREEMENT of the earlier ones (scripted
    samples); without one, best of 3 on each clock, as before."""
    samples = iter(timing.Sample(own=o, wall=w, cpu=o, waited=w - o if w > o else 0.0) for w, o in zip(walls, owns))
    ran = []

    def timed(fn):
        ran.append(fn)
        return None, next(samples)

    monkeypatch.setattr(timing, "timed", timed)
    before = None if agreeing_with is None else {"wall": agreeing_with[0], "own": agreeing_with[1], "repeats": 3}
    got = timing.calibrate_both(agreeing_with=before)
    assert (got["wall"], got["own"]) == best and got["repeats"] == runs == len(ran)


def test_a_unit_over_its_scaled_budget_is_stopped_and_says_why(monkeypatch):
    if not timeouts.supported():
        pytest.skip("no SIGALRM here")
    monkeypatch.setattr(run_config, "_STACK", [run_config.RunConfig(profile="dev")])
    timing.set_calibration(1e-4)                   # 800 units x 0.1 ms = 0.08 s
    try:
        def spin():
            while True:
                pass

        rec = timeouts.run_unit(spin, check="law", subject="spinner")
    finally:
        timing.set_calibration(None)
    assert rec.status == "failed" and "time budget of 0.08 s" in rec.message
    assert rec.details["budget"] == {"seconds": pytest.approx(0.08), "source": "profile dev", "units": 800.0,
                                     "calibration": 1e-4}


# -- the gate: stage times judged only on a quiet machine ------------------------------------------------------


def run_report(duration: float, calibrations: list[float], cpu_waiting: float | None = 0.01,
               foreign_cpu: float | None = 0.02) -> Report:
    rep = Report([CheckResult("monotone", "Box", PASSED, worst=0.5, bound=1.0)])
    stage = {"name": "operator_laws", "duration": duration, "status": "passed", "records": 1,
             "cpu": 3.6, "calibration_cpu": [0.05] * 8}          # the CPU time unchanged: the wall-time rule
    for key, value in (("cpu_waiting", cpu_waiting), ("foreign_cpu", foreign_cpu)):
        if value is not None:
            stage[key] = value
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
    # other processes shared the cores and tasks waited for them: the growth is reported, not a regression
    regs, others = stage_changes(run_report(12.0, [0.05, 0.051], cpu_waiting=0.7, foreign_cpu=0.6))
    assert not regs and len(others) == 1 and "not judged" in others[0].message
    assert "waited for a CPU 70%" in others[0].message and "outside the run used 60%" in others[0].message
    # the machine's speed changed between the run's start and end: no single unit describes the stage
    regs, others = stage_changes(run_report(16.0, [0.05, 0.08], cpu_waiting=None, foreign_cpu=None))
    assert not regs and "calibrations at the run's start and end differ by 1.60x" in others[0].message
    # one of the two signs recorded: it decides
    regs, _ = stage_changes(run_report(12.0, [0.05, 0.051], cpu_waiting=None, foreign_cpu=0.5))
    assert not regs
    regs, _ = stage_changes(run_report(12.0, [0.05, 0.051], cpu_waiting=0.5, foreign_cpu=None))
    assert not regs
    # neither recorded and agreeing calibrations: judged (the calibrations alone as evidence)
    regs, _ = stage_changes(run_report(12.0, [0.05, 0.051], cpu_waiting=None, foreign_cpu=None))
    assert [c.key for c in regs] == ["stage operator_laws"]


def test_a_slowdown_hidden_by_a_drifting_calibration_is_shown_not_dropped():
    """A busy run whose end calibration doubled: 3x the work reads only 1.5x in units of the slower calibration,
    3x in units of the faster one; it is not judged, but listed with the evidence (not silently passed)."""
    regs, others = stage_changes(run_report(12.0, [0.05, 0.1], cpu_waiting=0.8, foreign_cpu=0.7))
    assert not regs and len(others) == 1, others
    assert "up to 3.0x growth" in others[0].message and "not judged" in others[0].message
    # the same reading from a run that can be judged (no drift, quiet): within 2x, nothing to say
    regs, others = stage_changes(run_report(4.0 * 1.9, [0.05, 0.05]))
    assert not regs and not others


def test_a_run_contending_with_itself_is_still_judged():
    """Waiting for a CPU caused by the run's own worker processes (40% in a quiet run's first stage) is part of
    the stage's normal time, in the baseline too: with little foreign CPU a 3x slowdown still regresses."""
    regs, _ = stage_changes(run_report(12.0, [0.05, 0.051], cpu_waiting=0.4, foreign_cpu=0.03))
    assert [c.key for c in regs] == ["stage operator_laws"]
    # another process busy on an otherwise idle core, no contention: judged too
    regs, _ = stage_changes(run_report(12.0, [0.05, 0.051], cpu_waiting=0.02, foreign_cpu=0.45))
    assert [c.key for c in regs] == ["stage operator_laws"]


def test_the_probe_counts_the_runs_own_processes_as_its_own():
    """A child process's CPU time is the run's (``_tree_cpu_s``), not foreign."""
    import subprocess
    import sys

    before = timing._tree_cpu_s()
    if before is None:
        pytest.skip("no /proc here")
    subprocess.run([sys.executable, "-c", "import time\nt = time.process_time()\nwhile time.process_time() - t < 0.3: pass"],
                   check=True)
    assert timing._tree_cpu_s() - before >= 0.29
    lap = timing.MachineProbe().lap()
    assert set(lap) == {"cpu_waiting", "foreign_cpu", "loadavg"}
    assert all(lap[k] is None or 0.0 <= lap[k] <= 1.0 for k in ("cpu_waiting", "foreign_cpu"))


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
    from verimono.cli import _finish
    from verimono.run.execute import EXIT_OK, EXIT_UNDECIDED, exit_status as _exit_status

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


# -- a law out of budget: undecided when everything it evaluated held, failed when a call does not return -------


needs_alarm = pytest.mark.skipif(not timeouts.supported(), reason="no SIGALRM here")


def _sleep_then(seconds: float):
    def run():
        time.sleep(seconds)
    return run


@needs_alarm
def test_a_unit_stopped_after_samples_that_all_held_is_undecided():
    def law():
        time.sleep(0.05)
        timeouts.note_progress(1, True, "partitions")
        time.sleep(10)                            # the next evaluation: slow, not hung (0.45 s < 20 x 0.05 s)

    rec = timeouts.run_unit(law, check="law", subject="slow stepper", seconds=0.5)
    assert rec.status == UNDECIDED, rec
    assert rec.details["undecided_reason"] == timeouts.TIME_BUDGET_REASON == "time budget"
    assert rec.details["evaluated"] == 1 and "after 1 partition, all of which held" in rec.message


@needs_alarm
def test_a_unit_stopped_after_a_violation_or_in_a_call_that_does_not_return_fails():
    def violated():
        timeouts.note_progress(2, False, "partitions")
        time.sleep(10)

    rec = timeouts.run_unit(violated, check="law", subject="s", seconds=0.3)
    assert rec.status == "failed" and "not all of which held" in rec.message

    def hangs():
        timeouts.note_progress(3, True)             # three quick samples held, then a call that never returns
        while True:
            pass

    rec = timeouts.run_unit(hangs, check="law", subject="s", seconds=0.5)
    assert rec.status == "failed" and "a call that does not return" in rec.message, rec
    assert rec.details["in_flight"] > timeouts.HANG_MULTIPLE * rec.details["slowest"]

    rec = timeouts.run_unit(_sleep_then(10), check="law", subject="s", seconds=0.2)   # nothing returned
    assert rec.status == "failed" and rec.message.startswith("timed out")
    timeouts.note_progress(1, True)                  # outside a unit: nothing to note
    assert not timeouts._PROGRESS


@needs_alarm
def test_a_stepper_law_out_of_budget_after_partitions_that_held_is_undecided():
    """``check_stepper`` runs each law under the unit budget; a correct but slow stepper on a loaded machine is
    undecided (time budget, k partitions), a stepper that hangs on its second partition still fails."""
    import verimono as vm
    from verimono.reference import get

    problem = get("t|x| (n=1)")

    def slow(p, t):                                  # two partitions of 0.5 s each
        time.sleep(0.5)
        return vm.solve(p, t)

    with timeouts.budget(0.8):                       # stopped in the second partition, whatever the load
        rep = vm.check_stepper(slow, [problem], laws=["in_domain"], orders=False)
    (rec,) = rep.results
    assert rec.status == UNDECIDED and rec.details["undecided_reason"] == "time budget", rec
    assert rec.details["evaluated"] >= 1 and "all of which held" in rec.message

    calls = []

    def hangs_on_the_second(p, t):
        calls.append(len(t))
        while len(calls) > 1:
            pass
        return vm.solve(p, t)

    with timeouts.budget(1.5):                       # in flight > 20x the first partition, even on a busy machine
        rep = vm.check_stepper(hangs_on_the_second, [problem], laws=["in_domain"], orders=False)
    (rec,) = rep.results
    assert rec.status == "failed" and "a call that does not return" in rec.message, rec


@pytest.mark.timing   # 0.4 s of 4 ms samples: under `stress` the first sample alone can outlast the budget
@needs_alarm
def test_an_operator_law_out_of_budget_after_samples_that_held_is_undecided():
    import numpy as np

    import verimono as vm
    from verimono.checks import operator_laws  # noqa: F401 - the operator laws join the registry on import
    from verimono.checks.engine.search import run_law

    def slow(x, lam, t):
        time.sleep(0.004)
        return np.asarray(x, dtype=float) / (1.0 + lam)

    op = vm.operator_from_resolvent(slow, 2, name="slow")
    with timeouts.budget(0.4):
        rec = run_law("resolvent_nonexpansive", op, seed=0, examples=500)
    # undecided whatever the load: what was evaluated held and no call in flight had run long — on a busy machine
    # the harness may spend the whole budget before the first sample (then no call of the subject was running),
    # which was recorded as failed before ("0 samples evaluated before"; 2 runs in 3 under `stress`)
    assert rec.status == UNDECIDED and rec.details["undecided_reason"] == "time budget", rec
    if rec.details["evaluations"]:
        assert "all of which held" in rec.message
    else:
        assert "before any sample was evaluated" in rec.message

    def hangs_later(x, lam, t):                      # samples hold, then a call never returns (it sleeps: the
        seen.append(1)                               # test takes no CPU from a busy machine); after 200 calls: past
        if len(seen) == 201:                         # the first vectorised pass (the draws and edge samples, one
            time.sleep(60)                           # evaluation counted when all its rows return), in the sweep
        return np.asarray(x, dtype=float) / (1.0 + lam)

    seen: list[int] = []
    op = vm.operator_from_resolvent(hangs_later, 2, name="hangs later")
    with timeouts.budget(1.5):                       # in flight > half the budget and 20x any sample, even when busy
        rec = run_law("resolvent_nonexpansive", op, seed=0, examples=50)
    # the sweep had no limit of its own (the search and the coordinate phase each armed a whole budget): a law
    # called outside run_unit slept the 60 s out, then passed
    assert rec.status == "failed" and "does not return" in rec.message and rec.details["evaluations"] >= 2, rec
    assert "time budget of 1.5 s" in rec.message, rec.message
