"""verimono — verification and property testing for evolution inclusions with maximal monotone operators.

``x'(t) ∈ -F(t, x) + f(x) + u(t)``, with ``F(t,·)`` maximal monotone for every ``t``, solved by the
proximal scheme of Camlibel, Iannelli and Tanwani and checked against the laws and bounds of their paper.
Data flow one way: Problem → stepper → Trajectory → checks → results → report / gate.
"""

from .errors import (BadTarget, IncompatibleBaseline, InfeasibleStep, InvalidCheckArgument, InvalidClaim, InvalidGrid,
                     InvalidProblem, MissingOptionalDependency, NotMonotone, OutsideDomain, SchemaError,
                     SolverFailure, StageUnavailable, UnitTimeout, UnknownProfile, UnknownStage, VerimonoError)
from .grids import graded_grid, random_grid, refine, uniform_grid, validate_grid
from .operators import (L1Subdifferential, Linear, LogBarrier, NormalCone, NormSubdifferential, Operator,
                        Shifted, operator_from_resolvent)
from .problem import Order, Problem
from .claims import Claim, Stepper
from .results import CheckResult, Report
from .stepping import Trajectory, solve, stream
from .pseudo_distance import pseudo_distance_lower_bound
from .checks import check_operator, check_stepper, operator_checks
from .checks.assumptions import check_assumptions
from .convergence import ConvergenceStudy, ErrorAccumulator, convergence_study
from . import lcs, sets, strategies

__version__ = "0.1.0"

__all__ = [
    "VerimonoError", "InvalidProblem", "InvalidGrid", "OutsideDomain", "NotMonotone", "InfeasibleStep",
    "SolverFailure", "UnknownProfile", "UnknownStage", "StageUnavailable", "BadTarget", "SchemaError",
    "IncompatibleBaseline", "MissingOptionalDependency", "InvalidClaim",
    "InvalidCheckArgument", "UnitTimeout",
    "Operator", "operator_from_resolvent", "Linear", "NormSubdifferential", "L1Subdifferential",
    "NormalCone", "Shifted", "LogBarrier", "sets",
    "Problem", "Order", "Stepper", "Claim", "Trajectory", "solve", "stream", "ErrorAccumulator",
    "uniform_grid", "graded_grid", "random_grid", "refine", "validate_grid",
    "CheckResult", "Report", "pseudo_distance_lower_bound", "lcs", "strategies",
    "convergence_study", "ConvergenceStudy", "check_stepper", "check_operator", "operator_checks",
    "check_assumptions",
]
