"""Issue 43 (branch units10): a law's fixed costs made cheaper give the same numbers — ``searched``'s time
resolution (the largest gap between the times searched, clipped to ``[0, horizon]``) without ``np.r_``,
the list's own ``np.clip`` and ``np.unique``: equal to that formula bit for bit on times with repeats, signed
zeros, NaN, times outside the horizon and a zero horizon.  Seen failing with the clip left out."""

from __future__ import annotations

import numpy as np

from verimono.checks.engine.coordinates import searched


def _formula(ts, horizon):
    tt = np.unique(np.r_[0.0, np.clip(ts, 0.0, horizon), horizon])
    return float(np.max(np.diff(tt))) if tt.size > 1 else float(horizon)


def test_time_resolution_is_the_unique_formulas():
    rng = np.random.default_rng(0)
    for h in (1.0, 0.0, 2.5, 1e-300):
        for k in range(120):
            m = int(rng.integers(1, 40))
            if k % 2:
                ts = rng.choice([0.0, -0.0, h, h / 2, 1e-98, 2.0 ** -24, -1.0, 3.0, np.nan], m).tolist()
            else:
                ts = (rng.uniform(-0.5, 1.5, m) * h).tolist()
            if k % 7 == 0:
                ts = [ts[0]] * m
            got = searched([1.0, 2.0], [0.5, 1.0], ts, h, [])
            assert np.float64(got["t_resolution"]).tobytes() == np.float64(_formula(ts, h)).tobytes(), (h, ts)
            assert got["samples"] == m
