"""The arguments every public check validates the same way, before any work (typed errors, no hypothesis import:
the stepper laws take them too): a seed, a time horizon, a flag, a step range, an executor, a list of problems, a
selection of laws.  What the harness was given is never charged to the subject: a malformed argument is an
:class:`InvalidCheckArgument` before the subject is first called, not a failed or undecided record."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..core._validate import step_range_of, study_executor
from ..core.errors import InvalidCheckArgument
from ..core.problem import Problem


def valid_seed(seed: Any) -> int:
    """``seed`` as a non-negative integer; :class:`InvalidCheckArgument` otherwise."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidCheckArgument(f"seed must be a non-negative integer, got {seed!r}")
    return int(seed)


def valid_horizon(horizon: Any) -> float:
    """``horizon`` as a finite time ``≥ 0``; :class:`InvalidCheckArgument` otherwise."""
    if isinstance(horizon, bool) or not isinstance(horizon, (int, float, np.integer, np.floating)) \
            or not (math.isfinite(horizon) and horizon >= 0):
        raise InvalidCheckArgument(f"horizon must be a finite time >= 0, got {horizon!r}")
    return float(horizon)


def valid_flag(value: Any, what: str) -> bool:
    """``value`` as ``True`` or ``False`` (a NumPy bool too); :class:`InvalidCheckArgument` otherwise —
    ``orders='no'`` is truthy, and would run what it asked not to."""
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidCheckArgument(f"{what} must be True or False, got {value!r}")
    return bool(value)


def valid_step_range(step_range: Any) -> tuple[float, float] | None:
    """``step_range``: ``None`` or two finite step sizes ``> 0`` (either order); :class:`InvalidCheckArgument`
    otherwise.  A range well formed but holding no two grids of some problem's ``[0, T]`` is that problem's
    study left undecided (:func:`verimono.checks.orders.check_convergence_order`), not an error."""
    return None if step_range is None else step_range_of(step_range, InvalidCheckArgument)


def valid_executor(executor: Any) -> Any:
    """``executor`` of a stepper battery: ``None``, ``"serial"``, ``"process"``, a ``concurrent.futures``
    executor (the convergence studies' grids), or ``"process:N"`` with an integer ``N >= 1`` (every check in
    one of ``N`` worker processes); :class:`InvalidCheckArgument` otherwise."""
    if isinstance(executor, str) and executor.startswith("process:"):
        n = executor.partition(":")[2]
        if not (n.isdigit() and int(n) >= 1):
            raise InvalidCheckArgument(f"executor {executor!r}: process:N needs an integer N >= 1 worker processes")
        return executor
    return study_executor(executor, InvalidCheckArgument)


def valid_problems(problems: Any, who: str = "check_stepper") -> list | None:
    """``problems``: ``None`` (the catalog) or a non-empty list (any iterable but a string) of
    :class:`verimono.Problem`; :class:`InvalidCheckArgument` otherwise — a single problem is not a list of them."""
    if problems is None:
        return None
    if isinstance(problems, Problem):
        raise InvalidCheckArgument(f"{who} takes a list of problems, got a single Problem ({problems.name!r}): "
                                   "pass problems=[problem]")
    if isinstance(problems, (str, bytes, dict)) or not hasattr(problems, "__iter__"):
        raise InvalidCheckArgument(f"{who} takes a list of verimono.Problem, got {type(problems).__name__} "
                                   f"{problems!r:.60}")
    found = list(problems)
    if not found:
        raise InvalidCheckArgument(f"{who} was given an empty list of problems: it would verify nothing (pass "
                                   "problems=None for the whole catalog)")
    for p in found:
        if not isinstance(p, Problem):
            raise InvalidCheckArgument(f"{who} takes a list of verimono.Problem, got {type(p).__name__} {p!r:.60} "
                                       "in it")
    return found


def valid_laws(laws: Any) -> bool | tuple[str, ...]:
    """``laws``: ``True`` (all), ``False`` (none) or a list of law names; :class:`InvalidCheckArgument` otherwise
    (``None`` and a bare string included: ``laws="contraction"`` would be read letter by letter).  Whether each
    name is a law is the battery's to say."""
    if isinstance(laws, (bool, np.bool_)):
        return bool(laws)
    if isinstance(laws, (str, bytes)) or laws is None or not hasattr(laws, "__iter__"):
        raise InvalidCheckArgument(f"laws must be True, False or a list of law names (e.g. laws=['contraction']), "
                                   f"got {laws!r:.60}")
    names = tuple(laws)
    bad = [n for n in names if not isinstance(n, str)]
    if bad:
        raise InvalidCheckArgument(f"laws must be law names (strings), got {bad!r:.60}")
    return names


__all__ = ["valid_seed", "valid_horizon", "valid_flag", "valid_step_range", "valid_executor", "valid_problems",
           "valid_laws"]
