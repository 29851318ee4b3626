"""Issue 6, target 3: Section 7 systems — DiodeBridge, 5000 steps of EulerMoreauOSI(θ = 1/2).

``LinearRelationSystem.simulate`` against a minimal script calling the same one-step solver with
everything precomputed: the step matrices (``W = I − hθA`` factored once, ``E``, ``G``, ``M``) built
outside the timing, the relation's warm-started stepper (its pivoting pattern and factorisations reused
across steps), no validation, the same outputs ``x``, ``z``, ``w``.  Target ≤ 1.5×; the results must agree
bit for bit.
"""

from __future__ import annotations

import numpy as np
import pytest

lcs = pytest.importorskip("verimono.lcs", reason="verimono.lcs (Section 7 systems) is not available")
if not hasattr(lcs, "LinearRelationSystem"):
    pytest.skip("verimono.lcs has no LinearRelationSystem yet", allow_module_level=True)

TARGET = 1.5
L, Cc, R = 1e-2, 1e-6, 1e3


def diode_bridge():
    A = [[0, -1 / Cc], [1 / L, 0]]
    B = [[0, 0, -1 / Cc, 1 / Cc], [0, 0, 0, 0]]
    C = [[0, 0], [0, 0], [-1, 0], [1, 0]]
    D = [[1 / R, 1 / R, -1, 0], [1 / R, 1 / R, 0, -1], [1, 0, 0, 0], [0, 1, 0, 0]]
    return lcs.LinearRelationSystem(A, B, C, D, lcs.Complementarity())


def minimal(system, sm, x0, K):
    """The bare loop: precomputed matrices, the same warm-started one-step solver, nothing else."""
    E, G, C, D, step = sm.E, sm.G, system.C, system.D, sm.step
    v = system.v(0.0)
    X = np.empty((K + 1, system.n))
    Z = np.empty((K, system.m))
    W = np.empty((K, system.m))
    X[0] = xk = x0
    for k in range(K):
        xfree = E @ xk
        z, _ = step(C @ xfree + v)
        xk = xfree + G @ z
        X[k + 1] = xk
        Z[k] = z
        W[k] = C @ xk + D @ z + v
    return X, Z, W


def test_diode_bridge_simulate_vs_minimal_script(gate):
    system = diode_bridge()
    K, h, theta = gate.size(5000, 1000), 1e-6, 0.5
    t = np.linspace(0.0, K * h, K + 1)
    x0 = np.array([10.0, 0.0])
    tr = system.simulate(x0, t, theta=theta)
    X, Z, W = minimal(system, system.step_matrices(h, theta), x0, K)
    assert np.array_equal(tr.x, X) and np.array_equal(tr.extras["z"], Z) and np.array_equal(tr.extras["w"], W)
    fresh = [system.step_matrices(h, theta) for _ in range(12)]  # one cold stepper per round, built untimed
    gate.benchmark.extra_info.update({"steps": K, "h": h, "theta": theta})
    gate.measure(lambda: system.simulate(x0, t, theta=theta), lambda: minimal(system, fresh.pop(), x0, K),
                 target=TARGET)
