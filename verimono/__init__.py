"""verimono — verification and property testing for evolution inclusions with maximal monotone operators.

``x'(t) ∈ -F(t, x) + f(x) + u(t)``, with ``F(t,·)`` maximal monotone for every ``t``, solved by the
proximal scheme of Camlibel, Iannelli and Tanwani and checked against the laws and bounds of their paper.
Data flow one way: Problem → stepper → Trajectory → checks → results → report / gate.
"""

import importlib
import sys as _sys

if _sys.argv and _sys.argv[0].replace("\\", "/").rpartition("/")[2].split(".")[0] in ("verimono", "verimono-script"):
    # the `verimono` command: a signal during its first imports (about 2 s) is one line, not a traceback
    # (verimono.cli.console_main takes over once it runs: docs/run.md "Exit status, and what survives")
    from .core._early_signals import quiet_until_main as _quiet

    _quiet()

from .core.errors import (BadTarget, BatchStepError, IncompatibleBaseline, InfeasibleStep, InvalidCheckArgument,
                          InvalidClaim, InvalidGrid, InvalidProblem, MissingOptionalDependency, NotApplicable,
                          NotMonotone, OutsideDomain, SchemaError, SolverFailure, StageUnavailable, UnitTimeout, UnknownProfile,
                          UnknownStage, UnverifiedSolution, VerimonoError)
from .core.grids import graded_grid, random_grid, refine, uniform_grid, validate_grid
from .core.operators import (L1Subdifferential, Linear, LogBarrier, NormalCone, NormSubdifferential, Operator,
                             Shifted, operator_from_resolvent)
from .core.prox import ProxOperator, ProxOutputError, operator_from_prox
from .core.problem import Order, Problem
from .core.claims import Claim, Stepper
from .records.results import CheckResult, Report
from .core.stepping import Trajectory, solve, stream
from .core.pseudo_distance import pseudo_distance_lower_bound
from .core.convergence import ConvergenceStudy, ErrorAccumulator, convergence_study
from .core.adaptive import Adaptive, ToleranceStudy, tolerance_study
from .core import sets
from .core._moved import install_moved_modules

#: module paths of the flat layout, kept importable (``import verimono.stepping``, ``from verimono.sets import
#: Ball``): each is the module of its new home, loaded on first use
MOVED = {
    "_jsonable": "core._jsonable",
    "_params": "core._params",
    "_reproducible": "core._reproducible",
    "_rows": "core._rows",
    "_subgradients": "core._subgradients",
    "_validate": "core._validate",
    "arrays": "core.arrays",
    "atomic": "records.atomic",
    "calibration": "execution.calibration",
    # the search engine's modules, in verimono/checks/ before its folder of their own
    "checks.batches": "checks.engine.batches",
    "checks.coordinates": "checks.engine.coordinates",
    "checks.directions": "checks.engine.directions",
    "checks.forms": "checks.engine.forms",
    "checks.samples": "checks.engine.samples",
    "checks.search": "checks.engine.search",
    "checks.supremum": "checks.engine.supremum",
    "checks.sweep": "checks.engine.sweep",
    "claims": "core.claims",
    "convergence": "core.convergence",
    "display": "core.display",
    "environment": "records.environment",
    "errors": "core.errors",
    "executors": "execution.executors",
    "gate": "run.gate",
    "grids": "core.grids",
    "manufactured": "reference.manufactured",
    "naming": "core.naming",
    "operators": "core.operators",
    "performance": "run.performance",
    "problem": "core.problem",
    "profiles": "execution.profiles",
    "progress": "run.progress",
    "prox": "core.prox",
    "pseudo_distance": "core.pseudo_distance",
    "qp": "core.qp",
    "report": "records.report",
    "results": "records.results",
    "runs": "run.execute",
    "schema": "records.schema",
    "sets": "core.sets",
    "stages": "run.stages",
    "stepping": "core.stepping",
    "targets": "run.targets",
    "timeouts": "execution.timeouts",
    "timing": "execution.timing",
    "tolerances": "core.tolerances",
    "watchdog": "execution.watchdog",
}
install_moved_modules(__name__, MOVED)


def __getattr__(name: str):
    """Names loaded on first use (``from verimono import check_stepper`` works as before): the checks and
    strategies import hypothesis, the LCS tools SciPy's optimizers, so ``import verimono`` does not."""
    if name in ("check_operator", "check_stepper", "operator_checks"):
        from .checks import check_operator, check_stepper, operator_checks

        value = {"check_operator": check_operator, "check_stepper": check_stepper,
                 "operator_checks": operator_checks}[name]
    elif name == "manufactured_problem":   # verimono.reference loads the catalog's LCS tools
        from .reference.manufactured import manufactured_problem as value
    elif name == "solve_adaptive":         # the adaptive proximal scheme (core, light; kept out of the import)
        from .core.adaptive_proximal import solve_adaptive as value
    elif name in ("work_precision", "WorkPrecisionSet"):   # timing lives in execution: the run layer
        from .run import work_precision as _wp

        value = getattr(_wp, name)
    elif name in ("check_adaptive", "check_tolerance_rate", "check_switching_times"):
        from .checks import own_steps as _own

        value = getattr(_own, name)
    elif name == "check_assumptions":
        from .checks.assumptions import check_assumptions as value
    elif name == "checks":  # `import a.b as c` imports the submodule before reading it: no recursion here
        import verimono.checks as value
    elif name == "lcs":
        import verimono.lcs as value
    elif name == "strategies":
        import verimono.strategies as value
    elif name in MOVED:   # `vm.stepping`, as the submodule of the flat layout was
        value = importlib.import_module(f"{__name__}.{MOVED[name]}")
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


__version__ = "0.1.0"

__all__ = [
    "VerimonoError", "InvalidProblem", "InvalidGrid", "OutsideDomain", "NotMonotone", "InfeasibleStep",
    "BatchStepError", "SolverFailure", "UnverifiedSolution", "UnknownProfile", "UnknownStage", "StageUnavailable", "BadTarget", "SchemaError",
    "NotApplicable",   # a stepper (or a law) raises it for a problem it does not apply to: a counted skip
    "IncompatibleBaseline", "MissingOptionalDependency", "InvalidClaim",
    "InvalidCheckArgument", "UnitTimeout",
    "Operator", "operator_from_resolvent", "operator_from_prox", "ProxOperator", "ProxOutputError", "Linear",
    "NormSubdifferential", "L1Subdifferential",
    "NormalCone", "Shifted", "LogBarrier", "sets",
    "Problem", "Order", "Stepper", "Claim", "Trajectory", "solve", "stream", "ErrorAccumulator",
    "uniform_grid", "graded_grid", "random_grid", "refine", "validate_grid",
    "CheckResult", "Report", "pseudo_distance_lower_bound", "lcs", "strategies",
    "convergence_study", "ConvergenceStudy", "check_stepper", "check_operator", "operator_checks",
    "check_assumptions", "manufactured_problem",
    "Adaptive", "ToleranceStudy", "tolerance_study", "solve_adaptive", "work_precision", "WorkPrecisionSet",
    "check_adaptive", "check_tolerance_rate", "check_switching_times",
]
