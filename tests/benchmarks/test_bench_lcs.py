"""Issue 6, target 3: Section 7 systems — DiodeBridge, 5000 steps of EulerMoreauOSI(θ = 1/2).

``LinearRelationSystem.simulate`` against :func:`verimono.performance.minimal_lcs`, a minimal script
calling the same one-step solver with everything precomputed: the step matrices (``W = I − hθA`` factored
once, ``E``, ``G``, ``M``) built outside the timing, the relation's warm-started stepper (its pivoting
pattern and factorisations reused across steps), no validation, the same outputs ``x``, ``z``, ``w``.
Target ``LCS_TARGET``; the results must agree bit for bit.
"""

from __future__ import annotations

import pytest

pytest.importorskip("verimono.lcs", reason="verimono.lcs (Section 7 systems) is not available")

from verimono.performance import check_lcs_step  # noqa: E402


def test_diode_bridge_simulate_vs_minimal_script(gate):
    gate.check(check_lcs_step(steps=gate.size(5000, 1000), rounds=gate.rounds(5, 3), runner=gate.runner))
