"""Stages at once on the shared queue: whether they may overlap (:func:`_can_share`), and the stages of a group each
in a thread of its own, their units in one :class:`verimono.execution.schedule.SharedQueue` over the workers,
stopped and joined when the run is interrupted (:mod:`.stopper`) (:func:`_run_together`)."""

from __future__ import annotations

import ctypes
import threading
import time
from threading import get_ident as _get_ident   # (a test replaces this module's `threading` by a shim)
from typing import Callable

from ...execution.executors import ProcessRunner
from ...execution.profiles import Profile
from ...execution.schedule import SharedQueue
from ...records.results import Report
from .context import RunContext
from .current import _HERE
from .one_stage import _run_stage, _stage_failure
from .stopper import _SET_ASYNC_EXC, _Stopper, _join_all
from .table import STAGES, Stage


def _can_share(context: RunContext) -> bool:
    """Whether stages may overlap: ``schedule == "shared"`` on a pool of 2 or more worker processes."""
    return (context.schedule == "shared" and isinstance(context.executor, ProcessRunner)
            and context.executor.workers >= 2)


def _run_together(group: list[str], first: int, count: int, profile: Profile, context: RunContext,
                  on_start: Callable[[Stage, int, int], None] | None, finish: Callable[[str, Report, dict], None]
                  ) -> None:
    """The stages ``group`` at once, each in a thread of its own (taking turns in this process: the queue's
    ``turn``), their units in one :class:`SharedQueue` served from this thread; ``finish`` in ``group``'s order,
    each stage as soon as it and those before it have ended."""
    queue = SharedQueue(context.executor, first=[d for n in group for d in STAGES[n].after if d in group])
    outer, context.executor = context.executor, queue
    slots: dict[str, tuple[Report, dict] | None] = {n: None for n in group}
    ended = {n: threading.Event() for n in group}

    stopper = _Stopper()

    def body(n: str) -> None:
        me = ctypes.c_ulong(_get_ident())
        try:
            stopper.enter()
            try:
                for dep in STAGES[n].after:
                    if dep in ended:
                        ended[dep].wait()
                with queue.turn:
                    _HERE.stage = n
                    slots[n] = _run_stage(n, profile, context, overlapped=[m for m in group if m != n])
            except BaseException as exc:  # noqa: BLE001 - the queue closed under it (an interrupt): the run ends
                with queue.turn:          # a stage's code in this process runs holding the turn, even this (fork_guard)
                    slots[n] = _stage_failure(n, exc, 0.0)[0], {"name": n, "status": "error", "records": 1,
                                                                 "duration": 0.0, "cpu": 0.0, "message": str(exc)}
            finally:
                ended[n].set()
                queue._wake()
        except BaseException:  # noqa: BLE001 - a stop (:class:`_Stopper`) delivered late: the run is ending anyway
            pass
        finally:
            # inline, no Python call: a call's first bytecode would deliver a pending stop here, outside every catch
            with stopper.lock:
                _SET_ASYNC_EXC(me, None)      # NULL: a stop sent and not yet delivered is cleared
                stopper.running.discard(me.value)

    # not daemons, and joined below even when serving raises: a daemon thread alive at the interpreter's exit that
    # re-enters a C++ extension releasing the GIL (pybind11's: HiGHS, ProxQP) is ended by pthread_exit, whose
    # unwinding aborts the process ("terminate called without an active exception", status 134; docs/speed.md)
    threads = [threading.Thread(target=body, args=(n,), name=f"verimono-stage-{n}") for n in group]
    released = [0]

    def release() -> None:
        while released[0] < len(group) and ended[group[released[0]]].is_set():
            n = group[released[0]]
            released[0] += 1
            finish(n, *slots[n])

    for k, n in enumerate(group):
        if on_start:
            on_start(STAGES[n], first + k, count)
    start = time.perf_counter()
    raising = False
    try:
        for t in threads:
            t.start()
        queue.serve(threads, on_idle=release)
    except BaseException as exc:
        raising = True
        queue._break(exc)          # (serve did already, unless a thread failed to start) every waiting stage released
        stopper.stop()             # a stage's own code in this process stops at its next bytecode, not its next unit
        raise
    finally:
        try:
            _join_all([t for t in threads if t.ident is not None], stopper, raising=raising)
        finally:
            context.executor = outer
    wall = time.perf_counter() - start
    for n in group:      # the group's wall, what the gate compares (a stage's own is the span it shared)
        if slots[n] is not None:
            slots[n][1]["group_duration"] = wall
    release()
