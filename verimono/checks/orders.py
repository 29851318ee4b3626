"""The convergence order of a stepper on a problem with its expected order (Theorem ``thm:main`` and each
reference's stated order).

``check_convergence_order(stepper, problem)`` runs a :func:`verimono.core.convergence.convergence_study` and
turns its verdict into a record: ``worst = expected / (upper end of the interval + slack)`` and
``bound = 1``, so the stepper passes when its measured order can reach the expected one.  For references
on which the scheme is exact at the nodes, ``worst = max error / round-off floor``.  The study is kept in
the record (``details["study"]``).

A problem without an exact solution is measured against a fine-grid solution of the same stepper: that is
self-convergence, which a scheme converging to a wrong limit (an input or a field dropped) passes.  So the
limit is checked too (:func:`limit_agreement`): on the study's finest grid the stepper and
:func:`verimono.solve` — the proximal scheme, whose limit is the solution (Theorem ``thm:main``) — must agree
within ``LIMIT_FACTOR`` times the sum of their estimated errors there.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from ..core.claims import claim_of
from ..core.convergence import ORDER_SLACK, _timed_run, convergence_study, study_grids
from ..core.grids import uniform_grid
from ..core.problem import Order, Problem, origin_of
from ..records.results import FAILED, PASSED
from ..core.stepping import solve
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


#: the stepper's and verimono.solve's solutions on the finest grid may differ by this many times the sum of
#: their estimated errors there: each estimate is against a solution 8x finer, which underestimates the true
#: error by at most 1/(1 - 8^-p) (1.5x at the catalog's lowest order 1/2), and error constants vary by up to
#: 2x between the grids of a study
LIMIT_FACTOR = 4.0


def limit_agreement(stepper: Callable, study: Any, problem: Problem) -> tuple[bool, str, dict]:
    """Whether ``stepper`` converges to the limit of :func:`verimono.solve` on ``problem`` (see the module
    docstring): their sup distance on the finest grid of ``study`` against ``LIMIT_FACTOR`` times the sum of
    their estimated errors there (each from its own study on the same grids), plus both round-off floors."""
    grids = study_grids(problem.T, problem.steps)
    k = int(np.argmin(study.mesh))
    grid = grids[k]
    ref = convergence_study(solve, problem, grids)
    ours, _ = _timed_run(stepper, problem, grid)
    theirs, _ = _timed_run(solve, problem, grid)
    e_ours, e_ref = float(study.errors["sup"][k]), float(ref.errors["sup"][k])
    bound = LIMIT_FACTOR * (e_ours + e_ref) + study.floor + ref.floor
    gap = float(np.max(np.linalg.norm((ours - theirs).reshape(len(grid), -1), axis=1)))
    info = {"distance": gap, "bound": bound, "stepper_error": e_ours, "solve_error": e_ref, "steps": len(grid) - 1}
    if gap <= bound:
        return True, f"its limit agrees with verimono.solve's (distance {gap:.3g} ≤ {bound:.3g} on K = {len(grid) - 1})", info
    return False, (f"converges, but not to the solution: on K = {len(grid) - 1} it is {gap:.3g} from verimono.solve "
                   f"(the proximal scheme, whose limit is the solution), more than {LIMIT_FACTOR:g} x the two "
                   f"estimated errors {e_ours:.3g} + {e_ref:.3g}: self-convergence alone does not show the limit"), info


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
    try:
        study = convergence_study(stepper, problem if exp is problem.order else problem.replace(order=exp),
                                  problem.steps, executor=executor)
    except NotImplementedError as exc:
        refused = _refuses_fine_grids(stepper, problem, exc)
        if refused is None:
            raise                   # not even the coarsest grid: not available here (skipped, as before)
        return refused
    ok, msg = study.verdict()
    fit = study.order
    if exp.exact:
        worst = max(study.errors["sup"]) / study.floor
    elif fit.exact:
        worst = 0.0
    else:
        worst = exp.value / (fit.high + ORDER_SLACK) if fit.high == fit.high else float("inf")
    details = {"study": study, "reproduce_python": reproduction_script(problem)}
    if ok and problem.exact is None and getattr(stepper, "fn", stepper) is not solve:
        ok, why, details["limit"] = limit_agreement(stepper, study, problem)
        msg = f"{msg}; {why}"
        if not ok:
            worst = max(worst, details["limit"]["distance"] / details["limit"]["bound"])
    if not claim_of(stepper).proximal:
        details["expected"] = {"order": exp.value, "source": exp.source}
    # the study's verdict decides; the ratio says by how much
    return Outcome(worst, details=details, message=msg, status=PASSED if ok else FAILED,
                   counter={} if ok else {"steps": study.mesh, "errors": study.errors["sup"], "message": msg})


def _refuses_fine_grids(stepper: Callable, problem: Problem, exc: NotImplementedError) -> Outcome | None:
    """The failed outcome of a stepper that runs the study's coarsest grid but raised ``exc``
    (NotImplementedError) on a finer one — convergence is a statement about every partition as ``h → 0``, so
    it cannot be shown, and such a stepper was reported ok (its order record skipped, the stage passed) —
    or ``None`` when the coarsest grid raises too (the stepper does not run this problem at all)."""
    h = max(problem.steps)
    try:
        stepper(problem, uniform_grid(problem.T, h))
    except NotImplementedError:
        return None
    msg = (f"the stepper runs the coarsest grid (h = {h:g}) but raised NotImplementedError on a finer one of the "
           f"study (h = {', '.join(f'{s:g}' for s in problem.steps)}): {exc}; convergence is a statement about every "
           "partition as h → 0, so a stepper that refuses fine grids cannot be shown to converge")
    return Outcome(math.inf, details={"refused_grids": f"NotImplementedError: {exc}"}, message=msg, status=FAILED,
                   counter={"steps": list(problem.steps), "message": msg})


def reproduction_script(problem: Problem) -> str:
    """Python that reruns the order check with ``stepper`` bound: the problem from the reference catalog by
    name, from the ``MODULE:OBJECT`` it was loaded from (:func:`verimono.core.problem.origin_of`), or else a line
    the user completes with their own problem."""
    from ..reference import names

    name = subject_name(problem)
    lines = ["from verimono.checks.orders import check_convergence_order"]
    origin = origin_of(problem)
    if name in names():
        lines += ["from verimono.reference import get", f"problem = get({name!r})"]
    elif origin:
        lines += ["from verimono.run.targets import load_target", f"problem = load_target({origin!r})"]
    else:
        lines += [f"problem = ...   # the Problem {name!r} you checked (it is not in verimono's reference catalog)"]
    return "\n".join(lines + ["print(check_convergence_order(stepper, problem))"])


__all__ = ["check_convergence_order", "limit_agreement", "reproduction_script", "LIMIT_FACTOR"]
