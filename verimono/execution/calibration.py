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

from .lifetime import die_with, quiet_signals


#: the steps of the calibration workload's loop
WORKLOAD_STEPS = 20000
#: the steps of a *slice* (:func:`slice_cpu`): a twentieth of the workload, 3-4 ms of CPU idle, 8 ms busy
SLICE_STEPS = 1000


def workload(steps: int = WORKLOAD_STEPS) -> None:
    """The calibration workload itself: 20 000 small NumPy steps in a Python loop and one 60 x 60 solve
    (``steps``: fewer steps, for a slice of it)."""
    x, lo, hi = np.array([0.3, -0.2, 0.9]), -np.ones(3) * 0.5, np.ones(3) * 0.5
    for k in range(steps):
        x = np.clip(x - 1e-3 * np.sin(k * 1e-3) * x, lo, hi)
    np.linalg.solve(np.eye(60) * 4.0 + np.ones((60, 60)), np.ones(60))


#: a slice is taken after each unit, and one more per SLICE_EVERY CPU seconds of it, at most MAX_SLICES:
#: 1.4% of a long unit's CPU time, 3-8 ms after a short one
SLICE_EVERY = 0.25
MAX_SLICES = 8


def slices_after(cpu_seconds: float) -> list[float]:
    """:func:`slice_cpu` samples to take after work of ``cpu_seconds``: one, and one more per
    :data:`SLICE_EVERY` seconds, at most :data:`MAX_SLICES`."""
    k = 1 + min(int(max(cpu_seconds, 0.0) / SLICE_EVERY), MAX_SLICES - 1)
    return [slice_cpu() for _ in range(k)]


def slice_cpu() -> float:
    """The CPU time of one slice of the workload, scaled to the whole (x WORKLOAD_STEPS / SLICE_STEPS): a
    sample of the calibration taken between a run's units, where and when they ran
    (:func:`verimono.run.stages.registry.timed_unit`).  Load on a shared machine changes within seconds, and
    with it what the code's CPU time is inflated by (a busy machine switches between more processes, each
    switch refilling caches: the workload's CPU time read 0.09-0.18 s within a minute here, 0.065 s idle), so a
    stage's CPU time is stated against samples taken beside its own work, not against one calibration
    before it."""
    c0 = time.thread_time()
    workload(SLICE_STEPS)
    return (time.thread_time() - c0) * (WORKLOAD_STEPS / SLICE_STEPS)


#: how close (relative) a repeat of :func:`calibrate` must come to ``agreeing_with`` to end the repeats early
AGREEMENT = 0.05


def calibrate_times(repeats: int = 3, *, agreeing_with: float | None = None,
                    agreeing_cpu: float | None = None) -> tuple[float, list[float]]:
    """``(best wall seconds, CPU seconds of every repeat)`` of :func:`workload`: :func:`calibrate`'s
    measurement, with the CPU time of the calling thread (:func:`time.thread_time`) of each repeat too.

    The CPU figure is what :mod:`verimono.run.gate` states stage times in: load on the other cores does not
    add to it (a wait for a CPU is not CPU time), while what load does to the code as it runs (caches,
    memory bandwidth, a slower clock: up to 2.5x here, the calibration's CPU time 0.17 s against 0.065 s
    idle beside other test runs) slows the workload and the stages alike.  ``agreeing_with``: as in
    :func:`calibrate`, on the wall figure; ``agreeing_cpu``: the same on the CPU figure (:func:`cpu_seconds`
    of the repeats so far within :data:`AGREEMENT` of it) — with both given, both must agree."""
    best, cpus = float("inf"), []
    for _ in range(repeats):
        c0, start = time.thread_time(), time.perf_counter()
        workload()
        best = min(best, time.perf_counter() - start)
        cpus.append(time.thread_time() - c0)
        agree = [abs(now / then - 1.0) <= AGREEMENT for now, then in ((best, agreeing_with),
                                                                       (cpu_seconds(cpus), agreeing_cpu))
                 if then is not None]
        if agree and all(agree):
            break
    return best, cpus


def cpu_seconds(cpus: list[float]) -> float:
    """The CPU figure of a calibration: the median of its repeats' CPU seconds.  Not their minimum, as the
    wall figure is: a stage's CPU time is a sum over all its work, slowed by whatever the load does to code
    as it runs (caches, memory bandwidth), so the calibration it is divided by is the workload's typical CPU
    time under the same load, not its luckiest."""
    xs = sorted(float(c) for c in cpus)
    if not xs:
        raise ValueError("a calibration has at least one repeat")
    mid = len(xs) // 2
    return xs[mid] if len(xs) % 2 else 0.5 * (xs[mid - 1] + xs[mid])


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
    return calibrate_times(repeats, agreeing_with=agreeing_with)[0]


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
    """:func:`calibrate_times` measured in a forked copy of this process while this one goes on — the command line
    starts it before its imports (about 0.4 s on one core, while the measurement takes the other) and takes
    :meth:`result` when its run begins.  Where a fork is not safe (not Linux, or another thread running: a
    lock held at the fork would stay held in the copy) or fails, :meth:`result` measures here instead."""

    def __init__(self, repeats: int = 3, then: Callable[[], None] | None = None) -> None:
        """``then``: what the copy does once it has answered (the command line's report drawer,
        :func:`verimono.records.report.drawer.serve`); the copy then lives on until :meth:`close`."""
        self.repeats = repeats
        self._value: tuple[float, list[float]] | None = None
        self._pid: int | None = None
        self._fd: int | None = None
        self._lives_on = then is not None
        if not (sys.platform.startswith("linux") and threading.active_count() == 1):
            return
        r, w = os.pipe()
        leader = os.getpid()
        try:
            pid = os.fork()
        except OSError:
            os.close(r), os.close(w)
            return
        if pid == 0:                                     # the copy: measure, answer, and end at once
            code = 1
            try:
                quiet_signals()                          # Ctrl-C is the leader's; SIGTERM/SIGHUP end it quietly
                die_with(leader)                         # and it ends with the leader, however that ends
                os.close(r)
                wall, cpus = calibrate_times(repeats)
                os.write(w, struct.pack(f"<{1 + repeats}d", wall, *cpus))
                os.close(w)
                if then is not None:
                    then()
                code = 0
            finally:
                os._exit(code)                           # no atexit handlers, no buffers flushed twice
        os.close(w)
        self._pid, self._fd = pid, r

    def _collect(self, kill: bool = False) -> tuple[float, list[float]] | None:
        if self._fd is None or self._pid is None:
            return None
        fd, pid, self._fd = self._fd, self._pid, None
        size = 8 * (1 + self.repeats)
        data = b""
        try:
            if kill:
                try:
                    os.kill(pid, 9)
                except ProcessLookupError:  # pragma: no cover - it had ended
                    pass
                return None
            while len(data) < size:
                chunk = os.read(fd, size - len(data))
                if not chunk:
                    break
                data += chunk
        finally:
            os.close(fd)
            if kill or not self._lives_on or len(data) != size:   # else it lives on: reaped by close()
                self._reap()
        if len(data) != size:
            return None
        wall, *cpus = struct.unpack(f"<{1 + self.repeats}d", data)
        ok = all(x > 0 and math.isfinite(x) for x in (wall, *cpus))
        return (wall, list(cpus)) if ok else None

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
        return self.times()[0]

    def times(self) -> tuple[float, list[float]]:
        """:func:`calibrate_times` of the copy (waiting for it to answer), or measured here if it could not:
        the best wall seconds and the CPU seconds of every repeat."""
        if self._value is None:
            measured = self._collect()
            self._value = measured if measured is not None else calibrate_times(self.repeats)
        return self._value

    def close(self) -> None:
        """End the copy if its answer was never taken (a command that stopped before its run); else wait
        for a copy that lived on (what ``then`` did ends when its caller lets it: the drawer when its
        connection closes)."""
        if self._fd is not None:
            self._collect(kill=True)
        self._reap()


__all__ = ["AGREEMENT", "PendingCalibration", "calibrate", "calibrate_times", "cpu_seconds", "slice_cpu", "slices_after", "SLICE_EVERY", "MAX_SLICES", "WORKLOAD_STEPS", "SLICE_STEPS", "calibration", "set_calibration", "workload"]
