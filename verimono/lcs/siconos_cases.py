"""The Siconos reference systems of ``verimono/data/siconos/CASES.md``: each case is the system, initial
state, θ (and γ for the θ-γ variant), step ``h`` and the columns of the ``.ref`` file that hold the state;
:func:`simulate_case` runs one with :meth:`LinearRelationSystem.simulate`.  The agreement laws on them are
in :mod:`verimono.checks.siconos`.  ``data_dir`` is a data folder as
:func:`verimono.lcs.siconos.siconos_root` reads it; by default the data shipped in the package
(``PACKAGED_DATA``).
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Callable

import numpy as np

from .relations import Complementarity, Relay
from .siconos import PACKAGED_DATA, read_ref, ref_path, siconos_root
from .system import LinearRelationSystem

#: required agreement with Siconos, relative to the state's scale (Siconos' own tests use 1e-12,
#: 1e-10 for θ-γ): both codes run the same scheme, so only round-off separates them
SICONOS_RTOL = 1e-10
#: LCP test files with no solution (CASES.md: ``lcp_Pang_isolated_sol_perturbed``)
INFEASIBLE_LCPS = frozenset({"lcp_Pang_isolated_sol_perturbed.dat"})

_L, _C, _R = 1e-2, 1e-6, 1e3
_A_LC = [[0.0, -1 / _C], [1 / _L, 0.0]]


def diode_bridge() -> LinearRelationSystem:
    D = [[1 / _R, 1 / _R, -1, 0], [1 / _R, 1 / _R, 0, -1], [1, 0, 0, 0], [0, 1, 0, 0]]
    return LinearRelationSystem(_A_LC, [[0, 0, -1 / _C, 1 / _C], [0, 0, 0, 0]],
                                [[0, 0], [0, 0], [-1, 0], [1, 0]], D, Complementarity(), name="DiodeBridge")


def diode_bridge_cap_filter() -> LinearRelationSystem:
    Cf = 300e-9
    A = np.zeros((3, 3)); A[:2, :2] = _A_LC; A[2, 2] = -1 / (_R * Cf)
    C = np.zeros((4, 3)); C[0, 2] = 1; C[2, 0] = -1; C[2, 2] = 1; C[3, 0] = 1
    D = np.zeros((4, 4)); D[0, 1] = -1; D[1, 0] = 1; D[1, 2] = 1; D[1, 3] = -1; D[2, 1] = -1; D[3, 1] = 1
    B = np.zeros((3, 4)); B[0, 2] = -1 / _C; B[0, 3] = 1 / _C; B[2, 0] = 1 / Cf; B[2, 2] = 1 / Cf
    return LinearRelationSystem(A, B, C, D, Complementarity(), name="DiodeBridgeCapFilter")


def circuit_rlcd() -> LinearRelationSystem:
    return LinearRelationSystem(_A_LC, [[-1 / _C], [0]], [[-1, 0]], [[_R]], Complementarity(), name="CircuitRLCD")


def circuit_rlcd_theta_gamma() -> LinearRelationSystem:
    w2 = 4 * np.pi ** 2  # L = 1, C = 1/(4π²), R = 10
    return LinearRelationSystem([[0, -1], [w2, 0]], [[1], [0]], [[w2, 0]], [[10.0]], Complementarity(),
                                name="CircuitRLCD (θ-γ)")


def simple_relay() -> LinearRelationSystem:
    return LinearRelationSystem(np.zeros((2, 2)), 2 * np.eye(2), np.eye(2), np.zeros((2, 2)), Relay(),
                                name="SimpleExampleRelay")


def relay_oscillator() -> LinearRelationSystem:
    return LinearRelationSystem([[0, 1, 0], [0, 0, 1], [0, -3, -2]], [[0], [0], [1]], [[1, 0, 0]], [[0]], Relay(),
                                name="RelayOscillator")


def filippov() -> LinearRelationSystem:
    c = 25.0
    return LinearRelationSystem(np.zeros((2, 2)), 2 * np.array([[1, -(1 + c)], [1 + c, 1]]), np.eye(2),
                                np.zeros((2, 2)), Relay(), name="Filippov")


@dataclasses.dataclass(frozen=True)
class SiconosCase:
    file: str
    make: Callable[[], LinearRelationSystem]
    x0: tuple[float, ...]
    theta: float
    gamma: float | None
    h: float
    state_columns: tuple[int, ...]


CASES: dict[str, SiconosCase] = {c.file: c for c in [
    SiconosCase("DiodeBridge.ref", diode_bridge, (10, 0), 0.5, None, 1e-6, (1, 2)),
    SiconosCase("CircuitRLCD.ref", circuit_rlcd, (10, 0), 0.5000000000001, None, 1e-5, (1, 2)),
    SiconosCase("SimpleExampleRelay.ref", simple_relay, (1, -1), 0.5, None, 1e-3, (1, 2)),
    SiconosCase("SimpleExampleRelay_py.ref", simple_relay, (1, -1), 0.5, None, 1e-3, (1, 2)),
    SiconosCase("RelayOscillator.ref", relay_oscillator, (0, 3 * np.sqrt(2) / (2 * np.pi), 0), 0.5, None, 1e-2,
                (1, 2, 3)),
    SiconosCase("Filippov.ref", filippov, (3, 3), 0.5, None, 1e-3, (1, 2)),
    SiconosCase("ThetaGamma_DiodeBridge.ref", diode_bridge, (10, 0), 0.5, 0.5, 1e-6, (1, 2)),
    SiconosCase("ThetaGamma_CircuitRLCD.ref", circuit_rlcd_theta_gamma, (1, 1), 0.5, 0.5, 0.05, (1, 2)),
    SiconosCase("DiodeBridgeCapFilter.ref", diode_bridge_cap_filter, (10, 0, 0), 1.0, None, 1e-6, (1, 2)),
]}


def simulate_case(case: SiconosCase, data_dir: Path = PACKAGED_DATA):
    """``(trajectory, reference rows, seconds)`` for one case."""
    ref = read_ref(ref_path(siconos_root(data_dir), case.file))
    t = np.arange(ref.shape[0]) * case.h
    start = time.perf_counter()
    tr = case.make().simulate(case.x0, t, theta=case.theta, gamma=case.gamma)
    return tr, ref, time.perf_counter() - start


def state_error(case: SiconosCase, tr, ref) -> float:
    """Max over rows and state components of ``|x - x_ref| / max|x_ref|`` (per component)."""
    X = ref[:, list(case.state_columns)]
    return float((np.abs(tr.x[:, :X.shape[1]] - X).max(axis=0) / np.abs(X).max(axis=0)).max())


__all__ = ["CASES", "SiconosCase", "SICONOS_RTOL", "INFEASIBLE_LCPS", "PACKAGED_DATA", "simulate_case",
           "state_error"]
