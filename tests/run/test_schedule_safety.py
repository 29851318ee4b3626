"""Processes started while the shared queue's stage threads live (:mod:`verimono.execution.schedule`): a worker
replacing one that died or timed out, a worker forked for a unit that cannot be pickled.

A fork copies the locks of every thread as they are at that instant; a lock held by a thread that is running
stays held forever in the copy.  The provocation used below: a stage's code imports a slow module (its import
lock held for the import's 1.2 s) while a worker is lost and replaced, and a later unit imports the same module
on the replacement.  Forked at that instant, the replacement waits on the import lock forever: the unit times out,
a *failed* record for correct code.  Under :meth:`SharedQueue.fork_guard` the fork waits for the turn (no stage's
code runs), the import has ended, and the unit passes.  Each scenario is seen passing with the guard, and the
unsafe fork (the guard replaced by one that takes no turn) is seen failing."""

from __future__ import annotations

import contextlib
import importlib
import os
import signal
import subprocess
import sys
import threading
import time

import pytest

from verimono.execution import schedule
from verimono.execution.executors import ProcessRunner, Unit
from verimono.execution.profiles import get_profile
from verimono.execution.schedule import SharedQueue
from verimono.records.results import CheckResult, Report
from verimono.run.stages import STAGES, RunContext, register_stage, run_stages

SLOW_IMPORT = 1.2      # seconds the provoking module's import holds its import lock
TIMEOUT = 8.0          # the runner's per-unit timeout: a replacement deadlocked on the import lock ends there (a
#                        spawned replacement starting under load 15 took past 4 s: a second replacement, a false failure)


def _square(tag: str, k: int) -> Report:
    """A closed form: k^2, worst ratio k^2 / (k^2 + 1) < 1."""
    return Report([CheckResult("square", f"{tag} #{k}", "passed", worst=k * k / (k * k + 1.0), bound=1.0,
                               details={"value": k * k})])


def _after(seconds: float, tag: str, k: int) -> Report:
    time.sleep(seconds)
    return _square(tag, k)


def _importer(module: str, tag: str, k: int, lock: object = None) -> Report:
    """Imports ``module`` (the provoking one), then the closed form; ``lock``: makes the unit unpicklable."""
    mod = importlib.import_module(module)
    return _square(tag, k * mod.FACTOR)


def _lose_worker(how: str, tag: str, k: int) -> Report:
    time.sleep(0.4)                  # the provoking stage is inside its import by now
    if how == "exit":
        os._exit(7)
    if how == "kill":
        os.kill(os.getpid(), signal.SIGKILL)
    time.sleep(60)                   # "timeout": past the runner's timeout
    return _square(tag, k)


@pytest.fixture
def slow_module(tmp_path, monkeypatch):
    """A module (unique per test) whose import takes SLOW_IMPORT seconds; on sys.path here and in spawned workers."""
    name = f"verimono_slow_import_{os.getpid()}_{time.monotonic_ns()}"
    (tmp_path / f"{name}.py").write_text(f"import time\ntime.sleep({SLOW_IMPORT})\nFACTOR = 1\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(schedule, "GATHER_SECONDS", 1.0)   # both stages ask before the first unit is sent
    yield name
    sys.modules.pop(name, None)


def _stages(module: str, lose: str | None, unpicklable: bool = False):
    """``sf_a``: units that lose a worker (or one that cannot be pickled) and a later one that imports ``module``;
    ``sf_b``: one short unit, then it imports ``module`` in its own code (holding the turn)."""

    @register_stage("sf_a", overlap=True)
    def sf_a(profile, context):
        if unpicklable:        # the unpicklable importer runs once the blocker has ended (0.6 s): inside sf_b's import
            units = [Unit("sf_a", "importer", _importer, (module, "sf_a", 3, threading.Lock())),
                     Unit("sf_a", "blocker", _after, (0.6, "sf_a", 2))]
            costs = [1.0, 3.0]
        else:                  # lose a worker at 0.4 s; the blocker keeps the other busy: the importer gets the new one
            units = [Unit("sf_a", "lose", _lose_worker, (lose, "sf_a", 1)),
                     Unit("sf_a", "blocker", _after, (2.5, "sf_a", 2)),
                     Unit("sf_a", "importer", _importer, (module, "sf_a", 3))]
            costs = [3.0, 2.0, 1.0]
        reps = context.run_units(profile, units, costs=costs)
        return Report([r for rep in reps for r in rep.results])

    @register_stage("sf_b", overlap=True)
    def sf_b(profile, context):
        reps = context.run_units(profile, [Unit("sf_b", "short", _square, ("sf_b", 5))], costs=[9.0])
        mod = importlib.import_module(module)    # this stage's code, holding the turn, holds the import lock
        return Report([r for rep in reps for r in rep.results] + [_square("sf_b", 6 * mod.FACTOR).results[0]])

    return ["sf_a", "sf_b"]


@pytest.fixture
def cleanup_stages():
    yield
    for n in ("sf_a", "sf_b"):
        STAGES.pop(n, None)


def _fork_possible() -> bool:
    """No thread of pytest's own (xdist's) and nothing FORK_UNSAFE imported by another test: the guard may fork."""
    return threading.active_count() == 1 and not any(m in sys.modules for m in schedule.FORK_UNSAFE)


def _unsafe_guard(self):
    """The safety removed: a fork whenever asked, whatever the stage threads do."""
    return contextlib.nullcontext(True)


def _run(names) -> Report:
    runner = ProcessRunner(2, timeout=TIMEOUT)
    try:
        return run_stages(names, get_profile("ci"), RunContext(executor=runner, schedule="shared"))
    finally:
        runner.close(kill=True)


def _by_subject(rep: Report) -> dict:
    return {r.subject: r for r in rep.results}


LOST = {"exit": "its worker process died (exit status 7)", "kill": "its worker process died (signal 9)",
        "timeout": f"timed out after {TIMEOUT:g} s"}


@pytest.mark.slow   # two workers, a lost one replaced, a 2.5 s blocker: ~4 s each
@pytest.mark.parametrize("how", ["exit", "kill", "timeout"])
def test_a_lost_worker_is_replaced_safely_and_later_units_pass(how, slow_module, cleanup_stages, monkeypatch):
    methods, start = [], ProcessRunner._start

    def spy(self, count=1, method=None):
        methods.append(method)
        return start(self, count, method)

    monkeypatch.setattr(ProcessRunner, "_start", spy)
    alone = _fork_possible()
    rep = _run(_stages(slow_module, how))
    # the two first workers (start_all, no method given), then the replacement: forked under the guard where
    # only the parked stage threads live, spawned where another thread of this process runs
    assert methods[-1] == ("fork" if alone else "spawn") and methods[:-1] == [None], methods
    got = _by_subject(rep)
    lost = [r for r in rep.results if r.status == "failed"]
    assert len(lost) == 1 and LOST[how] in (lost[0].message or "") + str(lost[0].details), lost
    for subject, value in [("sf_a #2", 4), ("sf_a #3", 9), ("sf_b #5", 25), ("sf_b #6", 36)]:
        assert got[subject].status == "passed" and got[subject].details["value"] == value, got[subject]
    assert [s["name"] for s in rep.meta["stages"]] == ["sf_a", "sf_b"]


@pytest.mark.slow
def test_the_unsafe_fork_of_a_replacement_deadlocks_the_later_unit(slow_module, cleanup_stages, monkeypatch):
    """Seen failing: the replacement forked while sf_b's code holds the import lock; the importer waits forever."""
    monkeypatch.setattr(SharedQueue, "fork_guard", _unsafe_guard)
    got = _by_subject(_run(_stages(slow_module, "exit")))
    assert got["sf_a #2"].status == "passed" and got["sf_b #6"].status == "passed"
    importer = [r for r in got.values() if "importer" in r.subject]
    assert importer and importer[0].status == "failed", got      # a false failed record: what the guard prevents


@pytest.mark.slow
def test_an_unpicklable_unit_runs_forked_under_the_guard(slow_module, cleanup_stages, capfd):
    alone = _fork_possible()
    rep = _run(_stages(slow_module, None, unpicklable=True))
    got = _by_subject(rep)
    assert got["sf_a #3"].status == "passed" and got["sf_a #3"].details["value"] == 9, got
    assert all(r.status == "passed" for r in rep.results), [r for r in rep.results if r.status != "passed"]
    err = capfd.readouterr().err
    assert "cannot be sent to a worker process" in err
    assert ("forked for it" if alone else "in this process (forking is not safe here)") in err, err


@pytest.mark.slow
def test_the_unsafe_fork_of_an_unpicklable_unit_deadlocks_it(slow_module, cleanup_stages, monkeypatch):
    monkeypatch.setattr(SharedQueue, "fork_guard", _unsafe_guard)
    got = _by_subject(_run(_stages(slow_module, None, unpicklable=True)))
    assert got["sf_b #6"].status == "passed"
    importer = [r for r in got.values() if "importer" in r.subject]
    assert importer and importer[0].status == "failed", got


# -- a unit is pickled when its stage asks for it, not while another stage's code runs ----------------------------

class _Reduced:
    """Pickled through Python code (``__reduce__``): the pickler gives up the GIL between a dict's values."""

    def __init__(self, k: int) -> None:
        self.k = k

    def __reduce__(self):
        return (_Reduced, (self.k,))


SHARED_SIZE = 20_000
#: whether sp_b's code runs until sp_a's four count units have run (``sharing_stages``)
WAIT_FOR_COUNTS = {"on": False}


def _count(shared: dict, tag: str, k: int, mark: str | None = None) -> Report:
    if mark is not None:            # the unit ran (in a worker): sp_b's code may stop changing the dict
        open(os.path.join(mark, f"{tag}{k}"), "w").close()
    return Report([CheckResult("count", f"{tag} #{k}", "passed", worst=0.0, bound=1.0, details={"value": len(shared)})])


@pytest.fixture
def sharing_stages(monkeypatch, tmp_path):
    """``sp_a``: two 0.5 s units, then four that carry a dict of 20,000 entries and count them; ``sp_b``: one short
    unit, then 1.5 s of its own code adding and removing an entry of that same dict (as stages share the catalog's
    problems) — with ``WAIT_FOR_COUNTS`` set (the unsafe variant's test), until the four count units have run in
    workers (at most 6 s more: a unit that cannot be sent runs only after this code), so that each is pickled while
    the dict changes however late a loaded machine frees a worker (that test passed by luck once, under load).  Run one after another, every
    count is 20,000."""
    shared = {i: _Reduced(i) for i in range(SHARED_SIZE)}
    monkeypatch.setattr(schedule, "GATHER_SECONDS", 1.0)
    mark = str(tmp_path)

    @register_stage("sp_a", overlap=True)
    def sp_a(profile, context):
        units = [Unit("sp_a", f"slow{k}", _after, (0.5, "sp_a", k)) for k in (1, 2)]
        units += [Unit("sp_a", f"count{k}", _count, (shared, "sp_a", k, mark)) for k in range(3, 7)]
        reps = context.run_units(profile, units, costs=[5.0, 5.0, 0.0, 0.0, 0.0, 0.0])
        return Report([r for rep in reps for r in rep.results])

    @register_stage("sp_b", overlap=True)
    def sp_b(profile, context):
        reps = context.run_units(profile, [Unit("sp_b", "short", _square, ("sp_b", 5))], costs=[9.0])
        end = time.monotonic() + 1.5
        wait = WAIT_FOR_COUNTS["on"]
        while time.monotonic() < end or (wait and len(os.listdir(mark)) < 4 and time.monotonic() < end + 6.0):
            # its own code, holding the turn, changes what sp_a's units carry
            shared[-1] = _Reduced(-1)
            sum(range(2000))
            del shared[-1]
            sum(range(2000))
        return Report([r for rep in reps for r in rep.results])

    yield ["sp_a", "sp_b"]
    for n in ("sp_a", "sp_b"):
        STAGES.pop(n, None)


def _counts(rep: Report) -> list:
    return [r.details.get("value") for r in rep.results if r.check == "count"]


@pytest.mark.slow   # two workers, 0.5 s units, 1.5 s of the other stage's code: ~3 s
def test_units_are_pickled_as_their_stage_asks_not_beside_another_stages_code(sharing_stages, capfd):
    rep = _run(sharing_stages)
    assert _counts(rep) == [SHARED_SIZE] * 4 and all(r.status == "passed" for r in rep.results), _counts(rep)
    assert "cannot be sent" not in capfd.readouterr().err


@pytest.mark.slow
def test_units_pickled_by_the_main_thread_beside_another_stages_code_see_it_change(sharing_stages, monkeypatch,
                                                                                   capfd):
    """Seen failing: pickled when a worker frees (the branch's way), while sp_b's code changes the dict — the pickler
    sees it change size (three times: the unit leaves the workers) or sends a state with sp_b's extra entry."""
    monkeypatch.setattr(SharedQueue, "_ship_now", lambda self, job: None)
    monkeypatch.setitem(WAIT_FOR_COUNTS, "on", True)
    switch = sys.getswitchinterval()
    sys.setswitchinterval(1e-5)     # the threads switch within each pickling, not only now and then (5 ms)
    try:
        rep = _run(sharing_stages)
    finally:
        sys.setswitchinterval(switch)
    err = capfd.readouterr().err
    assert "cannot be sent" in err or _counts(rep) != [SHARED_SIZE] * 4, (_counts(rep), err[-1000:])


# -- no stage thread outlives the run: an interrupt while a stage's code is in HiGHS --------------------------------

INTERRUPTED = '''"""A run of two overlapping stages interrupted (SIGINT at 0.3 s) while one stage's code loops on HiGHS."""
import os, signal, sys, threading, time

import numpy as np

from verimono.execution.executors import ProcessRunner, Unit
from verimono.execution.profiles import get_profile
from verimono.lcs._highs import linprog_highs
from verimono.records.results import CheckResult, Report
from verimono.run.stages import RunContext, register_stage, run_stages
import verimono.run.stages.stopper as stopper
import verimono.run.stages.together as together

if sys.argv[1:] == ["unsafe"]:           # the pipeline branch's stage threads: daemons, not joined on the way out
    class _Unsafe(threading.Thread):
        def __init__(self, *a, **k):
            super().__init__(*a, **{**k, "daemon": True})

        def join(self, timeout=None):
            return None

    class _Shim:
        Thread, Event, Lock, local = _Unsafe, threading.Event, threading.Lock, threading.local
    together.threading = _Shim
    stopper._Stopper.stop = lambda self: None      # nor stopped, nor waited for (probe4's stopper and join came later)
    together._join_all = lambda *a, **k: None


def _sleepy(seconds):
    time.sleep(seconds)
    return Report([CheckResult("sleepy", "x", "passed", worst=0.0, bound=1.0)])


@register_stage("native_loop", overlap=True)
def native_loop(profile, context):
    import scipy.optimize._highspy._core as h

    linprog_highs(np.array([1.0, 1.0]), np.array([[-1.0, -1.0]]), np.array([-1.0]))   # verimono's own call, once
    lp = h.HighsLp()
    lp.num_col_, lp.num_row_ = 2, 1
    lp.col_cost_, lp.col_lower_, lp.col_upper_ = np.ones(2), np.zeros(2), np.full(2, h.kHighsInf)
    lp.row_lower_, lp.row_upper_ = np.array([1.0]), np.array([h.kHighsInf])
    lp.a_matrix_.format_ = h.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = np.array([0, 1, 2]), np.zeros(2, int), np.ones(2)
    solver = h._Highs()
    solver.setOptionValue("output_flag", False)
    solver.passModel(lp)
    end = time.monotonic() + 2.0
    signal.setitimer(signal.ITIMER_REAL, 0.3)     # the run is interrupted 0.3 s into this loop
    while time.monotonic() < end:          # this stage's own code, in this process: HiGHS (pybind11) again and again
        solver.run()
    return Report([r for rep in context.run_units(profile, [Unit("native_loop", "u", _sleepy, (0.1,))])
                   for r in rep.results])


@register_stage("waits", overlap=True)
def waits(profile, context):
    return Report([r for rep in context.run_units(profile, [Unit("waits", "u", _sleepy, (5.0,))]) for r in rep.results])


def _interrupt(signum, frame):
    raise KeyboardInterrupt


if __name__ == "__main__":
    signal.signal(signal.SIGALRM, _interrupt)
    runner = ProcessRunner(2)
    try:
        run_stages(["waits", "native_loop"], get_profile("ci"), RunContext(executor=runner, schedule="shared"))
    except KeyboardInterrupt:
        print("interrupted", flush=True)
        runner.close(kill=True)
        sys.exit(3)
    print("not interrupted", flush=True)
'''


@pytest.mark.slow   # a fresh interpreter importing verimono, and 2 s of HiGHS: ~4 s each
@pytest.mark.parametrize("threads", ["joined", "daemons"])
def test_an_interrupted_run_never_aborts_at_exit(threads, tmp_path):
    """The run is interrupted while one stage's code calls HiGHS (a pybind11 extension releasing the GIL) again
    and again.  Its stage threads are joined on the way out: the script exits with its own status, 3.  The
    pipeline branch's daemon threads, not joined ("daemons"): the interpreter finalizes while one is in HiGHS, its
    return to Python ends it by pthread_exit, whose unwinding aborts the process — "terminate called without an
    active exception", status 134 (SIGABRT) — seen failing so."""
    script = tmp_path / "interrupted.py"
    script.write_text(INTERRUPTED)
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    env.pop("VERIMONO_START_METHOD", None)
    proc = subprocess.run([sys.executable, str(script), *(["unsafe"] if threads == "daemons" else [])],
                          capture_output=True, text=True, timeout=120, env=env)
    assert "interrupted" in proc.stdout, proc.stderr[-2000:]
    if threads == "joined":
        assert proc.returncode == 3 and "terminate called" not in proc.stderr, (proc.returncode, proc.stderr[-2000:])
    else:
        assert proc.returncode == -signal.SIGABRT and "terminate called without an active exception" in proc.stderr, \
            (proc.returncode, proc.stderr[-2000:])


# -- the guard's decision, without processes (default tier) -----------------------------------------------------

class _FakeRunner:
    spec, workers, timeout = "process:2", 2, None


def test_fork_guard_holds_the_turn_and_refuses_a_thread_it_does_not_know(monkeypatch):
    monkeypatch.delenv("VERIMONO_START_METHOD", raising=False)
    q = SharedQueue(_FakeRunner())
    stop = threading.Event()
    stranger = threading.Thread(target=stop.wait, daemon=True)
    known = threading.Thread(target=stop.wait, daemon=True)
    stranger.start(), known.start()
    try:
        q._stage_threads = frozenset({known.ident})
        monkeypatch.setattr(schedule, "_native_threads", lambda: q._native0)
        with q.fork_guard() as fork:
            assert q.turn.locked()
            assert fork is False                        # a Python thread that is not a parked stage thread
        q._stage_threads = frozenset(t.ident for t in threading.enumerate() if t is not threading.main_thread())
        monkeypatch.setattr(schedule, "FORK_UNSAFE", ("verimono_no_such_module",))   # (JAX imported by another test)
        with q.fork_guard() as fork:
            assert fork is True                         # only stage threads, parked: the fork is safe
        assert not q.turn.locked()
        monkeypatch.setitem(sys.modules, "verimono_no_such_module", sys.modules[__name__])
        with q.fork_guard() as fork:
            assert fork is False                        # a module whose threads do not survive a fork (JAX, torch)
        monkeypatch.delitem(sys.modules, "verimono_no_such_module")
        monkeypatch.setattr(schedule, "_native_threads", lambda: q._native0 + 1)
        with q.fork_guard() as fork:
            assert fork is False                        # a native thread started since (a HiGHS or XLA pool)
        monkeypatch.setattr(schedule, "_native_threads", lambda: q._native0)
        monkeypatch.setenv("VERIMONO_START_METHOD", "spawn")
        with q.fork_guard() as fork:
            assert fork is False
    finally:
        stop.set()
        stranger.join(), known.join()


def test_fork_guard_waits_for_verimonos_own_report_threads_instead_of_spawning(monkeypatch):
    """The Python API (``execute`` with no drawer process) starts its own daemon threads: the matplotlib warm-up
    (an import, ~0.5 s) and the plots drawn after each stage.  A worker lost while one of them ran was *spawned*
    (0.5-0.9 s, and a script without ``if __name__ == "__main__"`` lost the whole run to a BadExecutor); the guard
    now waits for such a thread, which ends by itself, and forks — but never for a stranger's thread, and not
    past OWN_THREAD_WAIT."""
    from verimono.records.report.plots import PLOTS_THREAD, WARM_UP_THREAD

    monkeypatch.delenv("VERIMONO_START_METHOD", raising=False)
    monkeypatch.setattr(schedule, "FORK_UNSAFE", ("verimono_no_such_module",))
    q = SharedQueue(_FakeRunner())
    monkeypatch.setattr(schedule, "_native_threads", lambda: q._native0)
    # threads other tests left alive count as this queue's parked stage threads (as in the test above)
    q._stage_threads = frozenset(t.ident for t in threading.enumerate() if t is not threading.main_thread())
    for name in (WARM_UP_THREAD, PLOTS_THREAD):
        own = threading.Thread(target=time.sleep, args=(0.2,), name=name, daemon=True)
        own.start()
        with q.fork_guard() as fork:
            assert fork is True and not own.is_alive()   # waited for, then forked
    stop = threading.Event()
    stuck = threading.Thread(target=stop.wait, name=WARM_UP_THREAD, daemon=True)
    stuck.start()
    monkeypatch.setattr(schedule, "OWN_THREAD_WAIT", 0.1)
    try:
        t0 = time.monotonic()
        with q.fork_guard() as fork:
            assert fork is False and stuck.is_alive()    # not ended within the wait: spawn, as before
        assert time.monotonic() - t0 < 2.0
    finally:
        stop.set()
        stuck.join()


RETURNS_AND_EXITS = '''
from verimono.reference import catalog
from verimono.run.execute import execute
from verimono.run.stages import RunContext

if __name__ == "__main__":
    names = ("moving half-space", "moving box", "linear x' = -Mx", "t|x| (n=1)")
    execute(command="run", profile_name="ci", stages=["convergence", "trajectory_laws"], executor="process:2",
            context=RunContext(problems=[p for p in catalog() if p.name in names], seed=0))
'''


@pytest.mark.slow   # three fresh interpreters, each a small run on 2 worker processes: ~2 s each
def test_a_script_that_exits_as_execute_returns_never_aborts(tmp_path):
    """The Python API (``execute`` on worker processes, no drawer process) draws each stage's plots in a thread of
    the user's process (:func:`verimono.records.report.plots.draw_ahead`).  That thread was a daemon: a script
    exiting as ``execute`` returned finalized the interpreter under it while it was in matplotlib's Agg
    (pybind11) — "terminate called without an active exception", status 134 (2 of 3 runs here, 6 of 6 of a
    whole trajectory_laws + convergence run, on 5a13165 as on a2761d7).  Not a daemon now: the exit waits for the
    plots being drawn."""
    script = tmp_path / "returns_and_exits.py"
    script.write_text(RETURNS_AND_EXITS)
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    env.pop("VERIMONO_START_METHOD", None)
    for _ in range(3):
        proc = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120, env=env)
        assert proc.returncode == 0 and "terminate called" not in proc.stderr, (proc.returncode, proc.stderr[-2000:])
