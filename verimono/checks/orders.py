"""Convergence-order checks of a stepper against the analytic references.

``check_convergence_order(stepper, problem)`` runs a :func:`verimono.convergence.convergence_study` and
turns its verdict into a result record: ``worst = expected / (upper end of the interval + slack)`` and
``bound = 1``, so the stepper passes when its measured order can reach the expected one.  For references
on which the scheme is exact at the nodes, ``worst = max error / round-off floor``.
"""

from __future__ import annotations

from typing import Callable, Iterable

from ..claims import claim_of, with_claim
from ..convergence import ORDER_SLACK, convergence_study, _name
from ..problem import Order, Problem
from ..results import FAILED, PASSED, CheckResult, Report
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
    study = convergence_study(stepper, problem if exp is problem.order else with_order(problem, exp), steps,
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
    details = {"study": study.to_dict()}
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
                    problem=with_steps(problem, steps))
    return _run(_convergence_order.law, stepper, problem, steps, executor, stepper=stepper, problem=problem)


def with_order(problem: Problem, order: Order) -> Problem:
    from .trajectory_laws import with_changes

    return with_changes(problem, order=order)


def with_steps(problem: Problem, steps) -> Problem:
    from .trajectory_laws import with_changes

    return with_changes(problem, steps=list(steps))


def check_stepper(stepper: Callable, problems: Iterable[Problem] | None = None, *, scheme: str | None = None,
                  order: float | None = None, seed: int | None = None, executor=None,
                  laws: bool | Iterable[str] = True, generated: int = 4, orders: bool = True) -> Report:
    """Result records for ``stepper``: convergence orders on the references, then the trajectory laws.

    ``scheme``/``order`` state what the stepper claims (:class:`verimono.Stepper`; a bare callable
    claims ``scheme="proximal"``, the paper's scheme): a law that needs more than the claim is skipped
    with that reason, and ``convergence_order``/``in_domain`` hold an ``"any"`` scheme to its order.

    ``problems=None`` means the whole catalog of :mod:`verimono.reference` (orders and laws) plus
    ``generated`` seeded sample problems (laws only).  The records come first per problem for the
    convergence orders (in the order of ``problems``), then one record per (problem, law) of
    :mod:`verimono.checks.trajectory_laws`; ``laws=False`` keeps the orders only, a list of law names
    selects laws, ``orders=False`` keeps the laws only.  The records are those of :func:`verimono.checks.trajectory_laws.stepper_checks`,
    the same generator :func:`verimono.testing.parametrize_with_checks` turns into pytest cases.
    """
    from .trajectory_laws import LAWS, stepper_checks

    stepper = with_claim(stepper, scheme, order)
    seed = 0 if seed is None else int(seed)
    selected = () if laws is False else (LAWS if laws is True else tuple(laws))
    report = Report()
    for _name_, check in stepper_checks(stepper, problems, seed=seed, generated=generated, laws=selected,
                                        orders=orders, executor=executor):
        rec = check(stepper)
        report.add(rec)
        if "study" in rec.details:
            from ..convergence import ConvergenceStudy

            report.studies.append(ConvergenceStudy.from_dict(rec.details["study"]))
    return report
