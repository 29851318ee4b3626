"""The battery of a stepper: its convergence orders on the references, then every trajectory law on every
problem (scikit-learn's ``check_estimator``).

:func:`stepper_checks` yields ``(name, check)`` pairs, ``name = "<law>[<problem>]"`` — the one source of
:func:`check_stepper`, of :func:`verimono.testing.parametrize_with_checks` and of the stepper stages of
``verimono run``.
"""

from __future__ import annotations

from typing import Any, Callable, Iterable, Iterator, Sequence

import numpy as np

from ..core.adaptive import Adaptive
from ..core.claims import with_claim
from ..core.errors import InvalidCheckArgument
from ..core.problem import Problem
from ..records.results import CheckResult, Report
from ..execution.timeouts import run_unit
from . import bounds, limits, picard, trajectory_laws  # noqa: F401 - the laws join the registry on import
from . import orders as _order_law  # noqa: F401 - convergence_order joins the registry on import
from ..execution.config import chosen, current
from ..execution.executors import Unit
from ..execution.heap import heap_kept
from ..execution.workers import blas_limited
from .core import laws_of, stepper_subject
from .isolated import isolating, run_check, run_isolated
from .own_steps import check_adaptive
from .partitions import single
from .generated_problems import generated_problems
from .sample_problems import valid_count
from .arguments import valid_executor, valid_flag, valid_laws, valid_problems, valid_seed, valid_step_range
from .shared_runs import shared_runs
from .subjects import require_problem, require_stepper

#: the law judging the order a stepper reaches on a reference (on the references only)
ORDER_LAW = "convergence_order"
#: the trajectory laws of the battery, in the order they run (on every problem)
LAWS: tuple[str, ...] = tuple(n for n in laws_of("stepper", battery=True) if n != ORDER_LAW)
#: law name → its public check ``check(stepper, problem, ...)``
CHECKS: dict[str, Callable[..., CheckResult]] = {n: laws_of("stepper")[n].public for n in LAWS}


def reproduce(stepper: Callable, problem: Problem, record: CheckResult) -> CheckResult:
    """Re-run the law of ``record`` on exactly the inputs of its counterexample."""
    cx = record.counterexample or {}
    law = CHECKS[record.check]
    if record.check == "unique_limit":
        return law(stepper, problem, levels=cx["levels"], seed=cx["seed"])
    p = single(problem).replace(T=float(cx["T"]))
    # a law of several calls (trajectory_immutable) states all its partitions, a per-partition law its one
    grids = cx["grids"] if isinstance(cx.get("grids"), list) else [cx["grid"]]
    kw: dict[str, Any] = {"grids": [np.asarray(g, dtype=float) for g in grids]}
    if "x0_prime" in cx:
        kw["x0_primes"] = [np.asarray(cx["x0_prime"], dtype=float)]
    return law(stepper, p, **kw)


def generated_count(generated: object = None) -> int:
    """``generated`` as a number of generated problems (:func:`valid_count`); ``None``: the current profile's
    ``generated_subjects`` (:mod:`verimono.execution.profiles`; 3 for a profile of the user's own)."""
    if generated is None:
        effort = current().effort
        return 3 if effort is None else int(effort.generated_subjects)
    return valid_count(generated)


def _selected(laws: Sequence[str]) -> tuple[str, ...]:
    unknown = [n for n in laws if n not in CHECKS]
    if unknown:
        raise InvalidCheckArgument(f"unknown trajectory laws {unknown}; the laws are {list(CHECKS)}")
    return tuple(laws)


def law_checks(problems: Iterable[Problem], laws: Sequence[str] = LAWS, seed: int = 0
               ) -> Iterator[tuple[str, Callable[[Callable], CheckResult]]]:
    """``(name, check)`` pairs: ``name = "<law>[<problem>]"``, ``check(stepper) -> CheckResult``."""
    laws = _selected(laws)
    for p in problems:
        for law in laws:
            fn = CHECKS[law]
            yield f"{law}[{p.name}]", (lambda stepper, _fn=fn, _p=p: _fn(stepper, _p, seed=seed))


def stepper_checks(stepper: Callable | None = None, problems: Iterable[Problem] | None = None, *,
                   seed: int = 0, generated: int | None = None, laws: Sequence[str] = LAWS, orders: bool = True,
                   executor: Any = None, step_range: Sequence[float] | None = None
                   ) -> Iterator[tuple[str, Callable[[Callable], CheckResult]]]:
    """The battery of a stepper, as ``(name, check)`` pairs.

    ``problems=None``: the reference catalog (convergence orders and laws) plus ``generated`` problems drawn
    from the seed (:func:`verimono.checks.generated_problems.generated_problems`, laws only; ``None``: the
    current profile's ``generated_subjects``, :func:`generated_count`).  ``stepper`` is unused
    (the battery does not depend on it); it is accepted for the protocol ``stepper_checks(stepper)``.
    ``step_range = (h_min, h_max)`` confines every convergence study to those steps
    (:func:`verimono.convergence_study`).
    """
    seed = valid_seed(seed)
    generated = generated_count(generated)
    orders = valid_flag(orders, "orders")
    step_range = valid_step_range(step_range)
    executor = valid_executor(executor)
    problems = valid_problems(problems, "stepper_checks")
    if problems is None:
        from verimono.reference import catalog   # the catalog builds every reference: on first use only

        refs = catalog()
        extra = generated_problems(seed, generated)
    else:
        refs, extra = [require_problem(p) for p in problems], []
    if orders:
        order = laws_of("stepper")[ORDER_LAW].check
        for p in refs:
            yield f"{ORDER_LAW}[{p.name}]", (lambda s, _p=p: order(s, _p, executor=executor, step_range=step_range))
    yield from law_checks(list(refs) + list(extra), laws, seed)


def _largest_dim(problems: Iterable[Any]) -> int:
    """The largest number of coordinates of the problems' initial states (0 for none, or the catalog's: small)."""
    try:
        return max((int(np.size(getattr(p, "x0", ()))) for p in problems or ()), default=0)
    except Exception:   # noqa: BLE001 - an initial state without a size: nothing is kept
        return 0


def check_stepper(stepper: Callable, problems: Iterable[Problem] | None = None, *, scheme: str | None = None,
                  order: float | None = None, seed: int | None = None, executor: Any = None,
                  laws: bool | Iterable[str] = True, generated: int | None = None, orders: bool = True,
                  profile: str | None = None, step_range: Sequence[float] | None = None) -> Report:
    """Result records for ``stepper``: convergence orders on the references, then the trajectory laws.

    ``scheme``/``order`` state what the stepper claims (:class:`verimono.Stepper`; a bare callable
    claims ``scheme="proximal"``, the paper's scheme): a law that needs more than the claim is skipped
    with that reason, and ``convergence_order``/``in_domain`` hold an ``"any"`` scheme to its order.

    ``problems=None`` means the whole catalog of :mod:`verimono.reference` (orders and laws) plus
    ``generated`` problems drawn from ``seed`` (laws only; ``None``: the profile's ``generated_subjects`` —
    ``dev`` 3, ``ci`` 6, ``thorough`` 30): :mod:`verimono.checks.generated_problems`, whose records name the
    recipe ``generated #i (seed s)``, rebuilt by ``generated_problem(s, i)``.  The records come first per
    problem for the convergence orders (in the order of ``problems``), then one record per (problem, law);
    ``laws=False`` keeps the orders only, a list of law names selects laws, ``orders=False`` keeps the laws
    only.  What is not a stepper, a bad seed or an empty selection is refused before anything runs
    (:class:`verimono.InvalidCheckArgument`).  The convergence studies choose their grids for the claimed order
    (:mod:`verimono.core.grid_design`); ``step_range = (h_min, h_max)`` confines them to those step sizes.

    Every check runs under the unit time budget (:mod:`verimono.execution.timeouts`).  ``executor`` runs the
    convergence studies' grids (a ``concurrent.futures`` executor, ``"process"`` or ``"serial"``,
    :func:`verimono.convergence_study`) — except ``executor="process:N"``: then every check runs in one of
    ``N`` worker processes (:mod:`verimono.checks.isolated`), the only way the Python API bounds a stepper
    that blocks in native code (``os.system``, a C extension), which the budget's interrupt cannot stop: its
    worker ends, the check is a failed record naming the call, and the battery goes on.  In this process
    verimono never ends the interpreter on such a call: it warns once and waits for it to return
    (:mod:`verimono.execution.watchdog`).  ``profile`` (``"dev"``, ``"ci"``, ``"thorough"``) chooses the time
    budget of each check, as ``--profile`` does for ``verimono check``; by default the current run
    configuration's (:mod:`verimono.execution.config`).  In this process the BLAS libraries loaded when the
    battery begins run on one thread, as under the command line, and get the caller's limits back after
    (:func:`verimono.execution.workers.blas_limited`).

    A :class:`verimono.Adaptive` stepper (it takes a tolerance, not a grid) gets its own battery,
    :func:`verimono.check_adaptive`, on ``problems``.
    """
    if profile is not None:
        with chosen(profile):
            return check_stepper(stepper, problems, scheme=scheme, order=order, seed=seed, executor=executor,
                                 laws=laws, generated=generated, orders=orders, step_range=step_range)
    if isinstance(stepper, Adaptive):    # it chooses its own steps: a grid's study would call it wrongly
        return check_adaptive(stepper, problems, laws=laws is not False)
    require_stepper(stepper)
    # every argument before the first call of the stepper: what the harness was given is never charged to it
    problems = valid_problems(problems)
    given, stepper = stepper, with_claim(stepper, scheme, order)
    seed = 0 if seed is None else valid_seed(seed)
    generated = generated_count(generated)
    orders = valid_flag(orders, "orders")
    step_range = valid_step_range(step_range)
    executor = valid_executor(executor)
    laws = valid_laws(laws)
    selected = () if laws is False else (LAWS if laws is True else _selected(laws))
    if not selected and not orders:
        raise InvalidCheckArgument("check_stepper selected no check (no law, no order): it would verify nothing")
    report = Report()
    isolate = isolating(executor)
    checks = list(stepper_checks(stepper, problems, seed=seed, generated=generated, laws=selected,
                                 orders=orders, executor=None if isolate else executor, step_range=step_range))
    if isolate:   # every check in a worker process: one blocked in native code ends only its worker
        units = [Unit("check_stepper", name, run_check,
                      (check, stepper, name.partition("[")[0], stepper_subject(stepper, name.partition("[")[2][:-1])))
                 for name, check in checks]
        records = [rec for rep in run_isolated(executor, units, given) for rec in rep.results]
    else:
        # the laws judge the same runs of the stepper: each is made once; BLAS as under the command line
        # above LARGE_N coordinates glibc keeps the blocks the laws free (execution.heap: no page faults again)
        with shared_runs(), blas_limited(), heap_kept(_largest_dim(problems)):
            # a stepper that never returns: a failed record naming the unit, and the battery goes on
            records = [run_unit(lambda: check(stepper), check=name.partition("[")[0],
                                subject=stepper_subject(stepper, name.partition("[")[2][:-1]))
                       for name, check in checks]
    for rec in records:
        report.add(rec)
        if rec.study is not None:
            report.studies.append(rec.study)
    if not len(report):
        raise InvalidCheckArgument("check_stepper selected no check (no law, no order): it would verify nothing")
    return report


__all__ = ["LAWS", "CHECKS", "ORDER_LAW", "stepper_checks", "check_stepper", "law_checks", "reproduce",
           "generated_count"]
