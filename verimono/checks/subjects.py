"""What a subject is — an operator, a problem or a stepper — decided before any law runs.

A battery run on something that is not its kind of subject would charge every law's failure to the
subject; instead it is refused up front with one :class:`verimono.InvalidCheckArgument` that names what
was expected and the wrapper that makes one (:func:`verimono.operator_from_resolvent`,
:func:`verimono.operator_from_prox`, :class:`verimono.Stepper`).
"""

from __future__ import annotations

import inspect
from typing import Any

from ..core.errors import InvalidCheckArgument
from ..core.problem import Problem

#: second-parameter names that mark a callable as a resolvent or prox ``f(x, lam)``, not a stepper
#: ``(problem, t_grid)``
STEP_NAMES = frozenset({"lam", "lamb", "lmbda", "lambda_", "lmb", "gamma", "tau", "step", "h", "mu", "alpha",
                        "rho", "eta", "scaling", "sigma"})


def how_to_wrap(fn: Any = None) -> str:
    """How to make an operator of the callable ``fn`` (named in the advice)."""
    name = getattr(fn, "__name__", None) or "fn"
    return (f"wrap a resolvent as verimono.operator_from_resolvent({name}, dim=n), or a proximal operator as "
            f"verimono.operator_from_prox({name}, shape=n)")


def _described(obj: Any) -> str:
    text = repr(obj)
    return f"{type(obj).__name__} {text if len(text) <= 60 else text[:57] + '...'}"


def is_operator(obj: Any) -> bool:
    """Operators are known through their resolvent: an object (not a class) with ``.resolvent`` and ``.dim``."""
    return (not isinstance(obj, type) and callable(getattr(obj, "resolvent", None))
            and getattr(obj, "dim", None) is not None)


def is_problem(obj: Any) -> bool:
    return isinstance(obj, Problem)


def _positional(fn: Any) -> list[inspect.Parameter] | None:
    """The positional parameters of ``fn`` (``None`` when its signature cannot be read)."""
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return None
    return [p for p in sig.parameters.values() if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD,
                                                             p.VAR_POSITIONAL)]


def looks_like_resolvent(fn: Any) -> str | None:
    """Why ``fn`` looks like a resolvent or prox ``f(x, lam[, t])`` rather than a stepper, or ``None``."""
    params = _positional(fn)
    if params and len(params) >= 2 and params[1].kind != params[1].VAR_POSITIONAL \
            and params[1].name.lower() in STEP_NAMES:
        names = ", ".join(p.name for p in params)
        return (f"looks like a resolvent or proximal operator ({names}), not a stepper(problem, t_grid): its "
                f"second parameter {params[1].name!r} is a step size")
    return None


def stepper_arity_problem(fn: Any) -> str | None:
    """Why ``fn`` cannot be called as ``fn(problem, t_grid)``, or ``None``."""
    try:
        inspect.signature(fn).bind(None, None)
    except TypeError as exc:
        return f"it cannot be called as stepper(problem, t_grid) ({exc})"
    except ValueError:
        return None    # a builtin without a readable signature: it is called and judged
    return None


def require_operator(obj: Any) -> Any:
    """``obj`` if it is an operator, else :class:`InvalidCheckArgument` saying how to make one."""
    if is_operator(obj):
        dim = getattr(obj, "dim")
        if isinstance(dim, bool) or not isinstance(dim, int) or dim < 1:
            raise InvalidCheckArgument(f"an operator's dim must be a positive integer, got {dim!r} on "
                                       f"{_described(obj)}")
        return obj
    hint = f"; {how_to_wrap(obj)}" if callable(obj) and not isinstance(obj, type) else ""
    raise InvalidCheckArgument(f"expected an operator (an object with .resolvent(x, lam, t) and .dim), got "
                               f"{_described(obj)}{hint}")


def require_stepper(obj: Any) -> Any:
    """``obj`` if it can be a stepper ``stepper(problem, t_grid)``, else :class:`InvalidCheckArgument`."""
    if is_operator(obj):
        raise InvalidCheckArgument(f"expected a stepper(problem, t_grid), got an operator {_described(obj)}: "
                                   "check it with verimono.check_operator")
    if not callable(obj) or isinstance(obj, type) or is_problem(obj):
        raise InvalidCheckArgument(f"expected a stepper, a callable stepper(problem, t_grid) returning the states "
                                   f"(K+1, n), got {_described(obj)}")
    why = looks_like_resolvent(obj) or stepper_arity_problem(obj)
    if why:
        raise InvalidCheckArgument(f"expected a stepper(problem, t_grid), but {getattr(obj, '__name__', obj)!s} "
                                   f"{why}; a resolvent or prox is an operator: {how_to_wrap(obj)}; a scheme with "
                                   "another signature is wrapped as verimono.Stepper(lambda problem, t_grid: ...)")
    return obj


def require_problem(obj: Any) -> Any:
    """``obj`` if it is a :class:`verimono.Problem`, else :class:`InvalidCheckArgument`."""
    if not is_problem(obj):
        raise InvalidCheckArgument(f"expected a verimono.Problem, got {_described(obj)}")
    return obj


def kind_of(obj: Any) -> str:
    """``"operator"``, ``"problem"`` or ``"stepper"``; :class:`InvalidCheckArgument` for anything else."""
    if is_operator(obj):
        require_operator(obj)
        return "operator"
    if is_problem(obj):
        return "problem"
    require_stepper(obj)
    return "stepper"


__all__ = ["is_operator", "is_problem", "kind_of", "require_operator", "require_stepper", "require_problem",
           "looks_like_resolvent", "stepper_arity_problem", "how_to_wrap", "STEP_NAMES"]
