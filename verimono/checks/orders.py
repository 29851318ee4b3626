"""The convergence order of a stepper on a problem with its expected order (Theorem ``thm:main`` and each
reference's stated order).

``check_convergence_order(stepper, problem)`` runs a :func:`verimono.convergence.convergence_study` and
turns its verdict into a record: ``worst = expected / (upper end of the interval + slack)`` and
``bound = 1``, so the stepper passes when its measured order can reach the expected one.  For references
on which the scheme is exact at the nodes, ``worst = max error / round-off floor``.  The study is kept in
the record (``details["study"]``).
"""

from __future__ import annotations

from typing import Any, Callable

from ..claims import claim_of
from ..convergence import ORDER_SLACK, convergence_study
from ..problem import Order, Problem
from ..results import FAILED, PASSED
from .core import Holds, Outcome, law, subject_name
from .partitions import run_once


def _expected(stepper: Callable, problem: Problem) -> Order | None:
    """The order ``stepper`` must reach on ``problem``: the reference's order for the proximal scheme,
    ``min(claimed, regularity)`` for a scheme claiming only ``scheme="any"`` (:meth:`Order.for_claim`)."""
    claim = claim_of(stepper)
    if claim.proximal:
        return problem.order
    if problem.order is None:
        return Order(claim.order, "the claimed order (the problem states no regularity)")
    return problem.order.for_claim(claim.order)


def _states_order(p: Problem) -> str | None:
    return None if p.order is not None and p.steps else "the problem states no expected order or no step sizes"


def run_order(decl: Any, stepper: Callable, problem: Problem, steps: Any = None, executor: Any = None) -> Any:
    """The order law on ``problem`` (``steps``, step sizes or grids, stand in for the problem's own)."""
    if steps is not None:
        problem = problem.replace(steps=list(steps))
    return run_once(decl, stepper, problem, executor=executor)


@law("convergence_order", "thm:main (convergence) and each reference's stated order", subject="stepper",
     driver=run_order, requires=(Holds(_states_order),))
def check_convergence_order(stepper: Callable, problem: Problem, *, executor: Any = None) -> Outcome:
    """Whether ``stepper`` reaches the order it must on ``problem`` (one record, study in ``details``): the
    reference's stated order (exact at the nodes where it is) for the proximal scheme; for a scheme
    claiming only ``scheme="any"`` with order ``p``, ``min(p, problem.order.regularity)``."""
    exp = _expected(stepper, problem)
    study = convergence_study(stepper, problem if exp is problem.order else problem.replace(order=exp),
                              problem.steps, executor=executor)
    ok, msg = study.verdict()
    fit = study.order
    if exp.exact:
        worst = max(study.errors["sup"]) / study.floor
    elif fit.exact:
        worst = 0.0
    else:
        worst = exp.value / (fit.high + ORDER_SLACK) if fit.high == fit.high else float("inf")
    script = ("from verimono.reference import get\n"
              "from verimono.checks.orders import check_convergence_order\n"
              f"print(check_convergence_order(stepper, get({subject_name(problem)!r})))")
    details = {"study": study, "reproduce_python": script}
    if not claim_of(stepper).proximal:
        details["expected"] = {"order": exp.value, "source": exp.source}
    # the study's verdict decides; the ratio says by how much
    return Outcome(worst, details=details, message=msg, status=PASSED if ok else FAILED,
                   counter={} if ok else {"steps": study.mesh, "errors": study.errors["sup"], "message": msg})


__all__ = ["check_convergence_order"]
