"""Issue 15, targets 1 and 2: Section 7 systems at compiled-solver speed — DiodeBridge, EulerMoreauOSI(θ = 1/2),
h = 1e-6, against the floor of a Python step loop (:func:`verimono.run.performance.floor_loop`: one 2×2
matrix–vector product per step), both measured in the same run.

* one trajectory of 5000 steps (also in the un-timed run: the one-off cost of building the maps of the
  patterns met, ~2 ms, paid by a system's first run, would dominate fewer steps): ``simulate`` per step
  within ``LCS_TARGET`` (2x) the
  floor per step, its trajectory within ``LCS_AGREEMENT`` of the step-by-step verified solver;
* a batch of B = 1000 trajectories: per trajectory-step at most ``LCS_BATCH_TARGET`` (0.25x) the floor per
  step with the NumPy batch kernel, ``LCS_BATCH_TARGET_COMPILED`` (0.05x) with the compiled one (numba, used
  when installed: ``pip install verimono[fast]``; the record's ``details["kernel"]`` says which ran) (Siconos'
  C ``lcp_lexicolemke`` takes 0.23 µs per step where the floor takes about 1 µs), rows bit-identical to their
  single runs.
"""

from __future__ import annotations

import pytest

pytest.importorskip("verimono.lcs", reason="verimono.lcs (Section 7 systems) is not available")

from verimono.run.performance import check_lcs_batch, check_lcs_step  # noqa: E402


def test_diode_bridge_simulate_vs_floor_loop(gate):
    gate.check(check_lcs_step(steps=5000, rounds=gate.rounds(5, 3), runner=gate.runner))


def test_diode_bridge_batch_vs_floor_loop(gate):
    gate.check(check_lcs_batch(batch=1000, steps=gate.size(5000, 200), rounds=gate.rounds(7, 2), runner=gate.runner))
