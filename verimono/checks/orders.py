"""Convergence-order checks of a stepper against the analytic references (one record per reference; the
whole battery of a stepper, orders and laws, is :func:`verimono.checks.trajectory_laws.check_stepper`).

``check_convergence_order(stepper, problem)`` runs a :func:`verimono.convergence.convergence_study` and
turns its verdict into a result record: ``worst = expected / (upper end of the interval + slack)`` and
``bound = 1``, so the stepper passes when its measured order can reach the expected one.  For references
on which the scheme is exact at the nodes, ``worst = max error / round-off floor``.
"""

from __future__ import annotations

import time
from typing import Callable

from ..convergence import ORDER_SLACK, convergence_study, _name
from ..errors import VerimonoError
from ..problem import Problem
from ..results import FAILED, PASSED, SKIPPED, CheckResult


def check_convergence_order(stepper: Callable, problem: Problem, steps=None, executor=None) -> CheckResult:
    """Whether ``stepper`` reaches ``problem.order`` on ``problem`` (one record, study in ``details``)."""
    subject = f"{_name(stepper)} on {problem.name}"
    if problem.order is None or (steps is None and not problem.steps):
        return CheckResult("convergence_order", subject, SKIPPED,
                           message="the problem states no expected order or no step sizes")
    start = time.perf_counter()
    try:
        study = convergence_study(stepper, problem, steps, executor=executor)
    except (VerimonoError, ArithmeticError, ValueError) as exc:
        return CheckResult("convergence_order", subject, FAILED, message=f"{type(exc).__name__}: {exc}",
                           duration=time.perf_counter() - start)
    ok, msg = study.verdict()
    fit, exp = study.order, problem.order
    if exp.exact:
        worst = max(study.errors["sup"]) / study.floor
    elif fit.exact:
        worst = 0.0
    else:
        worst = exp.value / (fit.high + ORDER_SLACK) if fit.high == fit.high else float("inf")
    counter = None if ok else {"steps": study.mesh, "errors": study.errors["sup"]}
    script = ("from verimono.reference import get\n"
              "from verimono.checks.orders import check_convergence_order\n"
              f"print(check_convergence_order(stepper, get({problem.name!r})))")
    return CheckResult("convergence_order", subject, PASSED if ok else FAILED, worst=worst, bound=1.0,
                       counterexample=counter, message=msg, details={"study": study, "reproduce_python": script},
                       duration=time.perf_counter() - start)
