"""A distributed verification run (``--executor``): the stages' units on worker processes or a dask cluster
give the serial run's JSON apart from timings; a worker that dies, or a unit that overruns its timeout,
becomes one failed record naming the unit while every other unit's records stay as in the serial run."""

from __future__ import annotations

import json
import os
import re
import textwrap
from pathlib import Path

import pytest

from verimono.checks.core import REGISTRY
from verimono.cli import main
from verimono.execution.executors import BadExecutor, ProcessRunner, SerialRunner, Unit, make_runner
from verimono.records.results import CheckResult, Report

REF = ["--reference", "moving box", "--reference", "t|x| (n=1)"]
RUN = ["run", "--profile", "ci", "--stage", "convergence", "--stage", "assumptions", *REF]
#: what differs between two runs of the same battery: timings (seconds, or when the document was written),
#: the run id both output files carry, and where the units ran (``meta.executor``)
TIMING_KEYS = {"duration", "timings", "calibration", "calibrations", "created", "run_id", "executor",
               "cpu_waiting", "foreign_cpu", "loadavg",   # how busy the machine was during each stage
               "unit_budget",                             # the unit budget in seconds: units x the calibration
               "cpu", "calibration_cpu", "calibrations_cpu", "units",   # CPU times: the stages', the units', the calibrations'
               "overlapped", "group_duration"}   # on workers, the stages that ran at once and their wall together

STEPPERS = '''
import multiprocessing, os, signal, time
from verimono.core.stepping import solve as _solve


def killer(problem, t_grid):
    """verimono's own solve, except that it kills its worker process on the moving box."""
    if problem.name == "moving box" and multiprocessing.parent_process() is not None:
        os.kill(os.getpid(), signal.SIGKILL)
    return _solve(problem, t_grid)


def sleeper(problem, t_grid):
    """verimono's own solve, except that it hangs on the moving box when run by a worker."""
    if problem.name == "moving box" and multiprocessing.parent_process() is not None:
        time.sleep(600)
    return _solve(problem, t_grid)
'''


def without_timings(value):
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items() if k not in TIMING_KEYS}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


def document(out: Path) -> dict:
    return without_timings(json.loads((out / "results.json").read_text()))


@pytest.fixture(scope="module")
def serial_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("serial")
    assert main([*RUN, "--out", str(out), "--executor", "serial"]) == 0
    doc = document(out)
    # what the selection gives: one convergence record per reference, and per reference one per problem law
    assert len(doc["results"]) == 2 + 2 * len(REGISTRY["problem"]) and len(doc["studies"]) == 2
    return doc


@pytest.fixture(scope="module")
def steppers(tmp_path_factory):
    d = tmp_path_factory.mktemp("steppers")
    (d / "steppers.py").write_text(textwrap.dedent(STEPPERS))
    return d / "steppers.py"


@pytest.fixture(scope="module")
def serial_check(steppers, tmp_path_factory):
    """``verimono check`` of the killer stepper, serially (here it never kills: it is not in a worker)."""
    out = tmp_path_factory.mktemp("check")
    assert main(["check", f"{steppers}:killer", "--profile", "ci", *REF, "--out", str(out)]) == 0
    return document(out)


def killed_unit_intact(serial: dict, parallel: dict, how: str) -> None:
    """The moving box's units are failed ``unit`` records saying ``how``; every other record is the serial one."""
    failed = [r for r in parallel["results"] if r["check"] == "unit"]
    assert [(r["subject"], r["status"]) for r in failed] == [("convergence: moving box", "failed"),
                                                            ("trajectory_laws: moving box", "failed")]
    assert all(how in r["message"] for r in failed), [r["message"] for r in failed]
    kept = [r for r in serial["results"] if "moving box" not in r["subject"]]
    assert len(kept) >= 6
    assert [r for r in parallel["results"] if r["check"] != "unit"] == kept
    assert [s for s in parallel["studies"]] == [s for s in serial["studies"] if s["problem"] != "moving box"]


@pytest.mark.slow
def test_process_executor_gives_the_serial_json(serial_run, tmp_path, capsys):
    assert main([*RUN, "--out", str(tmp_path), "--executor", "process:2"]) == 0
    assert "units run on process:2" in capsys.readouterr().err
    assert document(tmp_path) == serial_run


@pytest.mark.slow
def test_a_killed_worker_process_fails_its_unit_only(steppers, serial_check, tmp_path):
    code = main(["check", f"{steppers}:killer", "--profile", "ci", *REF, "--out", str(tmp_path),
                 "--executor", "process:2"])
    assert code == 1
    killed_unit_intact(serial_check, document(tmp_path), "worker process died (signal 9)")


@pytest.mark.slow
def test_a_unit_over_its_timeout_fails_and_the_run_goes_on(steppers, serial_check, tmp_path):
    code = main(["check", f"{steppers}:sleeper", "--profile", "ci", *REF, "--out", str(tmp_path),
                 "--executor", "process:2", "--unit-timeout", "15"])
    assert code == 1
    doc = document(tmp_path)
    serial = json.loads(json.dumps(serial_check).replace('"killer', '"sleeper').replace("killer on", "sleeper on"))
    killed_unit_intact(serial, doc, "timed out after 15 s")


@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("distributed")
    import dask

    # a unit that kills its worker is reported at once rather than retried on the other workers
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                      dashboard_address=None, silence_logs=50) as c:
            yield c


@pytest.mark.slow
def test_dask_local_cluster_gives_the_serial_json(cluster, serial_run, tmp_path):
    assert main([*RUN, "--out", str(tmp_path), "--executor", cluster.scheduler_address]) == 0
    assert document(tmp_path) == serial_run


@pytest.mark.slow
def test_a_killed_dask_worker_fails_its_unit_only(cluster, steppers, serial_check, tmp_path):
    code = main(["check", f"{steppers}:killer", "--profile", "ci", *REF, "--out", str(tmp_path),
                 "--executor", cluster.scheduler_address])
    assert code == 1
    killed_unit_intact(serial_check, document(tmp_path), "KilledWorker")


def _ok(name):
    return Report([CheckResult("law", name, "passed", worst=0.5, bound=1.0)])


def _boom(name):
    raise ZeroDivisionError(f"{name} divided by zero")


def test_a_unit_that_raises_is_one_failed_record_in_place():
    units = [Unit("s", "a", _ok, ("a",)), Unit("s", "b", _boom, ("b",)), Unit("s", "c", _ok, ("c",))]
    seen = []
    reports = SerialRunner().map(units, None, lambda done, total, label: seen.append((done, total, label)))
    assert [r.key for rep in reports for r in rep] == ["law[a]", "unit[s: b]", "law[c]"]
    assert reports[1][0].status == "failed" and "ZeroDivisionError: b divided by zero" in reports[1][0].message
    assert "traceback" in reports[1][0].details
    assert seen[0] == (0, 3, "a") and seen[-1] == (3, 3, "")


def _unverified(name):
    from verimono.core.errors import UnverifiedSolution

    raise UnverifiedSolution(f"{name}: the LCP back-ends gave no verified answer")


@pytest.mark.parametrize("where", ["serial", "worker"])
def test_a_unit_is_judged_by_the_one_exception_policy(where):
    """What a unit raised means what it means in a law (:func:`verimono.checks.core.classify`): a limit of
    verimono's own solvers is undecided, never a failure of the subject; another exception is failed.  A unit
    turned every exception into *failed* before.  ``worker``: the code a worker process runs on a shipped
    unit, in this process."""
    from verimono.execution.executors import _decode_answer, _ship, run_payload

    units = [Unit("s", "a", _unverified, ("a",)), Unit("s", "b", _boom, ("b",)), Unit("s", "c", _ok, ("c",))]
    if where == "serial":
        reports = SerialRunner().map(units, None, lambda *a: None)
    else:
        reports = [_decode_answer(u, run_payload(_ship(u, None)))[0] for u in units]
    (a,), (b,), (c,) = (rep.results for rep in reports)
    assert (a.key, a.status) == ("unit[s: a]", "undecided") and "no verified answer" in a.message, a
    assert a.details["exception"] == "UnverifiedSolution"
    assert (b.key, b.status) == ("unit[s: b]", "failed") and "ZeroDivisionError: b divided by zero" in b.message
    assert "traceback" in b.details
    assert (c.key, c.status) == ("law[c]", "passed")


@pytest.mark.parametrize("spec", ["process:two", "threads", "process:0"])
def test_a_bad_executor_is_a_usage_error(spec, tmp_path, capsys):
    with pytest.raises(BadExecutor):
        make_runner(spec)
    assert main([*RUN, "--out", str(tmp_path), "--executor", spec]) == 2
    assert f"--executor {spec}" in capsys.readouterr().err


def test_auto_chooses_its_runner_from_the_cores_and_process_n_parses(monkeypatch):
    """The process-free part of the next test (tier ``slow``): which runner a spec makes; none starts a worker."""
    from verimono.execution.executors import AUTO_MAX_WORKERS

    monkeypatch.setattr(os, "cpu_count", lambda: 1)
    assert isinstance(make_runner("auto"), SerialRunner) and isinstance(make_runner(None), SerialRunner)
    monkeypatch.setattr(os, "cpu_count", lambda: 64)
    auto, three = make_runner("auto"), make_runner("process:3", timeout=5.0)
    assert isinstance(auto, ProcessRunner) and auto.workers == AUTO_MAX_WORKERS and auto.fallback
    assert three.spec == "process:3" and three.timeout == 5.0 and not three.fallback
    assert auto._pool == auto._launched == [] == three._pool == three._launched   # nothing was started


@pytest.mark.slow
def test_run_uses_every_core_by_default(monkeypatch, tmp_path, capsys):
    """``verimono run`` defaults to ``auto``: process:N with N the cores (at most AUTO_MAX_WORKERS), serial
    on one core; ``$VERIMONO_EXECUTOR`` overrides it.  The records are the serial run's (see above)."""
    from verimono.execution.executors import AUTO_MAX_WORKERS, ProcessRunner, SerialRunner, make_runner

    monkeypatch.setattr(os, "cpu_count", lambda: 1)
    assert isinstance(make_runner("auto"), SerialRunner)
    monkeypatch.setattr(os, "cpu_count", lambda: 64)
    runner = make_runner("auto")
    assert isinstance(runner, ProcessRunner) and runner.workers == AUTO_MAX_WORKERS
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    monkeypatch.delenv("VERIMONO_EXECUTOR", raising=False)
    assert main(["run", "--profile", "ci", "--stage", "convergence", "--reference", "t|x| (n=1)",
                 "--out", str(tmp_path)]) == 0
    assert "units run on process:2" in capsys.readouterr().err
    assert json.loads((tmp_path / "results.json").read_text())["meta"]["executor"] == "process:2"
    monkeypatch.setenv("VERIMONO_EXECUTOR", "serial")
    assert main(["run", "--profile", "ci", "--stage", "convergence", "--reference", "t|x| (n=1)",
                 "--out", str(tmp_path)]) == 0
    assert json.loads((tmp_path / "results.json").read_text())["meta"]["executor"] == "serial"


@pytest.mark.slow
def test_prestarted_workers_run_the_first_units_and_close_cleanly():
    """``prestart`` launches the workers without waiting (verimono run calibrates meanwhile); the first map
    uses them, and closing a runner whose launched workers never ran a unit leaves no process behind."""
    runner = ProcessRunner(2)
    runner.prestart()
    launched = [proc for proc, _ in runner._launched]
    assert len(launched) == 2 and all(p.is_alive() for p in launched)
    units = [Unit("s", "a", _ok, ("a",)), Unit("s", "b", _ok, ("b",))]
    reports = runner.map(units, None, lambda done, total, label: None)
    assert [r.key for rep in reports for r in rep] == ["law[a]", "law[b]"]
    assert sorted(proc.pid for proc, _ in runner._pool) == sorted(p.pid for p in launched)   # no new start
    runner.close()
    idle = ProcessRunner(2)
    idle.prestart()
    procs = [proc for proc, _ in idle._launched]
    idle.close()
    assert not any(p.is_alive() for p in procs)


@pytest.mark.slow
def test_auto_runs_serially_when_its_workers_cannot_start(monkeypatch, capsys):
    """``auto`` is best effort: when no worker can start (a script read from standard input cannot be
    re-imported by a spawned process) it says why and runs the units serially, recording ``serial``;
    an explicit ``process:N`` fails instead.  The reason names the worker's exit status."""
    import multiprocessing
    import sys as _sys

    def exits(self, count):
        started, ctx = [], multiprocessing.get_context("spawn")
        for _ in range(max(0, count)):
            parent, child = ctx.Pipe(duplex=True)
            proc = ctx.Process(target=_sys.exit, args=(1,))
            proc.start()
            child.close()
            started.append((proc, parent))
        return started

    monkeypatch.setattr(ProcessRunner, "_launch", exits)
    units = [Unit("s", "a", _ok, ("a",)), Unit("s", "b", _ok, ("b",))]
    with pytest.raises(BadExecutor, match="exited with status 1 before it was ready"):
        ProcessRunner(2).map(units, None, lambda done, total, label: None)
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    runner = make_runner("auto")
    reports = runner.map(units, None, lambda done, total, label: None)
    assert [r.key for rep in reports for r in rep] == ["law[a]", "law[b]"]
    assert runner.spec == "serial" and runner.workers == 1
    assert "running the units serially" in capsys.readouterr().err
    runner.close()


# -- how workers start, and what a unit carries to them ---------------------------------------------------

def _limits_seen() -> Report:
    """A unit reporting the unit budget and the calibration of the process it runs in."""
    from verimono.execution.timeouts import calibration, current_budget

    return Report([CheckResult("limits", "seen", "passed", details={"budget": current_budget(),
                                                                     "calibration": calibration()})])


@pytest.mark.parametrize("method", ["spawn", "fork"])
def test_a_worker_runs_a_unit_under_the_runs_budget_and_calibration(monkeypatch, method):
    """``--timeout`` and the run's calibration bound a unit on a worker as in the run's own process: a spawned
    worker used to measure its own calibration and ignore ``--timeout``."""
    from verimono.execution.calibration import calibration, set_calibration
    from verimono.execution.timeouts import budget

    monkeypatch.setenv("VERIMONO_START_METHOD", method)
    before = calibration()
    set_calibration(0.123)
    try:
        runner = ProcessRunner(1)
        with budget(7.5):
            (rep,) = runner.map([Unit("s", "limits", _limits_seen)], None, lambda *a: None)
        runner.close()
    finally:
        set_calibration(before)
    (rec,) = rep.results
    assert rec.details == {"budget": 7.5, "calibration": 0.123}


def test_workers_are_forked_only_where_that_is_safe(monkeypatch):
    """Fork (a ready copy of this process) on Linux with no other thread and no library whose threads do not
    survive a fork; spawn otherwise; ``$VERIMONO_START_METHOD`` decides when set."""
    import sys
    import threading

    from verimono.execution.executors import FORK_UNSAFE, start_method

    monkeypatch.delenv("VERIMONO_START_METHOD", raising=False)
    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.setattr(threading, "active_count", lambda: 1)
    for name in FORK_UNSAFE:         # (dask's distributed, loaded by another test of this module, is one)
        monkeypatch.delitem(sys.modules, name, raising=False)
    assert start_method() == "fork"
    monkeypatch.setitem(sys.modules, "torch", object())
    assert start_method() == "spawn"
    monkeypatch.delitem(sys.modules, "torch")
    monkeypatch.setattr(threading, "active_count", lambda: 2)      # a thread could hold a lock at the fork
    assert start_method() == "spawn"
    monkeypatch.setattr(threading, "active_count", lambda: 1)
    monkeypatch.setattr(sys, "platform", "darwin")
    assert start_method() == "spawn"
    monkeypatch.setenv("VERIMONO_START_METHOD", "fork")
    assert start_method() == "fork"
    monkeypatch.setenv("VERIMONO_START_METHOD", "forkserver")
    with pytest.raises(BadExecutor, match="fork or spawn"):
        start_method()


def test_units_start_costliest_first_and_come_back_in_their_order():
    from verimono.run.stages.registry import RunContext
    from verimono.execution.profiles import get_profile

    started: list[str] = []

    class Recording:        # a runner of worker processes, as far as run_units can tell
        workers = 2

        def map(self, units, profile, progress):
            started.extend(u.label for u in units)
            return SerialRunner().map(units, profile, progress)

    ctx = RunContext(executor=Recording())
    units = [Unit("s", label, _ok, (label,)) for label in "abc"]
    reports = ctx.run_units(get_profile("ci"), units, costs=[0.1, 3.0, 1.0])
    assert started == ["b", "c", "a"]
    assert [r.key for rep in reports for r in rep] == ["law[a]", "law[b]", "law[c]"]


# -- what cannot be pickled runs where nothing is pickled -------------------------------------------------

LOCKED = '''
import ctypes, ctypes.util, os, threading
import numpy as np
import verimono as vm

LOCK = threading.Lock()                         # a module that cannot be pickled: a lock, and a C library
LIBM = ctypes.CDLL(ctypes.util.find_library("m"))
PIDS, SEEN = os.environ["VERIMONO_TEST_PIDS"], set()


def shrink(x, lam, t):
    if os.getpid() not in SEEN:                 # where the battery ran
        SEEN.add(os.getpid())
        with open(PIDS, "a") as f:
            f.write(f"{os.getpid()}\\n")
    with LOCK:
        return np.asarray(x, dtype=float) / (1.0 + lam)


op = vm.operator_from_resolvent(shrink, 1, name="locked shrink")
'''


@pytest.mark.parametrize("method", ["fork", pytest.param("spawn", marks=pytest.mark.slow)])
def test_a_subject_that_cannot_be_pickled_runs_where_nothing_is_pickled(method, tmp_path, monkeypatch, capsys):
    """A module holding a ``threading.Lock`` and a ``ctypes`` library under a worker executor: the stage
    FAILED before ("cannot pickle '_thread.lock' object") where ``--executor serial`` passes it.  Now the unit
    runs in a worker forked for it (where forking is safe) or in this process, with one line saying so."""
    (tmp_path / "locked.py").write_text(textwrap.dedent(LOCKED))
    pids = tmp_path / "pids"
    monkeypatch.setenv("VERIMONO_TEST_PIDS", str(pids))
    monkeypatch.setenv("VERIMONO_START_METHOD", method)
    code = main(["check", f"{tmp_path / 'locked.py'}:op", "--executor", "process:2", "--profile", "dev",
                 "--seed", "0", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    doc = json.loads((tmp_path / "out" / "results.json").read_text())
    assert code == 0 and not [r for r in doc["results"] if r["status"] == "failed"], doc["results"]
    assert sum(r["status"] == "passed" for r in doc["results"]) >= 5
    lines = [ln for ln in err.splitlines() if "cannot be sent to a worker process" in ln]
    # the line names why, as the pickler said it: "TypeError: cannot pickle '_thread.lock' object" here, and in
    # some long-lived xdist workers (under load, 2 of ~10 full runs) "RuntimeError: dictionary changed size during
    # iteration" at every attempt (verimono.execution.workers.SHIP_ATTEMPTS) — the unit still runs where nothing
    # is pickled, which is what this test is about; the dict is not found yet (docs/tests.md)
    assert len(lines) == 1 and re.search(r"cannot be sent to a worker process \((TypeError|RuntimeError): .+\)",
                                         lines[0]), err
    ran_in = {int(p) for p in pids.read_text().split()}
    if method == "fork":
        assert "forked for it" in lines[0] and os.getpid() not in ran_in and len(ran_in) == 1
    else:
        assert "in this process" in lines[0] and ran_in == {os.getpid()}


class _ChangesUnderThePickler:
    """An argument whose first ``failures`` picklings meet a dict that changed size (as when another thread
    imports while the unit is pickled)."""

    def __init__(self, failures):
        self.failures = failures

    def __reduce__(self):
        if self.failures > 0:
            self.failures -= 1
            raise RuntimeError("dictionary changed size during iteration")
        return (_ChangesUnderThePickler, (0,))


def test_a_dict_changing_under_the_pickler_is_tried_again_and_the_units_own_error_stays_its_own():
    """Two transient failures: the unit still travels (it went to 'cannot be sent', under double load, with
    the locked module's real reason lost).  Failing at every attempt: the error is the caller's to report."""
    import cloudpickle

    from verimono.execution.workers import SHIP_ATTEMPTS, _ship

    assert SHIP_ATTEMPTS >= 3
    unit = Unit("s", "a", _ok, (_ChangesUnderThePickler(2),))
    config, fn, args, *_ = cloudpickle.loads(_ship(unit, "dev"))
    assert fn is _ok and isinstance(args[0], _ChangesUnderThePickler) and args[0].failures == 0
    with pytest.raises(RuntimeError, match="changed size"):
        _ship(Unit("s", "b", _ok, (_ChangesUnderThePickler(SHIP_ATTEMPTS),)), "dev")
