"""Checks: functions that return result records (never print, never assert).

Every law is one decorated evaluator returning an :class:`~verimono.checks.core.Outcome`
(:mod:`verimono.checks.core`); the decorator registers it (``REGISTRY``: operator, stepper, problem,
system and estimator laws, each with its paper label and requirements) and makes it the public
``check_<law>``, run by its kind's driver:

* operators — :mod:`.operator_laws`, :mod:`.prox_laws`, driven by the search of :mod:`.search`; the battery
  :func:`check_operator` (:mod:`.operator_battery`);
* steppers — :mod:`.trajectory_laws`, :mod:`.limits`, :mod:`.bounds`, :mod:`.orders`, :mod:`.picard`, driven
  on partitions by :mod:`.partitions`; the battery :func:`check_stepper` (:mod:`.stepper_battery`);
* problems — the assumptions of Theorem ``thm:main`` (:mod:`.assumptions`, :func:`check_assumptions`);
* linear relation systems — the hypotheses of Section 7 (:mod:`.section7`) and the paper's Example
  (:mod:`.example`);
* estimators — the pseudo-distance (:mod:`.pseudo_distance`) and Hoffman's constant (:mod:`.hoffman`).

The names below load their module on first use, so ``import verimono.checks.core`` (the run's stage registry
does) does not load hypothesis and every law; ``verimono.checks.REGISTRY`` and ``verimono.checks.laws_of``
come with every battery's laws registered.
"""

from __future__ import annotations

#: public name → the module that defines it
_HOMES = {
    "REGISTRY": "core", "Outcome": "core", "law": "core", "laws_of": "core",
    "check_assumptions": "assumptions", "problem_checks": "assumptions",
    "LAWS": "operator_battery", "OPERATOR_CHECKS": "operator_battery", "check_operator": "operator_battery",
    "operator_checks": "operator_battery",
    "check_convergence_order": "orders",
    "Sample": "samples", "law_samples": "samples",
    "BOUND": "search", "DEFAULT_EXAMPLES": "search", "fresh_seed": "search", "run_law": "search",
    "check_stepper": "stepper_battery", "stepper_checks": "stepper_battery",
    **{f"check_{law}": "operator_laws" for law in (
        "resolvent_single_valued", "resolvent_nonexpansive", "resolvent_firmly_nonexpansive", "resolvent_in_domain",
        "resolvent_identity", "resolvent_limit", "monotone", "yosida_lipschitz", "yosida_monotone",
        "yosida_in_graph", "yosida_nonincreasing", "yosida_bounded_by_min_norm", "yosida_limit",
        "min_norm_in_graph", "min_norm_least")},
}


def __getattr__(name: str):
    home = _HOMES.get(name)
    if home == "core":   # the registry, with every law registered: load the batteries first
        from . import assumptions, operator_battery, section7, stepper_battery  # noqa: F401
        from . import core as module
    elif home == "assumptions":
        from . import assumptions as module
    elif home == "operator_battery":
        from . import operator_battery as module
    elif home == "orders":
        from . import orders as module
    elif home == "samples":
        from . import samples as module
    elif home == "search":   # run_law takes a law by name: the operator laws join the registry on import
        from . import operator_laws  # noqa: F401
        from . import search as module
    elif home == "stepper_battery":
        from . import stepper_battery as module
    elif home == "operator_laws":
        from . import operator_laws as module
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(module, name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_HOMES))


__all__ = sorted(_HOMES)
