"""The calibration workload: seconds of a fixed NumPy-and-Python loop like the harness's own work.

Stage durations and time budgets divided by this number are comparable between jobs on different
machines: the gate compares such ratios, measured in the same job, never absolute seconds.
"""

from __future__ import annotations

import time

import numpy as np


def calibrate(repeats: int = 3) -> float:
    """Seconds of a fixed NumPy-and-Python workload like the harness's (best of ``repeats``).

    Stage durations divided by this number are comparable between jobs on different machines: the gate
    compares these ratios, measured in the same job, never absolute seconds.
    """
    best = float("inf")
    for _ in range(repeats):
        x, lo, hi = np.array([0.3, -0.2, 0.9]), -np.ones(3) * 0.5, np.ones(3) * 0.5
        start = time.perf_counter()
        for k in range(20000):
            x = np.clip(x - 1e-3 * np.sin(k * 1e-3) * x, lo, hi)
        np.linalg.solve(np.eye(60) * 4.0 + np.ones((60, 60)), np.ones(60))
        best = min(best, time.perf_counter() - start)
    return best


__all__ = ["calibrate"]
