"""``find_jumps(values=...)``: the grid's values in one call (branch perf10: the assumption laws hand it an operator's
block over the 129 grid times) give the jump search exactly what the calls per time give — the same jumps, brackets,
increments and what was searched."""

import numpy as np

from verimono.checks.jumps import find_jumps


def _value(t: float) -> np.ndarray:
    """A ramp with a jump of 0.3 at t = 0.61803 and a kink at 1.2, in R^2."""
    return np.array([0.5 * t + (0.3 if t >= 0.61803 else 0.0), abs(t - 1.2)])


def test_the_grid_in_one_call_is_the_calls_per_time():
    calls = []

    def grid(times: np.ndarray) -> np.ndarray:
        calls.append(len(times))
        return np.array([_value(float(t)) for t in times])

    want = find_jumps(_value, 2.0)
    got = find_jumps(_value, 2.0, values=grid)
    assert calls == [129]
    assert repr(got) == repr(want) and len(want[0]) == 1 and abs(want[0][0].time - 0.61803) < 1e-9
