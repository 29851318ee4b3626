"""Agreement with Siconos' EulerMoreauOSI(θ) references (../shared/siconos/CASES.md)."""

from __future__ import annotations

import functools
import time

import numpy as np
import pytest

from verimono.lcs import Complementarity, LinearRelationSystem, Relay, read_ref

L, Cc, R = 1e-2, 1e-6, 1e3
A_LC = [[0, -1 / Cc], [1 / L, 0]]


def diode_bridge():
    D = [[1 / R, 1 / R, -1, 0], [1 / R, 1 / R, 0, -1], [1, 0, 0, 0], [0, 1, 0, 0]]
    return LinearRelationSystem(A_LC, [[0, 0, -1 / Cc, 1 / Cc], [0, 0, 0, 0]], [[0, 0], [0, 0], [-1, 0], [1, 0]],
                                D, Complementarity())


def cap_filter():
    Cf = 300e-9
    A = np.zeros((3, 3)); A[:2, :2] = A_LC; A[2, 2] = -1 / (R * Cf)
    C = np.zeros((4, 3)); C[0, 2] = 1; C[2, 0] = -1; C[2, 2] = 1; C[3, 0] = 1
    D = np.zeros((4, 4)); D[0, 1] = -1; D[1, 0] = 1; D[1, 2] = 1; D[1, 3] = -1; D[2, 1] = -1; D[3, 1] = 1
    B = np.zeros((3, 4)); B[0, 2] = -1 / Cc; B[0, 3] = 1 / Cc; B[2, 0] = 1 / Cf; B[2, 2] = 1 / Cf
    return LinearRelationSystem(A, B, C, D, Complementarity())


def relay2(Bm):
    return LinearRelationSystem(np.zeros((2, 2)), Bm, np.eye(2), np.zeros((2, 2)), Relay())


CASES = {  # file: (system, x0, theta, gamma, h, state columns)
    "DiodeBridge.ref": (diode_bridge, [10, 0], 0.5, None, 1e-6, [1, 2]),
    "CircuitRLCD.ref": (lambda: LinearRelationSystem(A_LC, [[-1 / Cc], [0]], [[-1, 0]], [[R]], Complementarity()),
                        [10, 0], 0.5000000000001, None, 1e-5, [1, 2]),
    "SimpleExampleRelay.ref": (lambda: relay2(2 * np.eye(2)), [1, -1], 0.5, None, 1e-3, [1, 2]),
    "SimpleExampleRelay_py.ref": (lambda: relay2(2 * np.eye(2)), [1, -1], 0.5, None, 1e-3, [1, 2]),
    "RelayOscillator.ref": (lambda: LinearRelationSystem([[0, 1, 0], [0, 0, 1], [0, -3, -2]], [[0], [0], [1]],
                                                         [[1, 0, 0]], [[0]], Relay()),
                            [0, 3 * np.sqrt(2) / (2 * np.pi), 0], 0.5, None, 1e-2, [1, 2, 3]),
    "Filippov.ref": (lambda: relay2(2 * np.array([[1, -26], [26, 1]])), [3, 3], 0.5, None, 1e-3, [1, 2]),
    "ThetaGamma_DiodeBridge.ref": (diode_bridge, [10, 0], 0.5, 0.5, 1e-6, [1, 2]),
    "ThetaGamma_CircuitRLCD.ref": (lambda: LinearRelationSystem([[0, -1], [4 * np.pi ** 2, 0]], [[1], [0]],
                                                                [[4 * np.pi ** 2, 0]], [[10]], Complementarity()),
                                   [1, 1], 0.5, 0.5, 0.05, [1, 2]),
    "DiodeBridgeCapFilter.ref": (cap_filter, [10, 0, 0], 1.0, None, 1e-6, [1, 2]),
}


@functools.lru_cache(maxsize=None)
def _run(siconos_dir, name):
    make, x0, theta, gamma, h, cols = CASES[name]
    ref = read_ref(siconos_dir / "refs" / name)
    t = np.arange(ref.shape[0]) * h
    t0 = time.perf_counter()
    tr = make().simulate(x0, t, theta=theta, gamma=gamma)
    return tr, ref, cols, time.perf_counter() - t0


@pytest.mark.parametrize("name", sorted(CASES))
def test_states_match_siconos(siconos_dir, name):
    tr, ref, cols, _ = _run(siconos_dir, name)
    X = ref[:, cols]
    rel = np.abs(tr.x[:, :len(cols)] - X).max(axis=0) / np.abs(X).max(axis=0)
    assert rel.max() <= 1e-10, (name, rel)


def test_diode_bridge_outputs_multipliers_and_speed(siconos_dir):
    tr, ref, _, dt = _run(siconos_dir, "DiodeBridge.ref")
    z, w = tr.extras["z"], tr.extras["w"]
    assert z.shape == (4999, 4) and w.shape == (4999, 4)
    got = np.column_stack([w[:, 0], -z[:, 0], -z[:, 1], z[:, 2]])
    scale = np.abs(ref[1:, 3:7]).max(axis=0)
    assert (np.abs(got - ref[1:, 3:7]).max(axis=0) / scale).max() <= 1e-10
    assert np.all(z >= 0) and np.all(w >= -1e-9) and np.abs(np.sum(z * w, axis=1)).max() <= 1e-9
    assert dt < 5.0  # 5000 steps; constant matrices are factored once (about 0.5 s here)


def test_cap_filter_unique_multiplier_column(siconos_dir):
    tr, ref, _, _ = _run(siconos_dir, "DiodeBridgeCapFilter.ref")
    assert np.abs(tr.extras["z"][:, 0] - ref[1:, 3]).max() / np.abs(ref[:, 3]).max() <= 1e-10


def test_reference_reader(siconos_dir):
    assert read_ref(siconos_dir / "refs" / "DiodeBridge.ref").shape == (5000, 8)
    assert read_ref(siconos_dir / "refs" / "SimpleExampleRelay_py.ref").shape == (1001, 7)  # no header
