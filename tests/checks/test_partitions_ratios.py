"""Strongly non-uniform partitions (:func:`verimono.checks.partitions.ratio_grids`): neighbours' cell ratios over
``[10^-3, 10^3]``, random and graded, judged by every per-partition stepper law and stated in its record.  A stepper
that leaves the paper's scheme only where a cell is shorter than a quarter of the one before (blind set 8,
``merges_short_cells``: the short cell merged with the next, its node interpolated) is the paper's scheme on every
other partition the battery builds (ratios within ``[0.29, 3.5]``); it fails ``selections`` here, its twin (the same
code with the merge never taken) passes."""

from __future__ import annotations

import numpy as np
import pytest

from verimono.checks.partitions import (CELL_RATIOS, cell_ratio_range, default_grids, every_battery_grid,
                                        ratio_grids)
from verimono.checks.trajectory_laws import check_contraction, check_selections
from verimono.reference import get


def _merging(ratio: float):
    """The paper's scheme, except a cell shorter than ``ratio`` times the previous one is stepped over together
    with the next (``x_{k+1} = J_{H F(t_{k+1})}(x_{k-1} + H f(x_{k-1}) + ∫u)``, ``H = h_k + h_{k+1}``, ``x_k``
    interpolated); ``ratio = 0``: never (the scheme itself)."""
    def stepper(problem, t_grid):
        t = np.asarray(t_grid, dtype=float)
        dU = problem.input_increments(t)
        x = [None] * len(t)
        x[0] = np.array(problem.x0, dtype=float)

        def z(xk, h, k, m=1):
            out = xk + (h * np.asarray(problem.f(xk), dtype=float) if problem.f is not None else 0.0)
            return out if dU is None else out + dU[k - 1:k - 1 + m].sum(axis=0)
        k, K = 1, len(t) - 1
        while k <= K:
            h = t[k] - t[k - 1]
            if 2 <= k < K and h < ratio * (t[k - 1] - t[k - 2]):
                H = t[k + 1] - t[k - 1]
                x[k + 1] = np.asarray(problem.operator.resolvent(z(x[k - 1], H, k, 2), H, t[k + 1]), dtype=float)
                x[k] = x[k - 1] + (h / H) * (x[k + 1] - x[k - 1])
                k += 2
                continue
            x[k] = np.asarray(problem.operator.resolvent(z(x[k - 1], h, k), h, t[k]), dtype=float)
            k += 1
        return np.array(x)
    stepper.__name__ = f"merges_cells_below_{ratio:g}"
    return stepper


def test_ratio_grids_span_the_stated_ratios_and_are_seeded_partitions():
    for T in (1.0, 2.476):
        grids = ratio_grids(T, 0)
        assert set(grids) == {"ratios random", "ratios graded"}
        for g in grids.values():
            h = np.diff(g)
            assert g[0] == 0.0 and g[-1] == T and np.all(h > 0) and h.max() <= 0.1 * T     # mesh: the K = 10 grid's
        lo, hi = cell_ratio_range(grids)
        assert lo == pytest.approx(CELL_RATIOS[0], rel=1e-9) and hi == pytest.approx(CELL_RATIOS[1], rel=1e-9)
        assert not np.array_equal(ratio_grids(T, 1)["ratios random"], grids["ratios random"])
    p = get("t|x| (n=1)")
    assert {"ratios random", "ratios graded"} <= set(every_battery_grid(p, 0))
    lo, hi = cell_ratio_range(default_grids(p, 0))
    assert 0.25 < lo and hi < 4.0      # the battery's other partitions: a cell never below a quarter of the last


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_stepper_merging_short_cells_fails_selections_on_the_ratio_grids_only(seed):
    p = get("moving half-space")
    bad = check_selections(_merging(0.25), p, seed=seed)
    assert bad.status == "failed" and bad.counterexample["grid_kind"].startswith("ratios"), str(bad)
    assert bad.details["cell_ratios"][0] < 0.25
    good = check_selections(_merging(0.0), p, seed=seed)
    assert good.status == "passed", str(good)
    assert good.details["cell_ratios"] == pytest.approx(list(CELL_RATIOS), rel=1e-9)
    others = {k: g for k, g in every_battery_grid(p, seed).items() if not k.startswith("ratios")}
    assert check_selections(_merging(0.25), p, grids=others, seed=seed).status == "passed"   # missed without them


def test_the_default_grid_laws_state_the_ratios_they_were_judged_on():
    rec = check_contraction(_merging(0.0), get("linear x' = -Mx"), seed=0)
    assert rec.status == "passed" and rec.details["cell_ratios"] == pytest.approx(list(CELL_RATIOS), rel=1e-9)
    assert {"ratios random", "ratios graded"} <= set(rec.details["worst_by_grid"])
