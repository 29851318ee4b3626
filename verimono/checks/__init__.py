"""Checks: functions that return result records (never print, never assert).

Every law is declared once in :mod:`verimono.checks.core` (``REGISTRY``: operator, stepper and problem
laws, each with its paper label and requirements) and runs under the core's one driver.

Convergence orders (:mod:`verimono.checks.orders`); ``check_stepper``, the whole battery of a stepper, and
the trajectory laws (:mod:`verimono.checks.trajectory_laws`).  Operator laws (:mod:`verimono.checks.operator_laws`): ``check_<law>(op, ...)`` per law, the registry
``operator_checks(op)`` yielding ``(name, check)`` pairs, and ``check_operator(op)`` running them all.
"""

from . import assumptions   # noqa: F401 - its laws join the registry on import
from .core import REGISTRY, Outcome, law, laws_of
from .orders import check_convergence_order
from .trajectory_laws import check_stepper
from .operator_laws import (BOUND, DEFAULT_EXAMPLES, LAWS, OPERATOR_CHECKS, Law, Sample, check_min_norm_in_graph,
                            check_min_norm_least, check_monotone, check_operator, check_resolvent_firmly_nonexpansive,
                            check_resolvent_identity, check_resolvent_in_domain, check_resolvent_limit,
                            check_resolvent_nonexpansive, check_resolvent_single_valued, check_yosida_bounded_by_min_norm,
                            check_yosida_in_graph, check_yosida_limit, check_yosida_lipschitz, check_yosida_monotone,
                            check_yosida_nonincreasing, fresh_seed, law_samples, operator_checks, run_law)

__all__ = [
    "REGISTRY", "Outcome", "law", "laws_of",
    "check_convergence_order", "check_stepper",
    "check_operator", "operator_checks", "OPERATOR_CHECKS", "LAWS", "Law", "Sample", "law_samples", "run_law",
    "fresh_seed", "DEFAULT_EXAMPLES", "BOUND",
    "check_resolvent_single_valued", "check_resolvent_nonexpansive", "check_resolvent_firmly_nonexpansive",
    "check_resolvent_in_domain", "check_resolvent_identity", "check_resolvent_limit", "check_monotone",
    "check_yosida_lipschitz", "check_yosida_monotone", "check_yosida_in_graph", "check_yosida_nonincreasing",
    "check_yosida_bounded_by_min_norm", "check_yosida_limit", "check_min_norm_in_graph", "check_min_norm_least",
]
