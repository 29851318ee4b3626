"""Speed of the per-step loop of verimono.solve (recorded by pytest-benchmark, not asserted on time)."""

from __future__ import annotations

import verimono as vm
from verimono.reference import subdifferential


def test_solve_t_norm_1e5_steps(benchmark):
    p = subdifferential.t_norm((1.0,), T=2.0)
    grid = vm.uniform_grid(p.T, steps=100_000)
    tr = benchmark.pedantic(vm.solve, args=(p, grid), rounds=3, iterations=1)
    assert tr.x.shape == (100_001, 1) and tr.x[-1, 0] == 0.0  # extinct before T
