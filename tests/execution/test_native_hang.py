"""Issue 25, bounded time in native code: a call of the subject blocked where ``SIGALRM`` cannot reach it
(``os.system``: glibc's ``system`` retries its ``waitpid`` after the signal) is stopped by the process-level
limit of :mod:`verimono.execution.watchdog` once its budget and grace are over.

Before it, ``verimono check mod:stepper --timeout 3`` on a stepper calling ``os.system("sleep 20")`` took
141 s for 8 units of 3 s (``--executor serial``: each call ran its full 20 s) and 383 s under ``--executor
process:1`` (the workers did not even get ``--timeout``: they ran the profile's 47 s budget).

The subjects sleep far longer than any bound asserted here, so an assertion on the elapsed time only tells
"waited for the call" from "did not", never a busy machine from a quiet one.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import textwrap
import time

import pytest

import verimono as vm
from verimono import watchdog
from verimono.reference import get
from verimono.records.results import FAILED, PASSED, CheckResult, Report, load
from verimono.execution.timeouts import budget, current_budget, run_unit, supported, time_limit

pytestmark = pytest.mark.skipif(not supported() or not sys.platform.startswith("linux"),
                                reason="native hangs: a POSIX timer in the main thread, os.system, /proc")

REFS = ["--reference", "moving box", "--reference", "t|x| (n=1)"]

#: steppers that block in native code: in the last trajectory law (unique_limit, in verimono.checks.limits) when
#: each law runs apart (check_stepper with executor=...), in in_domain when a battery shares its runs
STEPPER = '''
import ctypes
import os
import sys

import verimono as vm


def _inside(module=None, function=None):
    """Whether a caller is in ``module`` or is the function named ``function``."""
    frame = sys._getframe(1)
    while frame is not None:
        if frame.f_globals.get("__name__") == module or frame.f_code.co_name == function:
            return True
        frame = frame.f_back
    return False


def stepper(problem, t_grid):
    if _inside("verimono.checks.limits"):
        os.system("sleep {sleep}")
    return vm.solve(problem, t_grid)


def battery_stepper(problem, t_grid):
    # in a battery the laws share the stepper's runs (verimono.checks.shared_runs): in_domain is the first law
    # to run it on the refined partitions, and unique_limit, judging those same runs, never calls it
    if _inside(function="check_in_domain"):
        os.system("sleep {sleep}")
    return vm.solve(problem, t_grid)


def gil_stepper(problem, t_grid):
    if _inside("verimono.checks.limits"):       # blocks in C holding the GIL: no Python thread runs
        ctypes.PyDLL(None).system(b"sleep {sleep}")
    return vm.solve(problem, t_grid)
'''


@pytest.fixture
def hanging(tmp_path, monkeypatch):
    """The module ``hanging_stepper`` (its native calls sleep 120 s), importable here and by spawned workers."""
    (tmp_path / "hanging_stepper.py").write_text(textwrap.dedent(STEPPER.format(sleep=120)))
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")]))
    import hanging_stepper

    yield hanging_stepper
    sys.modules.pop("hanging_stepper", None)


# -- the watchdog --------------------------------------------------------------------------------------------

def test_a_call_blocked_in_native_code_is_handed_to_the_handler_with_what_finished_before():
    """The timer fires at 0.1 s but ``os.system`` goes on: the watchdog names the call at 0.1 + 2 s."""
    got: list[Report] = []
    with watchdog.scope(stage="s", label="l"), watchdog.on_hang(lambda h: got.append(watchdog.hang_report(h)),
                                                                backstop=False), budget(0.1):
        first = run_unit(lambda: CheckResult("a", "x", PASSED), check="a", subject="x")
        late = run_unit(lambda: os.system("sleep 3.5"), check="b", subject="y")
    (rep,) = got
    assert [(r.check, r.subject) for r in rep] == [("a", "x"), ("b", "y")] and rep.results[0] is first
    hung = rep.results[-1]
    assert hung.status == FAILED and "blocked in native code" in hung.message
    assert "test_native_hang.py" in hung.details[watchdog.HANG_DETAIL]["where"]
    assert hung.details["elapsed"] >= 0.1 + watchdog.grace(0.1)
    assert late.status == FAILED and "timed out" in late.message     # the call returned: the timer's record


def _spin():
    while True:
        pass


def test_python_code_is_stopped_by_the_timer_and_never_reaches_the_watchdog():
    hangs: list = []
    with watchdog.on_hang(hangs.append, backstop=False), budget(0.1):
        rec = run_unit(lambda: time.sleep(30), check="law", subject="s")
        spin = run_unit(_spin, check="law", subject="spin")
    assert rec.status == FAILED and spin.status == FAILED and hangs == []
    assert watchdog.grace(1) == 2.0 and watchdog.grace(10) == 5.0


def test_the_api_warns_and_never_ends_the_interpreter(capfd):
    with budget(0.1):
        rec = run_unit(lambda: os.system("sleep 3.5"), check="law", subject="s")
    err = capfd.readouterr().err
    assert "law on s has run" in err and "blocked in native code" in err and 'executor="process:N"' in err
    assert rec.status == FAILED and "timed out" in rec.message


def test_no_handler_of_a_parent_runs_in_a_forked_child():
    with watchdog.on_hang(lambda h: None, backstop=False):
        pid = os.fork()
        if pid == 0:                                   # pragma: no cover - the child
            os._exit(0 if not watchdog._HANDLERS and not watchdog._LIMITS else 1)
        _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0


# -- inf is no limit -----------------------------------------------------------------------------------------

def test_timeout_inf_means_no_limit(tmp_path, monkeypatch):
    """``--timeout inf`` was refused ("every unit needs a finite budget"): it is no limit."""
    import signal

    from verimono.cli import build_parser, main
    from verimono.execution.executors import make_runner

    args = build_parser().parse_args(["run", "--timeout", "inf", "--unit-timeout", "Infinity"])
    assert args.timeout == math.inf and args.unit_timeout == math.inf
    with budget(math.inf):
        assert current_budget() == math.inf
        with time_limit(current_budget(), "u"):
            assert signal.getitimer(signal.ITIMER_REAL)[0] == 0          # no timer armed
        assert run_unit(lambda: 7, check="c", subject="s") == 7
    assert make_runner("process:1", timeout=math.inf).timeout is None
    monkeypatch.chdir(tmp_path)                   # no reports/baseline.json to compare with
    code = main(["run", "--profile", "ci", "--stage", "convergence", "--reference", "moving box", "--executor",
                 "serial", "--timeout", "inf", "--unit-timeout", "inf", "--out", str(tmp_path)])
    assert code == 0 and load(tmp_path / "results.json").ok


def test_a_resumed_run_drops_the_records_of_the_stage_that_hung():
    from verimono.run.execute import UNFINISHED_STAGE, merge_resumed

    done = CheckResult("a", "x", PASSED)
    partial = CheckResult("b", "y", PASSED, details={UNFINISHED_STAGE: True})
    previous = Report([done, partial], meta={"stages": [{"name": "one"}], "run_id": "r1", "incomplete": True})
    merged = merge_resumed(previous, Report([CheckResult("b", "y", PASSED)], meta={"stages": [{"name": "two"}]}))
    assert [(r.check, r.details.get(UNFINISHED_STAGE)) for r in merged] == [("a", None), ("b", None)]


# -- the command line ----------------------------------------------------------------------------------------

def _check(tmp_path, *options):
    start = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "verimono.cli", "check", "hanging_stepper:battery_stepper",
                           "--profile", "ci",
                           "--timeout", "1", *REFS, "--out", str(tmp_path / "out"), *options],
                          capture_output=True, text=True, timeout=600, cwd=tmp_path,
                          env={**os.environ, "OPENBLAS_NUM_THREADS": "1"})
    return proc, time.perf_counter() - start


@pytest.mark.slow
def test_a_serial_check_ends_on_a_native_hang_and_writes_what_finished(hanging, tmp_path):
    """Serial: the run ends (exit 1) with the finished stage, the current stage's records and the hung call."""
    proc, elapsed = _check(tmp_path, "--executor", "serial")
    # the call sleeps 120 s; the pipes close only once it is killed too (it inherits them)
    assert proc.returncode == 1, proc.stderr
    assert elapsed < 60
    line = proc.stderr.strip().splitlines()[-1]
    assert "in_domain on battery_stepper on moving box is blocked in native code" in line
    assert str(tmp_path / "out" / "results.json") in line and "--executor process:N" in line
    doc = json.loads((tmp_path / "out" / "results.json").read_text())
    assert doc["meta"]["incomplete"] and doc["meta"]["finished_stages"] == ["convergence"]
    recs = [(r["check"], r["status"]) for r in doc["results"]]
    assert recs[:2] == [("convergence_order", "passed")] * 2
    assert recs[-1] == ("in_domain", "failed") and len(recs) == 4      # contraction finished on moving box
    assert watchdog.HANG_DETAIL in doc["results"][-1]["details"]
    assert not (tmp_path / "out" / "results.json.in-progress").exists()


@pytest.mark.slow
def test_a_process_worker_answers_for_a_native_hang_and_the_run_goes_on(hanging, tmp_path):
    proc, elapsed = _check(tmp_path, "--executor", "process:1")
    assert proc.returncode == 1, proc.stderr
    assert elapsed < 90
    rep = load(tmp_path / "out" / "results.json")
    # the run returns, with every record of the units up to their hung calls (contraction, then in_domain)
    assert not rep.meta.get("incomplete") and len(rep) == 6
    hung = [r for r in rep if r.status == FAILED]
    assert [(r.check, r.subject) for r in hung] == [("in_domain", "battery_stepper on moving box"),
                                                    ("in_domain", "battery_stepper on t|x| (n=1)")]
    assert all("blocked in native code" in r.message for r in hung)


# -- the Python API ------------------------------------------------------------------------------------------

@pytest.mark.slow
def test_check_stepper_with_process_workers_bounds_a_native_hang(hanging):
    start = time.perf_counter()
    with budget(1.0):
        rep = vm.check_stepper(hanging.stepper, [get("moving box")], executor="process:1")
    assert time.perf_counter() - start < 60                   # not the 120 s of the call
    assert [r.check for r in rep if r.status == FAILED] == ["unique_limit"]
    assert "blocked in native code" in rep.results[-1].message and len(rep) == 10    # 1 order + 9 laws


@pytest.mark.slow
def test_a_native_call_that_holds_the_gil_ends_its_worker_by_the_backstop(hanging):
    """No Python thread runs while the call holds the GIL: faulthandler's timer ends the worker."""
    start = time.perf_counter()
    with budget(1.0):
        rep = vm.check_stepper(hanging.gil_stepper, [get("moving box")], executor="process:1",
                               laws=["contraction", "unique_limit"], orders=False)
    assert time.perf_counter() - start < 60   # the worker's pipe was not held open by the call's child either
    assert rep.results[0].status == PASSED
    dead = rep.results[-1]
    assert dead.status == FAILED and dead.check == "unit" and "worker process died" in dead.message
