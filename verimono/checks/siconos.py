"""Agreement with Siconos (beyond the paper): the reference trajectories of its ``EulerMoreauOSI(θ)`` and θ-γ
schemes and its LCP test set (``verimono/data/siconos``, :mod:`verimono.lcs.siconos_cases`).

* ``siconos_agreement`` — :meth:`LinearRelationSystem.simulate` on a case against its ``.ref`` file: the
  maximum state error relative to the state's scale over all rows, bound ``SICONOS_RTOL`` (both codes run
  the same scheme, so only round-off separates them);
* ``siconos_lcp`` — :func:`verimono.lcs.solve_lcp` on an LCP test file: the complementarity residual
  relative to the data ``≤ SICONOS_RTOL``, or :class:`verimono.InfeasibleStep` for the files that have no
  solution.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..core.errors import InfeasibleStep
from ..lcs.lcp import lcp_residual, solve_lcp
from ..lcs.siconos import PACKAGED_DATA, read_lcp, siconos_root
from ..lcs.siconos_cases import CASES, INFEASIBLE_LCPS, SICONOS_RTOL, simulate_case, state_error
from ..records.results import FAILED, CheckResult, Report
from ..records.verdicts import new_record
from .core import Outcome, law, run


def run_case(decl: Any, name: str, data_dir: Path = PACKAGED_DATA) -> CheckResult:
    """The law on the Siconos case ``name`` (a key of :data:`~verimono.lcs.siconos_cases.CASES`)."""
    case = CASES[name]
    return run(decl, case.file, lambda: decl.evaluate(case, data_dir))


def run_lcp_file(decl: Any, path: Path) -> CheckResult:
    """The law on one LCP test file."""
    return run(decl, Path(path).name, lambda: decl.evaluate(Path(path)))


@law("siconos_agreement", "Siconos EulerMoreauOSI(θ), θ-γ", subject="system", driver=run_case, battery=False)
def check_siconos_case(case: Any, data_dir: Path) -> Outcome:
    """``simulate`` on a Siconos case agrees with its reference trajectory: the maximum state error relative
    to the state's scale, over every row, is at most ``SICONOS_RTOL``."""
    tr, ref, _ = simulate_case(case, data_dir)
    err = state_error(case, tr, ref)
    message = f"max relative state error {err:.2e} over {ref.shape[0]} rows"
    return Outcome(err / SICONOS_RTOL, details={"error": err, "rows": int(ref.shape[0])}, message=message,
                   counter={"file": case.file, "theta": case.theta, "gamma": case.gamma, "h": case.h,
                            "message": message})


@law("siconos_lcp", "p:lcp2 on the Siconos LCP test set", subject="system", driver=run_lcp_file, battery=False)
def check_lcp_file(path: Path) -> Outcome:
    """``solve_lcp`` on a Siconos LCP test file: solved to a relative complementarity residual
    ``≤ SICONOS_RTOL``, or reported infeasible where the file has no solution."""
    M, q = read_lcp(path)
    try:
        z = solve_lcp(M, q)
    except InfeasibleStep as exc:
        ok = path.name in INFEASIBLE_LCPS
        return Outcome(None, status="passed" if ok else FAILED,
                       message=("reported infeasible, as expected: " if ok else "wrongly reported infeasible: ")
                       + str(exc)[:200])
    scale = 1.0 + np.abs(q).max() + np.abs(M).max() * np.abs(z).max()
    res = lcp_residual(M, q, z) / scale
    if path.name in INFEASIBLE_LCPS:
        return Outcome(res / SICONOS_RTOL, status=FAILED, details={"error": res, "n": int(q.size)},
                       message="a solution was returned for an LCP that has none")
    message = f"complementarity residual {res:.2e} (relative)"
    return Outcome(res / SICONOS_RTOL, details={"error": res, "n": int(q.size)}, message=message,
                   counter={"message": message})


def check_siconos_lcps(data_dir: Path = PACKAGED_DATA) -> Report:
    """One record per Siconos LCP test file (``lcp/*.dat``); one failed record when the data folder holds
    no LCP file."""
    try:
        root = siconos_root(data_dir)
    except FileNotFoundError as exc:
        return Report([new_record("siconos_lcp", "LCP test files", FAILED, message=str(exc))])
    paths = sorted((root / "lcp").glob("*.dat"))
    if not paths:
        return Report([new_record("siconos_lcp", "LCP test files", FAILED,
                                  message=f"no LCP test file (lcp/*.dat) in {root}")])
    return Report([check_lcp_file(path) for path in paths])


def check_siconos(data_dir: Path = PACKAGED_DATA) -> Report:
    """Agreement records for every Siconos trajectory and LCP test file under ``data_dir``."""
    report = Report([check_siconos_case(name, data_dir) for name in CASES])
    return report.extend(check_siconos_lcps(data_dir))


__all__ = ["check_siconos", "check_siconos_case", "check_siconos_lcps", "check_lcp_file"]
