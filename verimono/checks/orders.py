"""Convergence-order checks of a stepper against the analytic references (one record per reference; the
whole battery of a stepper, orders and laws, is :func:`verimono.checks.trajectory_laws.check_stepper`).

``check_convergence_order(stepper, problem)`` runs a :func:`verimono.convergence.convergence_study` and
turns its verdict into a result record: ``worst = expected / (upper end of the interval + slack)`` and
``bound = 1``, so the stepper passes when its measured order can reach the expected one.  For references
on which the scheme is exact at the nodes, ``worst = max error / round-off floor``.
"""

from __future__ import annotations

from typing import Callable

from ..claims import claim_of
from ..convergence import ORDER_SLACK, convergence_study, _name
from ..problem import Order, Problem
from ..results import FAILED, PASSED, CheckResult
from .core import Holds, law as _declare, run as _run


def _expected(stepper: Callable, problem: Problem) -> Order | None:
    """The order ``stepper`` must reach on ``problem``: the reference's order for the proximal scheme,
    ``min(claimed, regularity)`` for a scheme claiming only ``scheme="any"`` (:meth:`Order.for_claim`)."""
    claim = claim_of(stepper)
    if claim.proximal:
        return problem.order
    if problem.order is None:
        return Order(claim.order, "the claimed order (the problem states no regularity)")
    return problem.order.for_claim(claim.order)


@_declare("convergence_order", "thm:main (convergence) and each reference's stated order", subject="stepper",
          requires=(Holds(lambda p: None if p.order is not None and p.steps else
                          "the problem states no expected order or no step sizes"),))
def _convergence_order(stepper: Callable, problem: Problem, steps=None, executor=None) -> CheckResult:
    subject = f"{_name(stepper)} on {problem.name}"
    exp = _expected(stepper, problem)
    study = convergence_study(stepper, problem if exp is problem.order else problem.replace(order=exp), steps,
                              executor=executor)
    ok, msg = study.verdict()
    fit = study.order
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
    details = {"study": study, "reproduce_python": script}
    if not claim_of(stepper).proximal:
        details["expected"] = {"order": exp.value, "source": exp.source}
    return CheckResult("convergence_order", subject, PASSED if ok else FAILED, worst=worst, bound=1.0,
                       counterexample=counter, message=msg, details=details)


def check_convergence_order(stepper: Callable, problem: Problem, steps=None, executor=None) -> CheckResult:
    """Whether ``stepper`` reaches the order it must on ``problem`` (one record, study in ``details``): the
    reference's stated order (exact at the nodes where it is) for the proximal scheme; for a scheme
    claiming only ``scheme="any"`` with order ``p``, ``min(p, problem.order.regularity)``."""
    if steps is not None:   # explicit step sizes stand in for the problem's own
        return _run(_convergence_order.law, stepper, problem, steps, executor, stepper=stepper,
                    problem=problem.replace(steps=list(steps)))
    return _run(_convergence_order.law, stepper, problem, steps, executor, stepper=stepper, problem=problem)
