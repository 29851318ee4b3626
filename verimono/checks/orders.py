"""The convergence order of a stepper on a problem with its expected order (Theorem ``thm:main`` and each
reference's stated order).

``check_convergence_order(stepper, problem)`` runs a :func:`verimono.core.convergence.convergence_study` — which
chooses its grids for the scheme (coarser for a high-order one, finer when the finest refinement falls short) and
honours the stepper's claim — and turns its verdict (:mod:`verimono.core.verdicts`) into a record: passed, failed,
or *undecided* (no asymptotic range above the floor within the study's budget, a floor the user did not state),
with ``worst = expected / (upper end of the interval + slack)`` and ``bound = 1``.  For references on which the
scheme is exact at the nodes, ``worst = max error / round-off floor``.  The study is kept in the record
(``details["study"]``); ``steps`` or ``step_range`` choose the grids for a user who knows better.

A problem without an exact solution is measured against a fine-grid solution of the same stepper: that is
self-convergence, which a scheme converging to a wrong limit (an input or a field dropped) passes.  So the
limit is checked too (:func:`verimono.checks.agreement.limit_agreement`): the stepper's limit and that of
:func:`verimono.solve` — the proximal scheme, whose limit is the solution (Theorem ``thm:main``) — each
estimated from its own 4-fold refinements, must be within the law's resolution of each other (passed), or are
provably apart (failed), or the levels cannot tell (undecided, never a pass).
"""

from __future__ import annotations

import math
from typing import Any, Callable

from ..core.claims import claim_of
from ..core.convergence import convergence_study, expected_order
from ..core.errors import InvalidProblem
from ..core.grid_design import cells_range
from ..core.grids import uniform_grid
from ..core.problem import Problem, origin_of
from ..records.results import FAILED, PASSED, UNDECIDED
from ..core.stepping import solve
from .agreement import limit_agreement
from .core import Outcome, law, subject_name
from .partitions import run_once
from .shared_runs import note_partitions


#: the step sizes of a study on a problem that states none, as fractions of ``T`` (the study adds coarser and finer
#: grids as its verdict asks, :mod:`verimono.core.grid_design`)
DEFAULT_STEPS = (1 / 10, 1 / 20, 1 / 40, 1 / 80)


def default_steps(p: Problem) -> list[float]:
    """The problem's recommended step sizes, or :data:`DEFAULT_STEPS` of its horizon: every problem is studied
    (issue 40: a problem without an exact solution against a fine-grid reference, at the order the stepper
    claims or the theorem gives, never a silent skip)."""
    return list(p.steps) if p.steps else [p.T * f for f in DEFAULT_STEPS]


def run_order(decl: Any, stepper: Callable, problem: Problem, steps: Any = None, executor: Any = None,
              step_range: Any = None) -> Any:
    """The order law on ``problem``: on the grids the study chooses, or exactly on ``steps`` (step sizes or
    grids), or within ``step_range = (h_min, h_max)``."""
    kw = {k: v for k, v in (("steps", steps), ("step_range", step_range)) if v is not None}
    return run_once(decl, stepper, problem, executor=executor, **kw)


@law("convergence_order", "thm:main (convergence) and each reference's stated order", subject="stepper",
     driver=run_order)
def check_convergence_order(stepper: Callable, problem: Problem, *, executor: Any = None, steps: Any = None,
                            step_range: Any = None) -> Outcome:
    """Whether ``stepper`` reaches the order it must on ``problem`` (one record, study in ``details``): the
    reference's stated order (exact at the nodes where it is) for the proximal scheme; for a scheme
    claiming ``scheme="any"`` with order ``p``, ``min(p, problem.order.regularity)``.

    The study chooses its grids for the scheme from the problem's recommended steps
    (:mod:`verimono.core.grid_design`); ``steps`` are run exactly as given, ``step_range = (h_min, h_max)``
    confines it to those steps.  Its verdict (:mod:`verimono.core.verdicts`) may be *undecided*: no asymptotic
    range above the floor within the budget, a floor the user did not state (the message says what to do).

    A proximal scheme stating an inexact resolvent, ``ε(h) = C h^q``, must reach ``min(p, q − 1)``
    (:func:`verimono.core.convergence.inexact_order`); with ``q ≤ 1`` its claim allows errors that never vanish
    and the law fails before the stepper runs: the claim is the subject's, and it contradicts convergence."""
    exp = expected_order(stepper, problem)
    inexact = claim_of(stepper).inexact
    if inexact is not None and not exp.value > 0.0:
        # the claim itself rules convergence out: K = T/h steps may accumulate Σε_k = C T h^(q-1), which does
        # not vanish for q <= 1 (verimono.core.convergence.inexact_order) — the proximal scheme claims to converge
        msg = (f"the stated resolvent tolerance ε(h) = {inexact.describe()} (q = {inexact.exponent(problem.T):g}) "
               f"lets K = T/h steps accumulate Σε_k ~ h^{exp.value:g}, which does not vanish: no convergence follows "
               "from the claim (the proximal scheme converges, thm:main; its resolvent must be exact to ε(h) = o(h), "
               "q > 1)")
        return Outcome(math.inf, details={"expected": {"order": exp.value, "source": exp.source}}, message=msg,
                       status=FAILED, counter={"inexact": inexact.describe(), "message": msg})
    if step_range is not None:
        try:
            cells_range(problem.T, step_range)
        except InvalidProblem as exc:       # a range that fits this problem's horizon no study: nothing decided
            return Outcome(None, message=f"not studied: {exc}", status=UNDECIDED)
    try:
        study = convergence_study(stepper, problem, steps if steps is not None or step_range is not None or problem.steps
                                  else default_steps(problem), step_range=step_range, executor=executor,
                                  adapt=steps is None and step_range is None)
    except NotImplementedError as exc:
        refused = _refuses_fine_grids(stepper, problem, exc)
        if refused is None:
            raise                   # not even the coarsest grid: not available here (skipped)
        return refused
    # the study's runs are partitions the battery computed: the step laws judge the stepper on its finest and on
    # those where its errors fell short
    note_partitions(stepper, problem, study.step_law_grids())
    decision = study.decision()
    ok, msg, worst = decision.ok, decision.message, decision.worst
    details = {"study": study, "reproduce_python": reproduction_script(problem)}
    limit = None
    if ok and problem.exact is None and getattr(stepper, "fn", stepper) is not solve:
        limit, why, details["limit"] = limit_agreement(stepper, study, problem)
        msg = f"{msg}; {why}"
        ok = limit == PASSED
        if limit == FAILED:
            worst = max(worst, details["limit"]["distance"] / details["limit"]["bound"])
    if not claim_of(stepper).proximal or inexact is not None:
        details["expected"] = {"order": exp.value, "source": exp.source}
    if study.added:         # the cells of the grids the study chose itself (coarser, finer)
        details["grids_added"] = [study.steps[i] for i in study.added]
    status = PASSED if ok else (UNDECIDED if UNDECIDED in (decision.status, limit) else FAILED)
    # the study's verdict decides; the ratio says by how much
    return Outcome(worst, details=details, message=msg, status=status,
                   counter={} if ok else {"steps": study.mesh, "errors": study.errors["sup"], "message": msg})


def _refuses_fine_grids(stepper: Callable, problem: Problem, exc: NotImplementedError) -> Outcome | None:
    """The failed outcome of a stepper that runs the study's coarsest grid but raised ``exc``
    (NotImplementedError) on a finer one — convergence is a statement about every partition as ``h → 0``, so
    it cannot be shown, and such a stepper was reported ok (its order record skipped, the stage passed) —
    or ``None`` when the coarsest grid raises too (the stepper does not run this problem at all)."""
    h = max(default_steps(problem))
    try:
        stepper(problem, uniform_grid(problem.T, h))
    except NotImplementedError:
        return None
    msg = (f"the stepper runs the coarsest grid (h = {h:g}) but raised NotImplementedError on a finer one of the "
           f"study (h = {', '.join(f'{s:g}' for s in default_steps(problem))}): {exc}; convergence is a statement about every "
           "partition as h → 0, so a stepper that refuses fine grids cannot be shown to converge")
    return Outcome(math.inf, details={"refused_grids": f"NotImplementedError: {exc}"}, message=msg, status=FAILED,
                   counter={"steps": default_steps(problem), "message": msg})


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


__all__ = ["check_convergence_order", "limit_agreement", "reproduction_script"]
