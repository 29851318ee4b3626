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

**Names come from the registry.**  ``verimono.checks.check_<law>`` is the public check of every registered law
whose name is an identifier, found in ``REGISTRY`` once every module of this package is imported: a new law
is its decorated evaluator and nothing else here.  The names below the laws — the batteries, the drivers'
helpers, the registry itself — are listed in :data:`_HOMES`.  Everything loads on first use, so ``import
verimono.checks.core`` (the run's stage registry does) loads neither hypothesis nor every law.
"""

from __future__ import annotations

import importlib
import pkgutil

#: the public names that are not a law's ``check_<law>``: public name → the module that defines it
_HOMES = {
    "Outcome": "core", "law": "core",
    "check_assumptions": "assumptions", "problem_checks": "assumptions",
    "LAWS": "operator_battery", "OPERATOR_CHECKS": "operator_battery", "check_operator": "operator_battery",
    "operator_checks": "operator_battery",
    "Sample": "samples", "law_samples": "samples",
    "BOUND": "search", "DEFAULT_EXAMPLES": "search", "fresh_seed": "search",
    "run_law": "operator_battery",     # search's run_law, from the module that registers the laws it runs
    "check_stepper": "stepper_battery", "stepper_checks": "stepper_battery",
}


def load_every_law() -> dict:
    """Import every module of this package (each registers its laws on import) and return ``REGISTRY``."""
    for info in pkgutil.iter_modules(__path__):
        importlib.import_module(f"{__name__}.{info.name}")
    from .core import REGISTRY

    return REGISTRY


def laws_of(kind: str) -> dict:
    """The registered laws of ``kind`` (``"operator"``, ``"stepper"``, ...), every law module loaded first: the
    registry of :mod:`.core` alone holds only the laws of the modules imported so far (``laws_of("stepper")``
    raised KeyError in a fresh process)."""
    load_every_law()
    from .core import laws_of as registered

    return registered(kind)


def public_checks() -> dict:
    """``{"check_<law>": check}`` for every registered law whose name is an identifier."""
    return {f"check_{name}": decl.public for laws in load_every_law().values()
            for name, decl in laws.items() if name.isidentifier() and decl.public is not None}


def __getattr__(name: str):
    if name == "REGISTRY":
        value = load_every_law()
    elif name == "__all__":   # `from verimono.checks import *`
        return sorted(set(_HOMES) | {"REGISTRY", "laws_of"} | set(public_checks()))
    elif name in _HOMES:
        value = getattr(importlib.import_module(f"{__name__}.{_HOMES[name]}"), name)
    elif name.startswith("check_") and name in (checks := public_checks()):
        value = checks[name]
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_HOMES) | {"REGISTRY", "laws_of"} | set(public_checks()))
