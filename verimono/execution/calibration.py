"""The calibration workload: seconds of a fixed NumPy-and-Python loop like the harness's own work.

Stage durations and time budgets divided by this number are comparable between jobs on different
machines: the gate compares such ratios, measured in the same job, never absolute seconds.  The time
budgets of :mod:`verimono.execution.timeouts` are stated in its units: :func:`calibration` is this process's value
(measured once and cached; ``verimono run`` supplies the one it measures at its start through
:func:`set_calibration`), so a slower or busier machine — where the workload, like everything else, takes
longer — gets proportionally more seconds.  :func:`verimono.execution.timing.calibrate_both` times the same workload
on the own-time clock too.
"""

from __future__ import annotations

import math
import os
import struct
import sys
import threading
import time
from typing import Callable

import numpy as np


def workload() -> None:
    """The calibration workload itself: 20 000 small NumPy steps in a Python loop and one 60 x 60 solve."""
    x, lo, hi = np.array([0.3, -0.2, 0.9]), -np.ones(3) * 0.5, np.ones(3) * 0.5
    for k in range(20000):
        x = np.clip(x - 1e-3 * np.sin(k * 1e-3) * x, lo, hi)
    np.linalg.solve(np.eye(60) * 4.0 + np.ones((60, 60)), np.ones(60))


#: how close (relative) a repeat of :func:`calibrate` must come to ``agreeing_with`` to end the repeats early
AGREEMENT = 0.05


def calibrate(repeats: int = 3, *, agreeing_with: float | None = None) -> float:
    """Seconds of a fixed NumPy-and-Python workload like the harness's (best of ``repeats``, wall clock;
    about 0.06-0.08 s each on a 2-core EPYC).

    Stage durations divided by this number are comparable between jobs on different machines: the gate
    compares these ratios, measured in the same job, never absolute seconds.

    ``agreeing_with``: a calibration of the same run, measured earlier; the repeats end at the first within
    :data:`AGREEMENT` of it.  The machine's speed has then not changed, which is what a second measurement
    is for (:mod:`verimono.run.gate` judges a run's stage times only while its calibrations agree within
    ``CALIBRATION_DRIFT``, 1.25x), and more repeats could only lower the minimum by the noise they would be
    repeated to remove; a repeat that disagrees is repeated as before.  (0.12 s of a 2-second ``verimono
    check`` on a quiet machine.)
    """
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        workload()
        best = min(best, time.perf_counter() - start)
        if agreeing_with is not None and abs(best / agreeing_with - 1.0) <= AGREEMENT:
            break
    return best


_CALIBRATION: list[float] = []


def calibration() -> float:
    """This process's calibration (seconds of :func:`calibrate`), measured once (best of 3, ~0.2 s) on the
    first call and cached; :func:`set_calibration` supplies one measured elsewhere in the process."""
    if not _CALIBRATION:
        _CALIBRATION.append(calibrate())
    return _CALIBRATION[0]


def set_calibration(seconds: float | None) -> None:
    """Use ``seconds`` as this process's calibration (``None``: forget it, measure again when needed)."""
    _CALIBRATION.clear()
    if seconds is not None:
        s = float(seconds)
        if not (s > 0 and math.isfinite(s)):
            raise ValueError(f"a calibration is a positive number of seconds, got {seconds!r}")
        _CALIBRATION.append(s)


class PendingCalibration:
    """:func:`calibrate` measured in a forked copy of this process while this one goes on — the command line
    starts it before its imports (about 0.4 s on one core, while the measurement takes the other) and takes
    :meth:`result` when its run begins.  Where a fork is not safe (not Linux, or another thread running: a
    lock held at the fork would stay held in the copy) or fails, :meth:`result` measures here instead."""

    def __init__(self, repeats: int = 3, then: Callable[[], None] | None = None) -> None:
        """``then``: what the copy does once it has answered (the command line's report drawer,
        :func:`verimono.records.report.drawer.serve`); the copy then lives on until :meth:`close`."""
        self.repeats = repeats
        self._value: float | None = None
        self._pid: int | None = None
        self._fd: int | None = None
        self._lives_on = then is not None
        if not (sys.platform.startswith("linux") and threading.active_count() == 1):
            return
        r, w = os.pipe()
        try:
            pid = os.fork()
        except OSError:
            os.close(r), os.close(w)
            return
        if pid == 0:                                     # the copy: measure, answer, and end at once
            code = 1
            try:
                os.close(r)
                os.write(w, struct.pack("<d", calibrate(repeats)))
                os.close(w)
                if then is not None:
                    then()
                code = 0
            finally:
                os._exit(code)                           # no atexit handlers, no buffers flushed twice
        os.close(w)
        self._pid, self._fd = pid, r

    def _collect(self, kill: bool = False) -> float | None:
        if self._fd is None or self._pid is None:
            return None
        fd, pid, self._fd = self._fd, self._pid, None
        data = b""
        try:
            if kill:
                try:
                    os.kill(pid, 9)
                except ProcessLookupError:  # pragma: no cover - it had ended
                    pass
                return None
            while len(data) < 8:
                chunk = os.read(fd, 8 - len(data))
                if not chunk:
                    break
                data += chunk
        finally:
            os.close(fd)
            if kill or not self._lives_on or len(data) != 8:   # else it lives on: reaped by close()
                self._reap()
        if len(data) != 8:
            return None
        value = struct.unpack("<d", data)[0]
        return value if value > 0 and math.isfinite(value) else None

    def _reap(self) -> None:
        pid, self._pid = self._pid, None
        if pid is not None:
            os.waitpid(pid, 0)

    @property
    def forked(self) -> bool:
        """Whether a copy was forked (else :meth:`result` measures here, and ``then`` never runs)."""
        return self._pid is not None

    def result(self) -> float:
        """The seconds measured (waiting for the copy to answer), or measured here if it could not."""
        if self._value is None:
            measured = self._collect()
            self._value = measured if measured is not None else calibrate(self.repeats)
        return self._value

    def close(self) -> None:
        """End the copy if its answer was never taken (a command that stopped before its run); else wait
        for a copy that lived on (what ``then`` did ends when its caller lets it: the drawer when its
        connection closes)."""
        if self._fd is not None:
            self._collect(kill=True)
        self._reap()


__all__ = ["AGREEMENT", "PendingCalibration", "calibrate", "calibration", "set_calibration", "workload"]
