"""Issue 6, target 1: per-step overhead of ``verimono.solve`` on closed-form resolvents.

``solve`` on t|x| (``c(t) = t``), a box and a ball (``NormalCone``), ``n = 1, 3, 10``, 10^5 steps, within
``PER_STEP_TARGET`` × a bare NumPy loop doing the same arithmetic (preallocated output, steps as
Python floats, the same operations in the same order — hence the same bits, which is asserted).  The
cases and loops are :mod:`verimono.run.performance`'s.
"""

from __future__ import annotations

import pytest

from verimono.run.performance import PER_STEP_DIMS, PER_STEP_KINDS, check_per_step


@pytest.mark.parametrize("n", PER_STEP_DIMS)
@pytest.mark.parametrize("kind", PER_STEP_KINDS)
def test_per_step_overhead_vs_bare_numpy_loop(gate, kind, n):
    gate.check(check_per_step(kind, n, steps=gate.size(100_000, 20_000), rounds=gate.rounds(5, 3),
                              runner=gate.runner))
