"""The Siconos reference systems of ``verimono/data/siconos/CASES.md`` and the agreement check on them.

Each case is the system, initial state, θ (and γ for the θ-γ variant), step ``h`` and the columns of the
``.ref`` file that hold the state.  :func:`check_siconos` simulates every case with
:meth:`LinearRelationSystem.simulate` and records the maximum state error relative to the state's scale
over all rows (bound ``SICONOS_RTOL``), and solves every LCP test file (residual ``≤ SICONOS_RTOL`` relative
to the data, or :class:`verimono.InfeasibleStep` for the files that have no solution).  ``data_dir`` is a
data folder as :func:`verimono.lcs.siconos.siconos_root` reads it; by default the data shipped in the package
(``PACKAGED_DATA``).
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Callable

import numpy as np

from ..errors import InfeasibleStep, VerimonoError
from ..results import FAILED, PASSED, CheckResult, Report
from .lcp import lcp_residual, solve_lcp
from .relations import Complementarity, Relay
from .siconos import PACKAGED_DATA, read_lcp, read_ref, ref_path, siconos_root
from .system import LinearRelationSystem

#: required agreement with Siconos, relative to the state's scale (issue 4; Siconos' own tests use 1e-12,
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


def check_siconos(data_dir: Path = PACKAGED_DATA) -> Report:
    """Agreement records for every Siconos trajectory and LCP test file found under ``data_dir``."""
    report = Report()
    for name in CASES:
        report.add(check_siconos_case(name, data_dir))
    report.extend(check_siconos_lcps(data_dir))
    return report


def check_siconos_case(name: str, data_dir: Path = PACKAGED_DATA) -> CheckResult:
    """The agreement record of the Siconos trajectory ``name`` (a key of :data:`CASES`)."""
    case = CASES[name]
    try:
        tr, ref, seconds = simulate_case(case, data_dir)
    except (VerimonoError, OSError) as exc:
        return CheckResult("siconos_agreement", case.file, FAILED, message=f"{type(exc).__name__}: {exc}")
    err = state_error(case, tr, ref)
    ok = err <= SICONOS_RTOL
    return CheckResult("siconos_agreement", case.file, PASSED if ok else FAILED, worst=err / SICONOS_RTOL,
                       bound=1.0, message=f"max relative state error {err:.2e} over {ref.shape[0]} rows",
                       counterexample=None if ok else {"file": case.file, "theta": case.theta,
                                                       "gamma": case.gamma, "h": case.h},
                       details={"error": err, "rows": int(ref.shape[0])}, duration=seconds)


def check_siconos_lcps(data_dir: Path = PACKAGED_DATA) -> Report:
    """One record per Siconos LCP test file (``lcp/*.dat``): solved to the residual, or reported infeasible
    where it has no solution; one failed record when the data folder holds no LCP file."""
    try:
        root = siconos_root(data_dir)
    except FileNotFoundError as exc:
        return Report([CheckResult("siconos_lcp", "LCP test files", FAILED, message=str(exc))])
    paths = sorted((root / "lcp").glob("*.dat"))
    if not paths:
        return Report([CheckResult("siconos_lcp", "LCP test files", FAILED,
                                   message=f"no LCP test file (lcp/*.dat) in {root}")])
    return Report([_check_lcp_file(path) for path in paths])


def _check_lcp_file(path: Path) -> CheckResult:
    M, q = read_lcp(path)
    start = time.perf_counter()
    try:
        z = solve_lcp(M, q)
    except InfeasibleStep as exc:
        ok = path.name in INFEASIBLE_LCPS
        return CheckResult("siconos_lcp", path.name, PASSED if ok else FAILED,
                           message=("reported infeasible, as expected: " if ok else "wrongly reported infeasible: ")
                           + str(exc)[:200], duration=time.perf_counter() - start)
    except VerimonoError as exc:
        return CheckResult("siconos_lcp", path.name, FAILED, message=f"{type(exc).__name__}: {exc}")
    scale = 1.0 + np.abs(q).max() + np.abs(M).max() * np.abs(z).max()
    res = lcp_residual(M, q, z) / scale
    ok = res <= SICONOS_RTOL and path.name not in INFEASIBLE_LCPS
    msg = (f"complementarity residual {res:.2e} (relative)" if path.name not in INFEASIBLE_LCPS
           else "a solution was returned for an LCP that has none")
    return CheckResult("siconos_lcp", path.name, PASSED if ok else FAILED, worst=res / SICONOS_RTOL, bound=1.0,
                       message=msg, details={"error": res, "n": int(q.size)}, duration=time.perf_counter() - start)


__all__ = ["CASES", "SiconosCase", "SICONOS_RTOL", "INFEASIBLE_LCPS", "check_siconos", "check_siconos_case",
           "check_siconos_lcps", "simulate_case",
           "state_error"]
