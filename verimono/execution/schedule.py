"""One queue of units over a :class:`~verimono.execution.executors.ProcessRunner`'s workers, shared by several
stages running at once (:func:`verimono.run.stages.run_stages` runs the untimed stages so).

Run one after another, each stage's units spread over the workers, a stage ends when its longest unit ends and
a worker idles at every stage's tail (the assumptions stage's wall was its one 5.5 s unit while the other worker
ran out of units).  Here each stage runs in a thread of its own, and every unit it asks for
(:meth:`SharedQueue.map`, what :meth:`verimono.run.stages.RunContext.run_units` calls) joins one queue; this
process's main thread (:meth:`SharedQueue.serve`) hands the queued units to idle workers, the longest
expected first (``costs``: an estimate per unit, which only orders the queue — a wrong one costs speed,
never a record), and gives each stage thread its reports back in its units' order.  A unit's records do not
depend on where or when it ran (:mod:`verimono.execution.executors`), so neither does the run's report.

The stage threads take turns in this process (:attr:`SharedQueue.turn`: a stage's own code runs holding it
and waits for its units without it): the stages' code in this process — drawing operators through
hypothesis, building the catalog, merging reports — never runs two at a time, as in a run of one stage after
another; only their units, in the workers, overlap.

A worker that dies, a unit past the timeout, a unit that cannot be pickled and a unit answered for after a
native hang are handled as :meth:`ProcessRunner.map` handles them (one failed record each, the other units'
records kept).

**Processes started while the stage threads live** (a worker replacing one that died, timed out or answered for a
native hang; a worker forked for a unit that cannot be pickled) are started under :meth:`SharedQueue.fork_guard`:
the main thread takes the turn, so no stage's code runs in this process — every stage thread is parked, waiting
for the turn, for its units or for a stage it reads — and forks only if, besides those parked stage threads, the
process has no thread it did not have when the stages started (no Python thread of anyone else's, no new native
thread: a HiGHS, XLA or OpenMP pool a stage's code started; those already there are the ones a run of one stage
after another forks its replacements beside) and none of
:data:`~verimono.execution.workers.FORK_UNSAFE` is imported.  A fork then copies no lock held by a running
thread (a module's import lock, a lock of a C library: a copy would wait on it forever and time out, a false
failed record).  Otherwise a replacement is spawned (a fresh interpreter: nothing of this process is copied;
0.55-0.9 s to ready on the 2-core machine against 0.01 s for a fork) and a unit that cannot be pickled runs in
this process, holding the turn, as :func:`~verimono.execution.executors.run_here` runs it wherever forking is not
safe.  OpenBLAS's own threads, there before the workers were forked, are stopped around a fork by OpenBLAS
(``pthread_atfork``).
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
import time
from multiprocessing.connection import wait as _wait
from typing import Any, Callable, Iterator, Sequence

from ..records.report.plots import PLOTS_THREAD, WARM_UP_THREAD
from ..records.results import Report
from .executors import run_forked, run_here, unpicklable
from .units import Unit, config_for, unit_failure
from .workers import FORK_UNSAFE, _decode_answer, _ship

#: seconds the queue waits, with a worker idle, for the stages that have not yet asked for their units, so
#: that the longest of them goes first (a stage's code builds its units in milliseconds)
GATHER_SECONDS = 0.05
#: seconds :meth:`SharedQueue.fork_guard` waits for a stage thread that has just ended to be gone before it forks
EXIT_WAIT = 0.05
#: verimono's own background threads of this process, which end by themselves (matplotlib's import, ~0.5 s; the
#: plots of a finished stage, when no drawer process was forked: the Python API): :meth:`SharedQueue.fork_guard`
#: waits for them, up to this many seconds in all, and forks, rather than spawning a replacement (0.5-0.9 s, and
#: a user's script without ``if __name__ == "__main__":`` cannot spawn at all)
OWN_THREAD_WAIT = 5.0
OWN_THREADS = frozenset({WARM_UP_THREAD, PLOTS_THREAD})


class _Job:
    """One :meth:`SharedQueue.map` call: a stage's units, their reports as they come back."""

    def __init__(self, seq: int, units: Sequence[Unit], cfg: Any, progress: Callable, costs: list[float],
                 stage: str | None = None):
        self.seq, self.units, self.cfg, self.progress, self.costs = seq, list(units), cfg, progress, costs
        self.stage = stage
        self.results: list[Report | None] = [None] * len(self.units)
        self.pending = list(range(len(self.units)))
        self.here: list[int] = []          # units that cannot be pickled: run once the others are done
        self.why: list[str] = []
        #: each unit pickled when its stage asked for it (:meth:`SharedQueue._ship_now`), ``None`` until sent
        self.payloads: list[bytes | None] = [None] * len(self.units)
        self.done = 0
        self.finished = threading.Event()
        self.error: BaseException | None = None


class SharedQueue:
    """The workers of ``runner`` (a started :class:`~verimono.execution.executors.ProcessRunner`) as one queue for
    the stage threads of a run; ``map`` from those threads, :meth:`serve` from the main thread."""

    def __init__(self, runner: Any, first: Sequence[str] = ()) -> None:
        self.runner = runner
        #: stages whose units go before every other's: those another stage waits for (``Stage.after``)
        self.first = frozenset(first)
        self.spec, self.workers, self.timeout = runner.spec, runner.workers, runner.timeout
        self.turn = threading.Lock()           # the stages' code in this process: one at a time
        self._cond = threading.Lock()
        self._jobs: list[_Job] = []
        self._seq = 0
        self._waiting = 0                      # stage threads inside map(), waiting on their units
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_r, False)
        self._broken: BaseException | None = None
        #: ``(stage, label, worker pid, sent, answered)`` of every unit, ``time.monotonic()`` seconds of this
        #: process: what the run reports of each stage's span on the shared workers
        self.timeline: list[tuple[str | None, str, int | None, float, float]] = []
        #: the stage threads (:meth:`serve`'s), and this process's threads that are not Python's (OpenBLAS's) when
        #: the queue was made, before the stages start: what :meth:`fork_guard` allows besides the main thread
        self._stage_threads: frozenset[int] = frozenset()
        self._native0 = _native_threads()

    # -- the stage threads' side -------------------------------------------------------------------------

    def map(self, units: Sequence[Unit], profile: Any, progress: Callable[[int, int, str], None],
            costs: list[float] | None = None, stage: str | None = None) -> list[Report]:
        """The reports of ``units`` in their order, run on the shared workers (longest ``costs`` first; those
        of a ``stage`` in :attr:`first` before any other); called from a stage thread holding :attr:`turn`,
        which it gives up while it waits."""
        if not units:
            progress(0, 0, "")
            return []
        held = self.turn.locked()
        job = _Job(-1, units, config_for(profile), progress,
                   list(costs) if costs is not None else [0.0] * len(units), stage)
        if held:
            self._ship_now(job)
        with self._cond:
            if self._broken is not None:
                raise RuntimeError("the run's shared queue is closed") from self._broken
            job.seq = self._seq
            self._seq += 1
            self._jobs.append(job)
            self._waiting += 1
        self._wake()
        if held:
            self.turn.release()
        try:
            job.finished.wait()
        finally:
            with self._cond:
                self._waiting -= 1
            if held:
                self.turn.acquire()
        if job.error is not None:
            raise RuntimeError("the run's shared queue is closed") from job.error
        return [r for r in job.results]  # type: ignore[misc]

    def _ship_now(self, job: _Job) -> None:
        """Pickle ``job``'s units now, in the stage's thread holding the turn, as one stage after another pickles
        them with nothing else running: pickled later by the main thread, a unit's arguments were walked while
        another stage's code changed what they share (the catalog's problems, a registry): "dictionary changed
        size during iteration" three times over (the unit then ran outside the workers), or worse, a state of
        them no run of one stage after another sends.  A unit that cannot be pickled runs where nothing is."""
        for i, u in enumerate(job.units):
            try:
                job.payloads[i] = _ship(u, job.cfg)
            except Exception as exc:  # noqa: BLE001 - it cannot travel: run where nothing is pickled
                job.here.append(i)
                job.why.append(f"{type(exc).__name__}: {exc}")
        job.pending = [i for i in job.pending if i not in job.here]

    def close(self) -> None:
        pass              # the workers are the runner's; execute() closes it

    @contextlib.contextmanager
    def fork_guard(self) -> Iterator[bool]:
        """Hold the turn (no stage's code runs in this process meanwhile) and say whether a fork of this process
        is safe now: called from the main thread, every other thread a parked stage thread, no native thread
        started since the workers were forked, Linux, none of ``FORK_UNSAFE`` imported and
        ``$VERIMONO_START_METHOD`` not ``spawn`` (see the module docstring).  ``False``: spawn instead, or run
        here (still holding the turn)."""
        with self.turn:
            yield self._fork_safe()

    def _fork_safe(self) -> bool:
        if os.environ.get("VERIMONO_START_METHOD", "").strip().lower() == "spawn":
            return False
        if not sys.platform.startswith("linux") or any(name in sys.modules for name in FORK_UNSAFE):
            return False
        main = threading.main_thread()
        if threading.current_thread() is not main:
            return False
        wait_until = time.monotonic() + OWN_THREAD_WAIT
        for t in threading.enumerate():
            if t.name in OWN_THREADS and t is not main and t.ident not in self._stage_threads:
                t.join(max(0.0, wait_until - time.monotonic()))
        if any(t is not main and t.ident not in self._stage_threads for t in threading.enumerate()):
            return False
        deadline = time.monotonic() + EXIT_WAIT
        while True:
            native = _native_threads()
            if native is None or self._native0 is None:
                return False
            if native <= self._native0:
                return True
            # a stage thread that has just ended may still be leaving (its C thread-local destructors): wait
            # briefly for it to be gone; a thread still there then is one this process did not have: no fork
            if time.monotonic() > deadline:
                return False
            time.sleep(0.002)

    def _wake(self) -> None:
        with self._cond:                  # never a write to a closed descriptor's number, reused since
            if self._wake_w < 0:
                return
            try:
                os.write(self._wake_w, b"x")
            except OSError:
                pass

    # -- the main thread's side --------------------------------------------------------------------------

    def serve(self, threads: list[threading.Thread], on_idle: Callable[[], None] = lambda: None) -> None:
        """Hand the queued units to the workers until every thread of ``threads`` (the stages) has ended;
        ``on_idle()`` between events (the run releases finished stages there, in their order)."""
        runner = self.runner
        self._stage_threads = frozenset(t.ident for t in threads if t.ident is not None)
        busy: dict[Any, tuple[Any, _Job, int, float]] = {}      # conn -> (worker, job, unit index, start)
        idle = list(runner._pool)
        idle_since: float | None = None
        try:
            while True:
                with self._cond:
                    alive = sum(t.is_alive() for t in threads)
                    jobs = [j for j in self._jobs if not j.finished.is_set()]
                    everyone_asked = self._waiting >= alive
                queued = [(j, i) for j in jobs for i in j.pending]
                if idle and queued:
                    idle_since = idle_since if idle_since is not None else time.monotonic()
                    if everyone_asked or busy or time.monotonic() - idle_since >= GATHER_SECONDS:
                        self._assign(idle, busy, queued)
                        idle_since = None
                for j in jobs:                   # only units that cannot be pickled left: here, as map() does
                    if j.here and not j.pending and not any(b[1] is j for b in busy.values()):
                        self._run_here(j)
                self._complete(jobs)
                on_idle()
                if not busy and alive == 0 and not any(not j.finished.is_set() for j in self._jobs):
                    break
                wait_for = 0.5
                if idle and queued and not busy:
                    wait_for = GATHER_SECONDS
                if self.timeout is not None and busy:
                    now = time.monotonic()
                    wait_for = max(0.0, min([wait_for] + [s + self.timeout - now for *_, s in busy.values()]))
                ready = _wait(list(busy) + [self._wake_r], timeout=wait_for)
                for conn in ready:
                    if conn == self._wake_r:
                        try:
                            while os.read(self._wake_r, 4096):
                                pass
                        except (BlockingIOError, OSError):
                            pass
                        continue
                    worker, job, i, start = busy.pop(conn)
                    idle.append(self._answer(worker, conn, job, i, start))
                if self.timeout is not None:
                    now = time.monotonic()
                    for conn, (worker, job, i, start) in list(busy.items()):
                        if now - start > self.timeout:
                            busy.pop(conn)
                            runner._stop(worker, kill=True)
                            self._give(job, i, unit_failure(job.units[i], f"timed out after {self.timeout:g} s "
                                                            "(worker stopped)", duration=now - start), worker[0], start)
                            idle.append(self._replace(worker))
        except BaseException as exc:
            self._break(exc)
            raise
        finally:
            with self._cond:
                for fd in (self._wake_r, self._wake_w):
                    try:
                        os.close(fd)
                    except OSError:
                        pass
                self._wake_r = self._wake_w = -1

    def _assign(self, idle: list, busy: dict, queued: list[tuple[_Job, int]]) -> None:
        # a stage others wait for first; then the longest expected first; ties in the order the stages asked
        # and their units are listed
        queued.sort(key=lambda ji: (ji[0].stage not in self.first, -ji[0].costs[ji[1]], ji[0].seq, ji[1]))
        for job, i in queued:
            if not idle:
                break
            job.pending.remove(i)
            payload, job.payloads[i] = job.payloads[i], None
            if payload is None:          # asked from a thread without the turn: pickled here, as before
                try:
                    payload = _ship(job.units[i], job.cfg)
                except Exception as exc:  # noqa: BLE001 - it cannot travel: run where nothing is pickled
                    job.here.append(i)
                    job.why.append(f"{type(exc).__name__}: {exc}")
                    continue
            worker = idle.pop()
            worker[1].send_bytes(payload)
            busy[worker[1]] = (worker, job, i, time.monotonic())
            self._progress(job, job.units[i].label)

    def _progress(self, job: _Job, label: str) -> None:
        """``progress`` over every stage's units queued so far (the stages share one progress line)."""
        jobs = list(self._jobs)
        job.progress(sum(j.done for j in jobs), sum(len(j.units) for j in jobs),
                     f"{job.units[0].stage}: {label}" if label else "")

    def _answer(self, worker: Any, conn: Any, job: _Job, i: int, start: float) -> Any:
        runner, proc = self.runner, worker[0]
        try:
            answer = conn.recv_bytes()
        except (EOFError, OSError):
            worker[0].join(timeout=5)
            code = worker[0].exitcode
            how = f"signal {-code}" if code is not None and code < 0 else f"exit status {code}"
            rep = unit_failure(job.units[i], f"its worker process died ({how}) while running it",
                               duration=time.monotonic() - start)
            runner._stop(worker, kill=True)
            worker = self._replace(worker)
        else:
            rep, ended = _decode_answer(job.units[i], answer)
            if ended:          # it answered for a unit blocked in native code, and exits
                runner._stop(worker, kill=False)
                worker = self._replace(worker)
            elif runner.on_report is not None:
                try:
                    runner.on_report(rep)
                except Exception:  # noqa: BLE001 - a plot asked ahead is drawn by the report instead
                    pass
        self._give(job, i, rep, proc, start)
        return worker

    def _replace(self, worker: Any) -> Any:
        """A new worker in ``worker``'s place: forked under :meth:`fork_guard` where that is safe, else spawned."""
        runner = self.runner
        runner._pool.remove(worker)
        with self.fork_guard() as fork:
            (new,) = runner._start(method="fork" if fork else "spawn")
        runner._pool.append(new)
        return new

    def _give(self, job: _Job, i: int, rep: Report, worker: Any = None, start: float | None = None) -> None:
        now = time.monotonic()
        self.timeline.append((job.stage, job.units[i].label, getattr(worker, "pid", None) if worker else None,
                              now if start is None else start, now))
        job.results[i] = rep
        job.done += 1
        self._progress(job, job.units[i].label)

    def _run_here(self, job: _Job) -> None:
        """``job``'s units that cannot be pickled: each in a worker forked for it under :meth:`fork_guard` where
        that is safe, else in this process holding the turn (no stage's code runs meanwhile)."""
        with self.fork_guard() as fork:
            for i in unpicklable(job.units, job.here, job.why, forked=fork):
                unit = job.units[i]
                self._give(job, i, run_forked(unit, job.cfg, self.timeout) if fork else run_here(unit, job.cfg))
        job.here.clear()

    def _complete(self, jobs: list[_Job]) -> None:
        for j in jobs:
            if not j.finished.is_set() and j.done == len(j.units):
                self._progress(j, "")
                j.finished.set()

    def _break(self, exc: BaseException) -> None:
        """An interrupt (or an error of the queue itself): every stage thread waiting is released with it."""
        with self._cond:
            self._broken = exc
            for j in self._jobs:
                if not j.finished.is_set():
                    j.error = exc
                    j.finished.set()


def _native_threads() -> int | None:
    """Threads of this process that are not running Python threads (OpenBLAS's, a C library's pool, a Python thread
    still leaving after its end); ``None`` where ``/proc`` cannot tell."""
    try:
        tids = {int(t) for t in os.listdir("/proc/self/task")}
    except (OSError, ValueError):
        return None
    return len(tids - {t.native_id for t in threading.enumerate()})


__all__ = ["SharedQueue", "GATHER_SECONDS"]
