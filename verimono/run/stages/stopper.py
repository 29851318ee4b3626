"""Stopping the stage threads of a run interrupted while stages run at once (the threads of
:func:`verimono.run.stages.together._run_together`):
:class:`_Stopper` raises ``KeyboardInterrupt`` in each where that is safe (``PyThreadState_SetAsyncExc``), and
:func:`_join_all` joins them however often Ctrl-C is pressed meanwhile."""

from __future__ import annotations

import ctypes
import math
import sys
import threading
import time
from threading import get_ident as _get_ident
from typing import Any

from ...execution.interrupts import safe_to_interrupt


#: ``PyThreadState_SetAsyncExc(thread id, exception or NULL)`` (:class:`_Stopper`)
_SET_ASYNC_EXC = ctypes.pythonapi.PyThreadState_SetAsyncExc


class _Stopper:
    """Stops the stage threads of :func:`.together._run_together` when the run is interrupted.

    Ctrl-C reaches the main thread only (serving the queue).  Closing the queue releases a stage thread waiting
    for its units, but one running its own code in this process (building units, drawing operators, merging
    reports; a user's stage, for as long as it likes) ran on until its next unit: the interrupted ``execute``
    waited for it (1-3 s of the built-in stages; forever for a stage that never asks for a unit), a second
    Ctrl-C then broke that wait, and the still-running thread used the run's closed worker pool again — it
    started new workers, and the user's script hung at its exit joining them (seen with two Ctrl-C's 0.3 s
    apart).  :meth:`stop` raises ``KeyboardInterrupt`` in each stage thread (what Ctrl-C does to a serial run's
    stage in the main thread) — but only while its stack is where an interrupt is safe
    (:func:`verimono.execution.interrupts.safe_to_interrupt`, and no import under way: one raised inside
    importlib's bookkeeping left the import lock held and every later import of the process waiting forever),
    looked at with thread switching held off, so the thread's next check of pending exceptions comes before it
    can enter such code; elsewhere it is tried again at the next call (:func:`_join_all` calls every 10 ms).
    A thread's end clears a stop not yet delivered, under the lock :meth:`stop` sends under (``body`` in
    :func:`.together._run_together`), so a stop never lands outside the thread's catch-all: no "Exception in thread"."""

    #: seconds after which a stop sent and not obeyed (a stage's code that caught it) is sent again
    AGAIN = 0.5

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.running: set[int] = set()
        self._stopping = False
        self._sent: dict[int, float] = {}

    def enter(self) -> None:
        with self.lock:
            self.running.add(_get_ident())
            if self._stopping:
                raise KeyboardInterrupt

    def stop(self) -> None:
        switch = sys.getswitchinterval()
        sys.setswitchinterval(1e3)        # no other thread runs between the look at its stack and the send
        try:
            with self.lock:
                self._stopping = True
                frames = sys._current_frames()
                now = time.monotonic()
                for ident in self.running:
                    if now - self._sent.get(ident, -math.inf) < self.AGAIN or not _stoppable(frames.get(ident)):
                        continue
                    _SET_ASYNC_EXC(ctypes.c_ulong(ident), ctypes.py_object(KeyboardInterrupt))
                    self._sent[ident] = now
        finally:
            sys.setswitchinterval(switch)


def _stoppable(frame: Any) -> bool:
    """Whether a stage thread whose innermost frame is ``frame`` may be interrupted now (:class:`_Stopper`)."""
    if frame is None:
        return False
    f = frame
    while f is not None:
        if (f.f_globals.get("__name__") or "").startswith("importlib"):
            return False
        f = f.f_back
    return safe_to_interrupt(frame)


def _join_all(threads: list[threading.Thread], stopper: _Stopper, raising: bool = False) -> None:
    """Join ``threads`` however often Ctrl-C is pressed meanwhile (each press stops them again): a stage thread
    left running would use the run's pool after it was closed.  The first such press is raised once they have
    ended, unless an exception (the first Ctrl-C) is already on its way (``raising``): that one is the user's."""
    interrupt: BaseException | None = None
    for t in threads:
        while True:
            try:
                t.join(0.01)
                if not t.is_alive():
                    break
                if stopper._stopping:
                    stopper.stop()        # those not yet stopped, where it is safe now
            except KeyboardInterrupt as exc:
                interrupt = interrupt or exc
                stopper.stop()
    if interrupt is not None and not raising:
        raise interrupt
