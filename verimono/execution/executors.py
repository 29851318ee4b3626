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

A unit that cannot be pickled (a module holding a ``threading.Lock``, a ``ctypes`` library) runs in a worker
process forked for it, where nothing is pickled but its answer, or in this process where forking is not safe
— one line on standard error says so; it is never a failed record.

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

This module holds the runners; a unit and its records are :mod:`verimono.execution.units`, what runs on a
worker and how units are shipped :mod:`verimono.execution.workers`.
"""

from __future__ import annotations

import multiprocessing
import os
import sys
import time
import traceback
from collections import deque
from multiprocessing.connection import wait as _wait
from typing import Any, Callable, Sequence

from . import config as _config
from . import watchdog
from ..core.errors import BadExecutor
from .config import RunConfig
from ..records.results import Report
from .lifetime import started_from_main_thread
from .timeouts import unlimited
from .units import UNIT_CHECK, Unit, config_for, raised, unit_failure, unit_raised, unit_record  # noqa: F401
from .workers import (BLAS_THREADS, FORK_UNSAFE, HANG_EXIT, WORKER_START_TIMEOUT, _decode, _decode_answer,  # noqa: F401
                      _limits, _process_worker, _ship, run_payload, ship_by_value, start_method)

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

    def _launch(self, count: int, method: str | None = None) -> list[tuple[Any, Any]]:
        """``count`` workers started (not yet ready), by ``method`` (``fork``/``spawn``; ``None``: :func:`start_method`)."""
        started = []
        ctx = multiprocessing.get_context(method or start_method())
        sys.stdout.flush(), sys.stderr.flush()       # a forked copy must not write this process's buffers again
        for _ in range(max(0, count)):
            parent, child = ctx.Pipe(duplex=True)
            # not a daemon: a unit may itself start a process pool (a large convergence study)
            proc = ctx.Process(target=_process_worker, args=(child,), name="verimono-unit-worker",
                               kwargs={"leader": os.getpid(), "kernel": started_from_main_thread()})
            proc.start()
            child.close()
            started.append((proc, parent))
        return started

    def _start(self, count: int = 1, method: str | None = None) -> list[tuple[Any, Any]]:
        """``count`` new workers (those :meth:`prestart` launched first), returned once each is ready; ``method``
        as :meth:`_launch`'s (the shared queue chooses it: :meth:`verimono.execution.schedule.SharedQueue.fork_guard`)."""
        started, self._launched = self._launched[:max(0, count)], self._launched[max(0, count):]
        n = count - len(started)
        started += self._launch(n) if method is None else self._launch(n, method)
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

    def start_all(self) -> bool:
        """Every worker started and ready (:class:`verimono.execution.schedule.SharedQueue` hands units to them
        itself); ``False`` when they run serially instead (``auto`` whose workers cannot start, as :meth:`map`
        falls back)."""
        return self._serial is None and self._fill(self.workers)

    def _fill(self, count: int) -> bool:
        """The pool started up to ``count`` workers; ``False`` when they cannot start and ``auto`` falls back to
        running serially from now on (said once on standard error); without the fallback the error is raised."""
        try:
            self._pool += self._start(count - len(self._pool))
        except BadExecutor as exc:
            if not self.fallback:
                raise
            print(f"verimono: {exc}; running the units serially", file=sys.stderr)
            self.close(kill=True)
            self.workers, self.spec, self._serial = 1, "serial", SerialRunner()
            return False
        return True

    def map(self, units: Sequence[Unit], profile: RunConfig | str | None, progress: Progress) -> list[Report]:
        results: list[Report | None] = [None] * len(units)
        pending = deque(range(len(units)))
        busy: dict[Any, tuple[tuple[Any, Any], int, float]] = {}   # conn -> (worker, unit index, start)
        arrived: list[Report] = []                                  # answered, not yet given to on_report
        if self._serial is not None or not self._fill(min(self.workers, len(units))):
            return self._serial.map(units, profile, progress)
        idle = list(self._pool)
        done = 0
        cfg = config_for(profile)
        here: list[int] = []                                        # units that cannot be pickled
        why: list[str] = []
        progress(0, len(units), "")

        def assign_all():
            while pending and idle:
                i = pending.popleft()
                try:
                    payload = _ship(units[i], cfg)
                except Exception as exc:  # noqa: BLE001 - it cannot travel: run where nothing is pickled
                    here.append(i)
                    why.append(f"{type(exc).__name__}: {exc}")
                    continue
                worker = idle.pop()
                worker[1].send_bytes(payload)
                busy[worker[1]] = (worker, i, time.monotonic())
                progress(done, len(units), units[i].label)

        def replace(worker):
            self._pool.remove(worker)
            (new,) = self._start()
            self._pool.append(new)
            return new

        try:
            while pending or busy:
                assign_all()
                if not busy:
                    break
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
                assign_all()              # the next units first: the hook below must not keep a worker waiting
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
            for i in unpicklable(units, here, why, forked=start_method() == "fork"):
                results[i] = self._run_unpicklable(units[i], cfg)
                done += 1
                progress(done, len(units), units[i].label)
        except BaseException:
            self.close(kill=True)
            raise
        progress(len(units), len(units), "")
        return [r for r in results]  # type: ignore[misc]

    def _run_unpicklable(self, unit: Unit, cfg: RunConfig) -> Report:
        """A unit that cannot be pickled: in a worker forked for it (nothing of it is pickled: it is in the
        forked copy's memory) where forking is safe (:func:`verimono.execution.workers.start_method`), else
        here, serially (:func:`run_here`)."""
        if start_method() != "fork":
            return run_here(unit, cfg)
        return run_forked(unit, cfg, self.timeout)

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


def unpicklable(units: Sequence[Unit], indices: list[int], why: list[str], forked: bool) -> list[int]:
    """``indices`` (of ``units`` that could not be pickled, for the reasons ``why``), after one line on standard
    error saying so and where they run instead — never a failed record: what cannot be pickled is a limit of
    the executor, not a fault of the subject (a module holding a ``threading.Lock`` or a ``ctypes`` library
    failed its stage before, with ``--executor serial`` passing it).  ``forked``: they run in worker
    processes forked for them, else in this process."""
    if indices:
        one = len(indices) == 1
        where = (("it runs" if one else "each runs") + " in a worker process forked for it" if forked else
                 ("it runs" if one else "they run") + " in this process (forking is not safe here)")
        names = ", ".join(units[i].label for i in indices[:3]) + (", ..." if len(indices) > 3 else "")
        print(f"verimono: {len(indices)} unit{'' if one else 's'} of {units[indices[0]].stage} ({names}) cannot be "
              f"sent to a worker process ({why[0]}): {where}", file=sys.stderr)
    return list(indices)


def run_here(unit: Unit, cfg: RunConfig) -> Report:
    """``unit`` in this process, as :class:`SerialRunner` runs it (under ``cfg``)."""
    with _config.using(cfg):
        return SerialRunner()._map([unit], lambda *a: None)[0]


def run_forked(unit: Unit, cfg: RunConfig, timeout: float | None = None) -> Report:
    """``unit`` in a worker process forked for it (:func:`verimono.execution.workers._process_worker` with
    the job in its memory): only its answer is pickled.  A worker that dies or overruns ``timeout`` seconds
    is a failed record, as for any worker."""
    ctx = multiprocessing.get_context("fork")
    parent, child = ctx.Pipe(duplex=True)
    job = (cfg, unit.fn, unit.args, _limits(), unit.stage, unit.label)
    sys.stdout.flush(), sys.stderr.flush()       # a forked copy must not write this process's buffers again
    proc = ctx.Process(target=_process_worker, args=(child, job), name="verimono-unit-worker",
                       kwargs={"leader": os.getpid(), "kernel": started_from_main_thread()})
    proc.start()
    child.close()
    start = time.monotonic()
    try:
        if not parent.poll(WORKER_START_TIMEOUT) or parent.recv_bytes() != b"ready":
            return unit_failure(unit, f"its forked worker process did not start within {WORKER_START_TIMEOUT:g} s")
        if not parent.poll(timeout):
            return unit_failure(unit, f"timed out after {timeout:g} s (worker stopped)", duration=time.monotonic() - start)
        return _decode_answer(unit, parent.recv_bytes())[0]
    except (EOFError, OSError):
        proc.join(timeout=5)
        code = proc.exitcode
        how = f"signal {-code}" if code is not None and code < 0 else f"exit status {code}"
        return unit_failure(unit, f"its worker process died ({how}) while running it", duration=time.monotonic() - start)
    finally:
        proc.join(timeout=5)
        if proc.is_alive():
            proc.kill()
            proc.join()
        parent.close()


#: seconds an executor address has to answer as a dask scheduler (connect, and answer who it is)
CONNECT_TIMEOUT = 30.0


def answers_as_dask(address: str, seconds: float = CONNECT_TIMEOUT) -> dict:
    """The identity a dask scheduler at ``address`` gives within ``seconds`` (connect, send
    ``{"op": "identity"}``, read the answer: every step bounded); :class:`BadExecutor` in one line when nothing
    answers there, or something that is not a dask scheduler (an HTTP server took the connection and the
    handshake, then never answered: ``distributed.Client`` waited on it past 120 s, silently).  Runs in a
    thread of its own, with its own event loop, so it works from inside a running loop (Jupyter) too."""
    import asyncio
    import threading

    async def probe() -> Any:
        from distributed.comm import connect

        comm = await asyncio.wait_for(connect(address, timeout=seconds), seconds)
        try:
            await asyncio.wait_for(comm.write({"op": "identity"}), seconds)
            return await asyncio.wait_for(comm.read(), seconds)
        finally:
            comm.abort()

    box: dict[str, Any] = {}

    def run() -> None:
        try:
            box["answer"] = asyncio.run(probe())
        except BaseException as exc:  # noqa: BLE001 - told below, in one line
            box["error"] = exc

    thread = threading.Thread(target=run, name="verimono-dask-probe", daemon=True)
    thread.start()
    thread.join(seconds * 3 + 5.0)      # each step is bounded by `seconds`; this only guards the guard
    answer, exc = box.get("answer"), box.get("error")
    if isinstance(answer, dict) and str(answer.get("type", "")).lower() == "scheduler":
        return answer
    if exc is None and "answer" not in box:
        why = f"no answer within {seconds:g} s"
    elif exc is not None:
        why = ("no answer within {:g} s".format(seconds) if isinstance(exc, (TimeoutError, asyncio.TimeoutError))
               else f"{type(exc).__name__}: {exc}")
    else:
        why = f"it answered {str(answer)[:80]!r}, not as a dask scheduler"
    raise BadExecutor(f"--executor {address}: no dask scheduler answers there ({why}; a scheduler is started with "
                      "`dask scheduler`, tcp://host:8786 by default)")


class DaskRunner:
    """The workers of a ``dask.distributed`` scheduler at ``address`` (or an existing ``Client``).

    At most as many units are in flight as the cluster has worker threads, so a unit's ``timeout`` counts
    from when it could start; a unit still unfinished then is cancelled and reported."""

    def __init__(self, address: Any, timeout: float | None = None, *,
                 connect_timeout: float | None = None) -> None:
        connect_timeout = CONNECT_TIMEOUT if connect_timeout is None else float(connect_timeout)
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
            answers_as_dask(address, connect_timeout)
            try:
                self.client, self._own = Client(address, timeout=f"{connect_timeout:g}s"), True
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
        cfg = config_for(profile)
        here: list[int] = []                                        # units that cannot be pickled
        why: list[str] = []
        progress(0, len(units), "")
        try:
            while pending or flying:
                slots = self._slots()
                while pending and len(flying) < slots:
                    i = pending.popleft()
                    try:
                        payload = _ship(units[i], cfg)
                    except Exception as exc:  # noqa: BLE001 - it cannot travel: run here, after the others
                        here.append(i)
                        why.append(f"{type(exc).__name__}: {exc}")
                        continue
                    fut = self.client.submit(run_payload, payload, pure=False,
                                             key=f"verimono-unit-{i}-{os.urandom(4).hex()}")
                    flying[fut] = (i, time.monotonic())
                    progress(done, len(units), units[i].label)
                if not flying:
                    break
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
            for i in unpicklable(units, here, why, forked=False):     # the cluster's workers are elsewhere
                results[i] = run_here(units[i], cfg)
                done += 1
                progress(done, len(units), units[i].label)
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


__all__ = ["Unit", "UNIT_CHECK", "AUTO_MAX_WORKERS", "CONNECT_TIMEOUT", "answers_as_dask", "ship_by_value", "BadExecutor", "SerialRunner", "ProcessRunner", "DaskRunner", "make_runner",
           "unit_failure", "unit_record", "unit_raised", "raised", "run_payload", "run_here", "run_forked"]
