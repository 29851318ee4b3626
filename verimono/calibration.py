"""The calibration workload: seconds of a fixed NumPy-and-Python loop like the harness's own work.

Stage durations and time budgets divided by this number are comparable between jobs on different
machines: the gate compares such ratios, measured in the same job, never absolute seconds.  The time
budgets of :mod:`verimono.timeouts` are stated in its units: :func:`calibration` is this process's value
(measured once and cached; ``verimono run`` supplies the one it measures at its start through
:func:`set_calibration`), so a slower or busier machine — where the workload, like everything else, takes
longer — gets proportionally more seconds.  :func:`verimono.timing.calibrate_both` times the same workload
on the own-time clock too.
"""

from __future__ import annotations

import math
import time

import numpy as np


def workload() -> None:
    """The calibration workload itself: 20 000 small NumPy steps in a Python loop and one 60 x 60 solve."""
    x, lo, hi = np.array([0.3, -0.2, 0.9]), -np.ones(3) * 0.5, np.ones(3) * 0.5
    for k in range(20000):
        x = np.clip(x - 1e-3 * np.sin(k * 1e-3) * x, lo, hi)
    np.linalg.solve(np.eye(60) * 4.0 + np.ones((60, 60)), np.ones(60))


def calibrate(repeats: int = 3) -> float:
    """Seconds of a fixed NumPy-and-Python workload like the harness's (best of ``repeats``, wall clock;
    about 0.06-0.08 s each on a 2-core EPYC).

    Stage durations divided by this number are comparable between jobs on different machines: the gate
    compares these ratios, measured in the same job, never absolute seconds.
    """
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        workload()
        best = min(best, time.perf_counter() - start)
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


__all__ = ["calibrate", "calibration", "set_calibration", "workload"]
