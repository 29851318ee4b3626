"""Convergence-order checks of a stepper against the analytic references.

``check_convergence_order(stepper, problem)`` runs a :func:`verimono.convergence.convergence_study` and
turns its verdict into a result record: ``worst = expected / (upper end of the interval + slack)`` and
``bound = 1``, so the stepper passes when its measured order can reach the expected one.  For references
on which the scheme is exact at the nodes, ``worst = max error / round-off floor``.
"""

from __future__ import annotations

import time
from typing import Callable, Iterable

from ..convergence import ORDER_SLACK, convergence_study, _name
from ..errors import InvalidCheckArgument, VerimonoError
from ..problem import Problem
from ..results import FAILED, PASSED, SKIPPED, CheckResult, Report
from ..timeouts import run_unit


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
    return CheckResult("convergence_order", subject, PASSED if ok else FAILED, worst=worst, bound=1.0,
                       counterexample=counter, message=msg, details={"study": study.to_dict()},
                       duration=time.perf_counter() - start)


def check_stepper(stepper: Callable, problems: Iterable[Problem] | None = None, *, executor=None,
                  laws: bool | Iterable[str] = True, seed: int = 0, generated: int = 4,
                  orders: bool = True) -> Report:
    """Result records for ``stepper``: convergence orders on the references, then the trajectory laws.

    ``problems=None`` means the whole catalog of :mod:`verimono.reference` (orders and laws) plus
    ``generated`` seeded sample problems (laws only).  The records come first per problem for the
    convergence orders (in the order of ``problems``), then one record per (problem, law) of
    :mod:`verimono.checks.trajectory_laws`; ``laws=False`` keeps the orders only, a list of law names
    selects laws, ``orders=False`` keeps the laws only.  The records are those of :func:`verimono.checks.trajectory_laws.stepper_checks`,
    the same generator :func:`verimono.testing.parametrize_with_checks` turns into pytest cases.
    """
    from .trajectory_laws import LAWS, stepper_checks

    if problems is not None:
        problems = list(problems)
        if not problems:
            raise InvalidCheckArgument("check_stepper was given an empty list of problems: it would verify "
                                       "nothing (pass problems=None for the whole catalog)")
    selected = () if laws is False else (LAWS if laws is True else tuple(laws))
    report = Report()
    for _name_, check in stepper_checks(stepper, problems, seed=seed, generated=generated, laws=selected,
                                        orders=orders, executor=executor):
        law, _, problem_name = _name_.partition("[")
        rec = run_unit(lambda: check(stepper), check=law, subject=f"{_name(stepper)} on {problem_name[:-1]}")
        report.add(rec)
        if "study" in rec.details:
            from ..convergence import ConvergenceStudy

            report.studies.append(ConvergenceStudy.from_dict(rec.details["study"]))
    if not len(report):
        raise InvalidCheckArgument("check_stepper selected no check (no law, no order): it would verify nothing")
    return report
