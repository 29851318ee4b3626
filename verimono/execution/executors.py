"""Fan-out of a verification run: independent *units* (a stage's per-subject batteries, per-reference
studies) mapped over an executor, their results merged in the units' own order.

``verimono run --executor SPEC`` (and ``verimono check``) chooses where units run:

* ``serial`` (the default of the Python API): in this process, one after the other;
* ``auto`` (the default of ``verimono run`` and ``verimono check``; ``$VERIMONO_EXECUTOR`` overrides):
  ``process:N`` with ``N`` the machine's cores (at most :data:`AUTO_MAX_WORKERS`), serial on a one-core
  machine or, saying why, when no worker can start (a script read from standard input cannot be
  re-imported by a spawned process);
* ``process:N``: ``N`` worker processes of this machine (forked where that is safe, else spawned:
  :func:`start_method`);
* ``tcp://host:port`` (any ``scheme://address``): the workers of a running ``dask.distributed`` scheduler
  (``pip install "verimono[dask]"``; verimono must be importable on the workers).

A unit is ``fn(*args) -> Report``, shipped with ``cloudpickle`` (closures, lambdas and a ``verimono check``
target loaded from a file travel by value), with the run configuration (:mod:`verimono.execution.config`:
profile, explicit budget, seed) and the run's calibration.  Each worker runs the unit under that
configuration, loads the run's hypothesis profile and pins BLAS to one thread, as ``verimono run`` does, so a
unit's records do not depend on where it ran: under a derandomized profile the merged report equals the
serial run's apart from timings.

A unit never takes the run down with it: a unit that raises becomes one record ``unit[<stage>: <label>]``
judged by the one exception policy (:func:`verimono.records.verdicts.classify`: a limit of verimono's own
solvers is undecided, anything else the subject raised is failed), one whose worker dies or that runs longer
than ``timeout`` seconds one *failed* record naming it (:func:`unit_failure`); the records of every other
unit are kept.  With ``process:N`` the unit a dying worker was running is known
exactly (each worker runs one unit at a time) and a fresh worker replaces it; on dask a unit that kills
workers is reported once the scheduler gives up on it (``KilledWorker``, after its ``allowed-failures``).
A ``process:N`` worker whose unit is blocked in native code past its time budget, which the budget's
interrupt cannot stop, answers for it before it exits (:mod:`verimono.execution.watchdog`): the records the unit
finished and a failed record naming the hung call.  The explicit budget of the sending process
(``--timeout``) applies on the workers too.
"""

from __future__ import annotations

import dataclasses
import functools
import multiprocessing
import os
import sys
import time
import traceback
from collections import deque
from multiprocessing.connection import wait as _wait
from typing import Any, Callable, Sequence

from . import watchdog
from .calibration import calibration, set_calibration
from ..core.errors import BadExecutor
from . import config as _config
from .config import RunConfig
from .profiles import load_hypothesis_profile
from ..records.results import FAILED, Report
from ..records.verdicts import classify, new_record
from .timeouts import unlimited

#: the check name of the record that stands for a unit that crashed, died or timed out
UNIT_CHECK = watchdog.UNIT_CHECK


@dataclasses.dataclass
class Unit:
    """One independent piece of a stage: ``fn(*args) -> Report``; ``label`` names it in progress and in
    the failed record that stands for it if it cannot finish."""

    stage: str
    label: str
    fn: Callable[..., Report]
    args: tuple = ()


def unit_record(unit: Unit, status: str, message: str, *, exception: str | None = None,
                traceback_text: str | None = None, duration: float | None = None) -> Report:
    """The report of a unit that did not finish: one record ``unit[<stage>: <label>]`` with ``status``."""
    details: dict[str, Any] = {}
    if exception:
        details["exception"] = exception
    if traceback_text:
        details["traceback"] = traceback_text
    return Report([new_record(UNIT_CHECK, f"{unit.stage}: {unit.label}", status, message=message,
                              duration=duration, details=details)])


def unit_failure(unit: Unit, message: str, *, traceback_text: str | None = None,
                 duration: float | None = None) -> Report:
    """The report of a unit that did not finish for a reason of its own — its worker died, it ran past the
    executor's timeout: one failed record ``unit[<stage>: <label>]``."""
    return unit_record(unit, FAILED, message, traceback_text=traceback_text, duration=duration)


def raised(exc: BaseException) -> tuple[str, str]:
    """``(status, message)`` of a unit that raised ``exc``: the one exception policy
    (:func:`verimono.records.verdicts.classify`) — a limit of verimono's own solvers is undecided in a unit as
    in a law, a failure of the subject is ``raised <type>: <message>``."""
    status, message = classify(exc)
    return status, ("raised " + message if status == FAILED else message)


def unit_raised(unit: Unit, exc: BaseException, *, traceback_text: str | None = None,
                duration: float | None = None) -> Report:
    """The report of a unit that raised ``exc`` (:func:`raised`)."""
    status, message = raised(exc)
    return unit_record(unit, status, message, exception=type(exc).__name__, traceback_text=traceback_text,
                       duration=duration)


# -- what runs on a worker ----------------------------------------------------------------------------

#: BLAS threads for a verification run, in its process and its workers: every matrix here is small, so extra
#: BLAS threads only contend for the cores; on the 2-core reference machine, under load, threaded OpenBLAS made
#: the catalog's convergence studies vary from 0.4 s to 31 s, against a steady 0.4 s single-threaded
BLAS_THREADS = 1


@functools.cache
def _one_blas_thread() -> None:
    """:data:`BLAS_THREADS` in this process, as in the ``verimono run`` process (once: threadpoolctl inspects
    every loaded library, 1.3 ms a call here)."""
    try:
        from threadpoolctl import threadpool_limits

        threadpool_limits(limits=BLAS_THREADS, user_api="blas")
    except ImportError:  # pragma: no cover - threadpoolctl is a dependency
        pass


def config_for(profile: RunConfig | str | None) -> RunConfig:
    """The run configuration units run under: ``profile`` itself, or the current one
    (:func:`verimono.execution.config.current`) with the profile named ``profile`` (``None``: as it is)."""
    if isinstance(profile, RunConfig):
        return profile
    cfg = _config.current()
    return cfg if profile is None or profile == cfg.profile else dataclasses.replace(cfg, profile=profile)


def _prepare_worker(cfg: RunConfig) -> None:
    """The run's hypothesis profile (loaded again for every unit: a unit may load another; a user's own
    profile is not registered in a fresh worker, so only verimono's) and one BLAS thread."""
    if cfg.effort is not None:
        load_hypothesis_profile(cfg.profile)
    _one_blas_thread()


def run_payload(payload: bytes) -> bytes:
    """Run one shipped unit: ``payload`` is ``cloudpickle.dumps((config, fn, args, limits, stage, label))``
    (``config``: the run configuration, :mod:`verimono.execution.config` — profile, explicit budget, seed —
    under which the unit runs here; ``limits``: the sending process's calibration, the unit of the profile's
    budgets — :func:`_limits` — applied here too, so a worker's budgets are the run's); the answer is ``cloudpickle.dumps(("ok", report))`` or ``("error", status, message,
    exception type, traceback, seconds)`` (the exception judged here, :func:`raised`) — never an exception, so a unit's own error is told apart from the worker's death.  (A
    ``process:N`` worker whose unit blocks in native code answers ``("hang", report)`` instead and exits:
    :func:`_process_worker`.)"""
    import cloudpickle

    start = time.perf_counter()
    try:
        cfg, fn, args, limits, stage, label = cloudpickle.loads(payload)
        _prepare_worker(cfg)
        if limits.get("calibration"):
            set_calibration(limits["calibration"])
        with watchdog.scope(stage=stage, label=label), _config.using(cfg):
            out = fn(*args)
        if not isinstance(out, Report):
            raise TypeError(f"a unit returned {type(out).__name__}, expected a verimono.Report")
        return cloudpickle.dumps(("ok", out))
    except Exception as exc:
        status, message = raised(exc)     # judged here, where the exception is
        return cloudpickle.dumps(("error", status, message, type(exc).__name__, traceback.format_exc(limit=8),
                                  time.perf_counter() - start))


def _decode(unit: Unit, answer: bytes) -> Report:
    return _decode_answer(unit, answer)[0]


def _decode_answer(unit: Unit, answer: bytes) -> tuple[Report, bool]:
    """The report an answer stands for, and whether its worker has ended (a unit blocked in native code:
    the records it finished and the failed record of the hung call)."""
    import cloudpickle

    try:
        out = cloudpickle.loads(answer)
    except Exception as exc:
        return unit_failure(unit, f"its result could not be read back ({type(exc).__name__}: {exc})"), False
    if out[0] == "ok":
        return out[1], False
    if out[0] == "hang":
        return out[1], True
    _, status, message, exception, traceback_text, duration = out
    return unit_record(unit, status, message, exception=exception, traceback_text=traceback_text,
                       duration=duration), False


#: seconds a new worker process may take to import verimono and say it is ready
WORKER_START_TIMEOUT = 300.0


#: exit status of a worker that ended itself on a unit blocked in native code (after answering for it)
HANG_EXIT = 3


def _process_worker(conn: Any) -> None:
    """Loop of a ``process:N`` worker: say ``ready`` once verimono is imported (so a unit's timeout does
    not count the worker's start), then receive a payload and answer, until an empty message.

    A call of the unit blocked in native code past its time budget (:mod:`verimono.execution.watchdog`) cannot be
    interrupted: the watchdog thread answers for the unit instead — ``("hang", report)``, the records the
    unit finished and the failed record of the hung call — ends the call's child processes and exits
    (status :data:`HANG_EXIT`); the parent replaces the worker.  One answer per payload, whichever comes
    first (``lock``)."""
    import threading

    import cloudpickle
    import scipy.linalg  # noqa: F401  (with numpy and verimono, imported here: what every unit needs)

    # spawn passed the connection as an inheritable descriptor: a child process of the unit's (os.system)
    # would hold it open, and the parent would not see this worker's end until that child's
    os.set_inheritable(conn.fileno(), False)
    lock, state = threading.Lock(), {"busy": False}

    def on_hang(hang: watchdog.Hang) -> None:
        with lock:
            if not state["busy"]:     # pragma: no cover - the unit returned meanwhile: nothing to answer
                return
            watchdog.ending()
            try:
                conn.send_bytes(cloudpickle.dumps(("hang", watchdog.hang_report(hang))))
            except Exception:  # noqa: BLE001 - the parent then sees a dead worker, which it reports too
                pass
            watchdog.end_process(HANG_EXIT)

    conn.send_bytes(b"ready")
    with watchdog.on_hang(on_hang):
        while True:
            try:
                payload = conn.recv_bytes()
            except (EOFError, OSError):
                return
            if not payload:
                return
            state["busy"] = True
            answer = run_payload(payload)
            with lock:
                state["busy"] = False
                conn.send_bytes(answer)


def _limits() -> dict[str, float | None]:
    """What a worker needs besides the run configuration to bound a unit as this process would: this
    process's calibration (the unit of the profile's budgets)."""
    return {"calibration": calibration()}


def _ship(unit: Unit, profile: RunConfig | str | None) -> bytes:
    import cloudpickle

    _register_targets_by_value()
    return cloudpickle.dumps((config_for(profile), unit.fn, unit.args, _limits(), unit.stage, unit.label))


def _register_targets_by_value() -> None:
    """A ``verimono check`` target loaded from a ``.py`` file lives in a module no worker can import:
    ship that module's functions by value."""
    import sys

    import cloudpickle

    for name, module in list(sys.modules.items()):
        if name.startswith("verimono_target_") and module is not None:
            try:
                cloudpickle.register_pickle_by_value(module)
            except ValueError:  # pragma: no cover - already registered
                pass


def ship_by_value(obj: Any) -> None:
    """Let workers that cannot import ``obj``'s module still run it: a module of the user's (not verimono's,
    not an installed distribution's) is shipped by value with every unit (``cloudpickle``)."""
    import sys

    import cloudpickle

    module = sys.modules.get(getattr(obj, "__module__", None) or "")
    path = getattr(module, "__file__", None) or ""
    if module is None or module.__name__.split(".")[0] in ("verimono", "__main__") or "-packages" in path:
        return
    try:
        cloudpickle.register_pickle_by_value(module)
    except ValueError:  # pragma: no cover - a module cloudpickle refuses: it ships by reference
        pass


# -- how workers start ----------------------------------------------------------------------------------

#: modules whose native threads or devices do not survive ``fork`` (their own documentation says so): while
#: one is loaded, workers are spawned
FORK_UNSAFE = ("jax", "torch", "tensorflow", "cupy", "numba", "mxnet", "ray", "distributed", "grpc")


def start_method() -> str:
    """How the next worker process starts: ``fork`` — a copy of this process, ready at once, with verimono and
    the subject already imported — where that is safe: Linux, no other Python thread running (a thread
    holding a lock at the fork would leave it held in the copy forever) and none of :data:`FORK_UNSAFE`
    imported; ``spawn`` (a fresh interpreter importing verimono, about 0.8 s on a 2-core machine) otherwise.
    ``$VERIMONO_START_METHOD`` (``fork`` or ``spawn``) decides instead.  NumPy's OpenBLAS threads are safe:
    OpenBLAS stops them around a fork (``pthread_atfork``)."""
    import threading

    chosen = os.environ.get("VERIMONO_START_METHOD", "").strip().lower()
    if chosen in ("fork", "spawn"):
        return chosen
    if chosen:
        raise BadExecutor(f"$VERIMONO_START_METHOD must be fork or spawn, got {chosen!r}")
    safe = (sys.platform.startswith("linux") and threading.active_count() == 1
            and not any(name in sys.modules for name in FORK_UNSAFE))
    return "fork" if safe else "spawn"


# -- runners --------------------------------------------------------------------------------------------

Progress = Callable[[int, int, str], None]


class SerialRunner:
    """Units in this process, in order (what ``verimono run`` does without ``--executor``)."""

    spec = "serial"

    def map(self, units: Sequence[Unit], profile: RunConfig | str | None, progress: Progress) -> list[Report]:
        with _config.using(config_for(profile)):
            return self._map(units, progress)

    def _map(self, units: Sequence[Unit], progress: Progress) -> list[Report]:
        out = []
        for i, u in enumerate(units):
            progress(i, len(units), u.label)
            start = time.perf_counter()
            try:
                with watchdog.scope(stage=u.stage, label=u.label):   # named should it block in native code
                    rep = u.fn(*u.args)
                if not isinstance(rep, Report):
                    raise TypeError(f"a unit returned {type(rep).__name__}, expected a verimono.Report")
            except Exception as exc:
                rep = unit_raised(u, exc, traceback_text=traceback.format_exc(limit=8),
                                  duration=time.perf_counter() - start)
            watchdog.finished(rep)
            out.append(rep)
        progress(len(units), len(units), "")
        return out

    def close(self) -> None:
        pass


class ProcessRunner:
    """``N`` worker processes, each running one unit at a time; a worker that dies or overruns
    ``timeout`` is replaced and its unit becomes a failed record (see the module docstring)."""

    def __init__(self, workers: int, timeout: float | None = None, *, fallback: bool = False) -> None:
        if workers < 1:
            raise BadExecutor(f"process:N needs N >= 1, got {workers}")
        self.workers, self.timeout = int(workers), timeout
        #: called with each unit's report as it comes back, before the others have (the run sends its plots
        #: to the drawer from it: :func:`verimono.records.report.plots.draw_ahead`); an error there is not the unit's
        self.on_report: Callable[[Report], None] | None = None
        #: ``auto``: when the workers cannot start, say so and run the units serially instead
        self.fallback = fallback
        self._serial: SerialRunner | None = None
        self.spec = f"process:{self.workers}"
        self._pool: list[tuple[Any, Any]] = []  # (process, connection)
        self._launched: list[tuple[Any, Any]] = []   # started by prestart(), not yet known to be ready

    def prestart(self) -> None:
        """Start every worker now without waiting for it (its imports take about 1.5 s): the first
        :meth:`map` then finds them ready, or waits for them as for any start."""
        self._launched += self._launch(self.workers - len(self._pool) - len(self._launched))

    def _launch(self, count: int) -> list[tuple[Any, Any]]:
        started = []
        ctx = multiprocessing.get_context(start_method())
        sys.stdout.flush(), sys.stderr.flush()       # a forked copy must not write this process's buffers again
        for _ in range(max(0, count)):
            parent, child = ctx.Pipe(duplex=True)
            # not a daemon: a unit may itself start a process pool (a large convergence study)
            proc = ctx.Process(target=_process_worker, args=(child,), name="verimono-unit-worker")
            proc.start()
            child.close()
            started.append((proc, parent))
        return started

    def _start(self, count: int = 1) -> list[tuple[Any, Any]]:
        """``count`` new workers (those :meth:`prestart` launched first), returned once each is ready."""
        started, self._launched = self._launched[:max(0, count)], self._launched[max(0, count):]
        started += self._launch(count - len(started))
        return self._ready(started)

    def _ready(self, started: list[tuple[Any, Any]]) -> list[tuple[Any, Any]]:
        for w in started:
            try:
                ready = w[1].poll(WORKER_START_TIMEOUT) and w[1].recv_bytes() == b"ready"
            except (EOFError, OSError):
                ready = False
            if not ready:
                w[0].join(timeout=1.0)   # a worker that died: its own exit status, before any kill
                code = w[0].exitcode
                for x in started:
                    self._stop(x, kill=True)
                raise BadExecutor(f"a worker process of {self.spec} " + (
                    f"exited with status {code} before it was ready (a spawned process re-imports the main "
                    "module: run verimono from a file or the command line, not from standard input)"
                    if code not in (None, -9) else f"did not start within {WORKER_START_TIMEOUT:g} s"))
        return started

    @staticmethod
    def _stop(worker: tuple[Any, Any], kill: bool = False) -> None:
        proc, conn = worker
        if kill:
            proc.kill()
        else:
            try:
                conn.send_bytes(b"")
            except OSError:
                pass
        proc.join(timeout=5)
        if proc.is_alive():
            proc.kill()
            proc.join()
        conn.close()

    def map(self, units: Sequence[Unit], profile: RunConfig | str | None, progress: Progress) -> list[Report]:
        results: list[Report | None] = [None] * len(units)
        pending = deque(range(len(units)))
        busy: dict[Any, tuple[tuple[Any, Any], int, float]] = {}   # conn -> (worker, unit index, start)
        arrived: list[Report] = []                                  # answered, not yet given to on_report
        if self._serial is not None:
            return self._serial.map(units, profile, progress)
        try:
            self._pool += self._start(min(self.workers, len(units)) - len(self._pool))
        except BadExecutor as exc:
            if not self.fallback:
                raise
            print(f"verimono: {exc}; running the units serially", file=sys.stderr)
            self.close(kill=True)
            self.workers, self.spec, self._serial = 1, "serial", SerialRunner()
            return self._serial.map(units, profile, progress)
        idle = list(self._pool)
        done = 0
        progress(0, len(units), "")

        def assign(worker):
            i = pending.popleft()
            worker[1].send_bytes(_ship(units[i], profile))
            busy[worker[1]] = (worker, i, time.monotonic())
            progress(done, len(units), units[i].label)

        def replace(worker):
            self._pool.remove(worker)
            (new,) = self._start()
            self._pool.append(new)
            return new

        try:
            while pending or busy:
                while pending and idle:
                    assign(idle.pop())
                wait_for = None
                if self.timeout is not None:
                    now = time.monotonic()
                    wait_for = max(0.0, min(start + self.timeout - now for _, _, start in busy.values()))
                for conn in _wait(list(busy), timeout=wait_for):
                    worker, i, start = busy.pop(conn)
                    try:
                        answer = conn.recv_bytes()
                    except (EOFError, OSError):
                        worker[0].join(timeout=5)
                        code = worker[0].exitcode
                        how = (f"signal {-code}" if code is not None and code < 0 else f"exit status {code}")
                        results[i] = unit_failure(units[i], f"its worker process died ({how}) while running it",
                                                  duration=time.monotonic() - start)
                        self._stop(worker, kill=True)
                        worker = replace(worker)
                    else:
                        results[i], ended = _decode_answer(units[i], answer)
                        if ended:          # it answered for a unit blocked in native code, and exits
                            self._stop(worker, kill=False)
                            worker = replace(worker)
                        elif self.on_report is not None:
                            arrived.append(results[i])
                    done += 1
                    idle.append(worker)
                    progress(done, len(units), units[i].label)
                while pending and idle:   # the next units first: the hook below must not keep a worker waiting
                    assign(idle.pop())
                for rep in arrived:
                    try:
                        self.on_report(rep)
                    except Exception:  # noqa: BLE001 - a plot asked ahead is drawn by the report instead
                        pass
                arrived.clear()
                if self.timeout is not None:
                    now = time.monotonic()
                    for conn, (worker, i, start) in list(busy.items()):
                        if now - start > self.timeout:
                            busy.pop(conn)
                            self._stop(worker, kill=True)
                            results[i] = unit_failure(units[i], f"timed out after {self.timeout:g} s (worker "
                                                      "stopped)", duration=now - start)
                            done += 1
                            idle.append(replace(worker))
        except BaseException:
            self.close(kill=True)
            raise
        progress(len(units), len(units), "")
        return [r for r in results]  # type: ignore[misc]

    def close(self, kill: bool = False) -> None:
        workers = self._pool + self._launched
        if not kill:   # ask every worker to stop first, so that they shut down together
            for _, conn in workers:
                try:
                    conn.send_bytes(b"")
                except OSError:
                    pass
        for w in workers:
            self._stop(w, kill=kill)
        self._pool, self._launched = [], []


class DaskRunner:
    """The workers of a ``dask.distributed`` scheduler at ``address`` (or an existing ``Client``).

    At most as many units are in flight as the cluster has worker threads, so a unit's ``timeout`` counts
    from when it could start; a unit still unfinished then is cancelled and reported."""

    def __init__(self, address: Any, timeout: float | None = None) -> None:
        try:
            from distributed import Client
        except ImportError:
            raise BadExecutor(f"--executor {address}: dask.distributed is not installed "
                              '(pip install "verimono[dask]")') from None
        self.timeout = timeout
        if isinstance(address, Client):
            self.client, self._own = address, False
            self.spec = str(address.scheduler.address if address.scheduler else address)
        else:
            try:
                self.client, self._own = Client(address, timeout="30s"), True
            except (OSError, TimeoutError) as exc:
                raise BadExecutor(f"--executor {address}: no dask scheduler answers there ({exc})") from None
            self.spec = str(address)

    def _slots(self) -> int:
        try:
            return max(1, sum(self.client.nthreads().values()))
        except Exception:  # pragma: no cover
            return 1

    def map(self, units: Sequence[Unit], profile: RunConfig | str | None, progress: Progress) -> list[Report]:
        from distributed import wait as dwait

        results: list[Report | None] = [None] * len(units)
        pending = deque(range(len(units)))
        flying: dict[Any, tuple[int, float]] = {}
        done = 0
        progress(0, len(units), "")
        try:
            while pending or flying:
                slots = self._slots()
                while pending and len(flying) < slots:
                    i = pending.popleft()
                    fut = self.client.submit(run_payload, _ship(units[i], profile), pure=False,
                                             key=f"verimono-unit-{i}-{os.urandom(4).hex()}")
                    flying[fut] = (i, time.monotonic())
                    progress(done, len(units), units[i].label)
                wait_for = 5.0
                if self.timeout is not None:
                    now = time.monotonic()
                    wait_for = max(0.05, min(start + self.timeout - now for _, start in flying.values()))
                try:
                    finished, _ = dwait(list(flying), timeout=wait_for, return_when="FIRST_COMPLETED")
                except TimeoutError:
                    finished = set()
                for fut in finished:
                    i, start = flying.pop(fut)
                    if fut.status == "finished":
                        results[i] = _decode(units[i], fut.result())
                    else:
                        exc = fut.exception()
                        name = type(exc).__name__
                        what = ("its worker died while running it (the scheduler gave up: "
                                f"{name}: {exc})" if name == "KilledWorker" else f"failed on dask: {name}: {exc}")
                        results[i] = unit_failure(units[i], what, duration=time.monotonic() - start)
                    done += 1
                    progress(done, len(units), units[i].label)
                if self.timeout is not None:
                    now = time.monotonic()
                    for fut, (i, start) in list(flying.items()):
                        if now - start > self.timeout:
                            flying.pop(fut)
                            fut.cancel()
                            results[i] = unit_failure(units[i], f"timed out after {self.timeout:g} s (cancelled)",
                                                      duration=now - start)
                            done += 1
        except BaseException:
            for fut in flying:
                fut.cancel()
            raise
        progress(len(units), len(units), "")
        return [r for r in results]  # type: ignore[misc]

    def close(self) -> None:
        if self._own:
            self.client.close()


#: ``auto`` starts at most this many worker processes (a run has about 15 units per stage)
AUTO_MAX_WORKERS = 4


def make_runner(spec: Any = None, *, timeout: float | None = None) -> Any:
    """A runner for ``spec``: ``None``/``"serial"``, ``"auto"`` (``process:N`` with ``N`` this machine's cores,
    at most :data:`AUTO_MAX_WORKERS`; serial on one core), ``"process:N"``, a ``scheme://address`` of a dask
    scheduler, or a ``distributed.Client``; :class:`BadExecutor` for anything else.  ``timeout``: seconds a
    unit may run on a worker (``None`` or ``inf``: no limit)."""
    timeout = None if unlimited(timeout) else timeout
    if spec is None or spec == "serial":
        return SerialRunner()
    if isinstance(spec, str):
        if spec == "auto":   # every core of this machine, up to AUTO_MAX_WORKERS; serial on one core
            n = min(os.cpu_count() or 1, AUTO_MAX_WORKERS)
            return ProcessRunner(n, timeout, fallback=True) if n >= 2 else SerialRunner()
        if spec.startswith("process:"):
            try:
                n = int(spec.partition(":")[2])
            except ValueError:
                raise BadExecutor(f"--executor {spec}: expected process:N with an integer N") from None
            if n < 1:
                raise BadExecutor(f"--executor {spec}: process:N needs N >= 1 worker processes")
            return ProcessRunner(n, timeout)
        if spec == "process":
            return ProcessRunner(os.cpu_count() or 1, timeout)
        if "://" in spec:
            return DaskRunner(spec, timeout)
        raise BadExecutor(f"--executor {spec}: expected serial, process:N or the address of a dask "
                          "scheduler (tcp://host:8786)")
    if type(spec).__name__ == "Client" and type(spec).__module__.startswith("distributed"):
        return DaskRunner(spec, timeout)
    if hasattr(spec, "map") and hasattr(spec, "close"):
        return spec
    raise BadExecutor(f"executor must be serial, process:N, a dask scheduler address or Client, got {spec!r}")


__all__ = ["Unit", "UNIT_CHECK", "AUTO_MAX_WORKERS", "ship_by_value", "BadExecutor", "SerialRunner", "ProcessRunner", "DaskRunner", "make_runner",
           "unit_failure", "unit_record", "unit_raised", "raised", "run_payload"]
