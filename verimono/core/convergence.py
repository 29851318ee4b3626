"""Convergence studies: errors of a stepper on grids it chooses for the scheme, and a verdict on its order.

``convergence_study(stepper, problem)`` measures the errors of ``stepper`` on a sequence of grids against the
exact solution (or a fine-grid solution of the same stepper, which it says), fits the order in three norms
(:mod:`verimono.core.order_fit`) and decides whether the stepper reaches the order it must
(:mod:`verimono.core.verdicts`).  The jobs are:

* **the order it must reach** (:func:`expected_order`) — the reference's stated order for the proximal scheme; for a
  stepper claiming ``scheme="any", order=p``, ``min(p, the order the solution's regularity allows)``: a claim is
  honoured everywhere, so an order-1 scheme claimed as order 5 is measured against 5 and reported as "order 1.00
  measured, 5 claimed";
* **its grids** (:mod:`verimono.core.grid_design`) — it starts from the problem's recommended steps and, when the
  verdict asks, coarsens (a high-order scheme at round-off on them) or refines (a finest refinement falling
  short, a pre-asymptotic regime from below), within a budget or a ``step_range`` the user gives;
* **the floor** — round-off, ``ROUNDOFF_FACTOR · ε · scale`` in the precision the stepper computes in
  (:func:`verimono.core.tolerances.roundoff_floor`), plus, for a stepper that states the accuracy ``τ`` of its
  inner solve (``Stepper(..., solve_tol=τ)``), what ``K`` inexact steps of a nonexpansive scheme can accumulate,
  ``K τ (1 + scale)`` (:func:`solve_floor`); errors at the floor are not fitted;
* **running the grids** (:mod:`verimono.core.study_runs`) — as independent jobs, serially or in parallel, without
  holding trajectories;
* **the verdict** (:mod:`verimono.core.verdicts`) — passed, failed or *undecided* (a limit of the study: no
  asymptotic range above the floor within the budget, a floor the user did not state), with the message a
  numerical analyst would sign.

``docs/convergence.md`` tells the whole story with examples.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from typing import Any, Callable, Sequence

import numpy as np

from ._jsonable import to_jsonable
from ._validate import refinement_of, step_range_of, study_executor
from .claims import _solve_tol, claim_of
from .display import render
from .errors import InvalidClaim, InvalidProblem
from .grid_design import GridPlan, MIN_GRIDS
from .naming import subject_name
from .order_fit import ASYMPTOTIC_SPREAD, ORDER_SLACK, OrderFit, fit_order, least_squares_slope
from .problem import Order, Problem
from .study_runs import (NORMS, PARALLEL_MIN_STEPS, ErrorAccumulator, GridRunner, Sampler, _timed_run, exact_on,
                         grid_errors, study_grids)
from .tolerances import ROUNDOFF_STEPS, coarser, observe, roundoff_floor
from .verdicts import (FAILED, PASSED, STALL_FRACTION, STALL_MARGIN, UNDECIDED, Decision, StudyData, decide,
                       shortfall_grids)

#: errors below ROUNDOFF_FACTOR * eps * (1 + max|x|) are round-off (≈ 2e-12 for unit-size states):
#: a K-step scheme accumulates O(K eps) rounding, and K ≤ 1e4 in the catalog's studies.  A stepper computing
#: in a coarser precision (observed from its states) gets that precision's floor,
#: :func:`verimono.core.tolerances.roundoff_floor` (float32: 1.2e-5)
ROUNDOFF_FACTOR = ROUNDOFF_STEPS


def solve_floor(steps: int, solve_tol: float, scale: float) -> float:
    """What ``steps`` inner solves of accuracy ``solve_tol`` (relative to ``1 + scale``) can add to the error
    of a nonexpansive scheme: each step's error passes through later steps without growing (the
    resolvent is nonexpansive, Proposition ``prop:maxmon-resolvent-Yosida`` ii), so they add up."""
    return float(steps) * float(solve_tol) * (1.0 + float(scale))


#: the order of the proximal scheme on a problem that states none: ``O(h^{1/2})`` for a maximal monotone ``F``
#: and ``x0 ∈ dom F`` (Crandall–Liggett; Rulla, SIAM J. Numer. Anal. 1996; for moving sets with Lipschitz
#: motion, Moreau's catching-up estimate: shared/literature.md), which the paper's setting contains
GENERAL_ORDER = Order(0.5, "the proximal scheme's order for a maximal monotone F with x0 in dom F(0), O(h^(1/2)) "
                           "(Crandall-Liggett; Rulla 1996; Moreau's catching-up): the problem states none")


def expected_order(stepper: Callable, problem: Problem) -> Order | None:
    """The order ``stepper`` must reach on ``problem``: the reference's order for the proximal scheme (on a
    problem that states none, the general :data:`GENERAL_ORDER`),
    ``min(claimed, regularity)`` for a scheme claiming ``scheme="any"`` with an order (:meth:`Order.for_claim`),
    the claim alone where the problem states none."""
    claim = claim_of(stepper)
    if claim.proximal and claim.inexact is not None:
        return inexact_order(claim.inexact, problem)
    if claim.proximal:
        return GENERAL_ORDER if problem.order is None else problem.order
    if problem.order is None:
        return Order(claim.order, "the claimed order (the problem states no regularity)")
    return problem.order.for_claim(claim.order)


def inexact_order(inexact: Any, problem: Problem) -> Order | None:
    """The order of the proximal scheme whose resolvent is within ``ε(h) = C h^q`` of the exact one
    (:class:`verimono.core.claims.Inexact`): ``min(p, q − 1)`` with ``p`` the problem's order for the exact
    scheme (``q − 1`` where it is exact at the nodes).

    Derivation (Rockafellar's criterion (A) accumulated over the steps; /work/shared/literature.md, "Inexact
    resolvents"): write ``x_{k+1} = J_k(z_k) + e_k``, ``|e_k| ≤ ε(h)``, and ``x̂`` for the exact scheme from
    the same ``x0``.  The resolvent is nonexpansive (Proposition ``prop:maxmon-resolvent-Yosida`` ii) and the
    explicit part ``z ↦ z + h f(z)`` grows distances by at most ``1 + hL ≤ e^{hL}``, so
    ``|x_{k+1} − x̂_{k+1}| ≤ e^{hL}|x_k − x̂_k| + ε(h)`` and ``|x_K − x̂_K| ≤ e^{LT} K ε(h) = e^{LT} C T h^{q−1}``
    on ``K = T/h`` steps; with ``|x̂_K − x(T)| = O(h^p)`` the error is ``O(h^p + h^{q−1})``.  The bound is
    attained (a projection stopped ``ε`` short on the same side every step), so nothing better is expected."""
    q = inexact.exponent(problem.T)
    src = (f"the resolvent's stated tolerance ε(h) = {inexact.describe()}: K = T/h steps accumulate Σε_k = O(h^(q-1)), "
           f"q = {q:g} (Rockafellar's criterion (A) summed over the steps; verimono.core.convergence.inexact_order)")
    base = problem.order
    if base is None:
        return Order(q - 1.0, src)
    if base.exact or base.value is None or q - 1.0 < base.value:
        return Order(q - 1.0, src + ("" if base.exact else f", below the exact scheme's {base.value:g} ({base.source})"),
                     regularity=base.regularity, regularity_source=base.regularity_source)
    return dataclasses.replace(base, source=f"{base.source}; within the stated tolerance's order q - 1 = {q - 1:g}")


@dataclasses.dataclass
class ConvergenceStudy:
    """Errors of a stepper on a sequence of grids, the fitted orders and the verdict (module docstring).

    ``fits`` are on the grids the verdict rests on (:meth:`decision`'s window: the usable grids after the last
    shortfall, at most the finest five); ``added`` lists the grids the study chose itself, ``refined`` how many
    times it refined beyond the grids it was given; ``claimed`` is the stepper's claimed order, if any."""

    problem: str
    stepper: str
    mesh: list[float]
    steps: list[int]
    errors: dict[str, list[float]]
    fits: dict[str, OrderFit]
    expected: Order | None
    reference: str
    floor: float
    timings: list[float]
    #: the floor of each grid (round-off plus what a stated inner-solve tolerance accumulates); ``None``:
    #: ``floor`` on every grid
    floors: list[float] | None = None
    #: the accuracy of its inner solve the stepper stated, if any
    solve_tol: float | None = None
    #: the scale of the solution, ``max(1, max |x(t_k)|)`` (the floors are relative to it)
    scale: float = 1.0
    #: the order the stepper claims (``scheme="any"``), if any
    claimed: float | None = None
    #: indices of the grids the study added itself (coarser, finer), in the order of ``mesh``
    added: list[int] = dataclasses.field(default_factory=list)
    #: how many times the study refined beyond the grids it was given
    refined: int = 0
    #: what the stepper raised on a grid the study added: ``[index, "Type: message"]`` pairs
    failures: list[list[Any]] = dataclasses.field(default_factory=list)
    #: the horizon of the problem (the uniform grids of :meth:`grids` are rebuilt from it)
    T: float | None = None

    @property
    def order(self) -> OrderFit:
        """The sup-norm fit, the norm of the paper's convergence result."""
        return self.fits["sup"]

    @property
    def grid_floors(self) -> list[float]:
        """The floor of each grid."""
        return list(self.floors) if self.floors is not None else [self.floor] * len(self.mesh)

    def data(self, *, can_coarsen: bool = False, can_refine: bool = False) -> StudyData:
        """What the verdict is decided from."""
        return StudyData(self.mesh, self.steps, self.errors["sup"], self.grid_floors, self.expected, self.scale,
                         self.solve_tol, self.claimed, self.added, self.refined, can_coarsen, can_refine,
                         {int(i): str(m) for i, m in self.failures})

    def decision(self) -> Decision:
        """The verdict: passed, failed or undecided, with its message (:func:`verimono.core.verdicts.decide`).

        Remembered with the data it was decided from (an attribute, not a field: pickled with the study, never
        in its document) and decided again whenever the data differ: the worker that ran the study decides it
        once, and the command line's process, which writes the report, reads that verdict instead of fitting
        the orders again (and importing ``scipy.special`` for the Student quantile: 0.04-0.08 s of
        ``verimono check``'s report, issue 43 item 3).  ``decide`` is a function of the data alone, so the
        verdict is the same either way; data that do not compare equal (a NaN error, an array) are decided
        afresh."""
        data = self.data()
        memo = self.__dict__.get("_decided")
        if memo is not None:
            try:
                same = bool(memo[0] == data)
            except (ValueError, TypeError):       # arrays in the data: no memo
                same = False
            if same:
                return dataclasses.replace(memo[1], window=list(memo[1].window))
        decision = decide(data)
        # a copy of the data: the study's lists changed in place must not compare equal to the memo
        self.__dict__["_decided"] = (copy.deepcopy(data), dataclasses.replace(decision, window=list(decision.window)))
        return decision

    @property
    def status(self) -> str:
        return self.decision().status

    def verdict(self) -> tuple[bool, str]:
        """Whether the stepper reaches the order it must, with the reason (undecided is not ``True``)."""
        d = self.decision()
        return d.ok, d.message if d.status != UNDECIDED else f"undecided: {d.message}"

    def step_law_grids(self) -> list[np.ndarray]:
        """The grids the step laws should judge the stepper on besides the battery's partitions: the finest (its
        smallest steps) and those where the errors fell short of the order (a pause, a stall) — uniform ones."""
        grids = self.grids()
        keep = {int(np.argmin(self.mesh))} | set(shortfall_grids(self.data()))
        return [grids[i] for i in sorted(keep) if grids[i] is not None]

    def grids(self) -> list[np.ndarray | None]:
        """The study's grids, rebuilt where they were uniform (``None`` for an explicit nonuniform grid, of which
        the study keeps only its cell count and mesh)."""
        T = self.T if self.T is not None else (self.mesh[0] * self.steps[0] if self.steps else 0.0)
        return [np.linspace(0.0, T, k + 1) if math.isclose(h * k, T, rel_tol=1e-9) else None
                for h, k in zip(self.mesh, self.steps)]

    def __repr__(self) -> str:
        """The errors per grid, the fitted orders and the verdict, as a small table."""
        return study_text(self)

    def _repr_html_(self) -> str | None:
        """Jupyter: the report's log-log plot of this study next to its table of errors and orders."""
        return render("study_html", self)

    def plot(self, ax: Any = None) -> Any:
        """The report's log-log plot (errors per norm, fitted slope with its 95% interval, expected slope,
        round-off floor) as a matplotlib ``Figure`` on the Agg canvas, or drawn on ``ax``."""
        return render("study_figure", self, ax)

    def to_dict(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        d["expected"] = None if self.expected is None else dataclasses.asdict(self.expected)
        decision = self.decision()
        d["verdict"], d["status"] = decision.ok, decision.status
        return to_jsonable(d)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "ConvergenceStudy":
        def num(v):
            return float(v) if isinstance(v, str) else v

        fits = {}
        for k, f in d["fits"].items():
            f = dict(f)
            for key in ("slope", "low", "high"):
                f[key] = num(f[key])
            f["local_slopes"] = [num(s) for s in f["local_slopes"]]
            fits[k] = OrderFit(**f)
        exp = None if d.get("expected") is None else Order(**d["expected"])
        floors = d.get("floors")
        return cls(d["problem"], d["stepper"], [num(m) for m in d["mesh"]], list(d["steps"]),
                   {k: [num(x) for x in v] for k, v in d["errors"].items()}, fits, exp, d["reference"],
                   num(d["floor"]), [num(x) for x in d["timings"]],
                   None if floors is None else [num(x) for x in floors], num(d.get("solve_tol")),
                   num(d.get("scale", 1.0)), num(d.get("claimed")), list(d.get("added", [])), int(d.get("refined", 0)),
                   [list(f) for f in d.get("failures", [])], num(d.get("T")))


def study_text(study: Any) -> str:
    """The study as a small table: mesh, steps, each norm's error per grid, the fitted orders, the verdict."""
    norms = list(study.errors)
    head = f"ConvergenceStudy({study.stepper} on {study.problem}; expected order " + \
        ("none stated" if study.expected is None else str(study.expected)) + f"; reference: {study.reference})"
    cols = ["mesh |Δ|", "steps"] + [f"{n} error" for n in norms]
    rows = [[f"{h:.4g}", str(k)] + [f"{float(study.errors[n][i]):.3e}" for n in norms]
            for i, (h, k) in enumerate(zip(study.mesh, study.steps))]
    rows.append(["order", ""] + [str(study.fits[n]) for n in norms])
    widths = [max(len(r[j]) for r in rows + [cols]) for j in range(len(cols))]
    fmt = "  " + "  ".join(f"{{:>{w}}}" for w in widths)
    d = study.decision()
    said = {PASSED: "reaches the expected order", FAILED: "MISSES the expected order",
            UNDECIDED: "UNDECIDED"}[d.status]
    return "\n".join([head, fmt.format(*cols)] + [fmt.format(*r) for r in rows] + [f"  verdict: {said} — {d.message}"])


def convergence_study(stepper: Callable, problem: Problem, steps: Sequence[Any] | None = None, *,
                      step_range: Sequence[float] | None = None, reference_refinement: int = 8,
                      executor: Any = None, solve_tol: float | None = None, adapt: bool | None = None,
                      expected: Order | None = None) -> ConvergenceStudy:
    """Run ``stepper`` on grids chosen for its scheme and judge its convergence order.

    ``steps`` are step sizes (uniform grids of ``[0, T]``) or explicit grids; by default the problem's
    recommended ``steps``.  ``adapt`` (default: when ``steps`` is not given) lets the study add coarser and finer
    grids as its verdict asks (:mod:`verimono.core.grid_design`); explicit ``steps`` are run as given.
    ``step_range = (h_min, h_max)``: the study runs uniform grids with steps in that range only, spaced for the
    order (at least four), and adds none outside it — for a user who knows where the scheme's asymptotic
    range lies.

    ``expected``: the order to judge against (default :func:`expected_order`: the problem's for the proximal
    scheme, the claim's for ``Stepper(..., scheme="any", order=p)``, capped by the solution's regularity).

    Without an exact solution the reference is the same stepper on a uniform grid ``reference_refinement`` times
    finer than the finest one (per batch of grids the study adds).  ``executor`` runs the grids (and the fine
    reference) as parallel jobs: any ``concurrent.futures.Executor`` — a process pool, a thread pool,
    ``dask.distributed``'s ``Client.get_executor()`` — or ``"process"`` (a process pool of ``os.cpu_count()``
    workers) or ``"serial"``.  ``None`` picks ``"process"`` for studies of at least :data:`PARALLEL_MIN_STEPS`
    steps in all on a multi-core machine, else ``"serial"``.  Problems and steppers built from lambdas and
    closures (the reference catalog's) need no pickling with verimono's own process pool (forked workers
    inherit them); for other executors they travel by pickle, else by ``cloudpickle``.

    ``solve_tol``: the accuracy of the stepper's inner solve, relative to the state's size (default: the
    stepper's own claim, ``Stepper(..., solve_tol=τ)``); it raises each grid's floor by :func:`solve_floor`.
    """
    # every argument checked before the stepper is called: what the study was given is never charged to it
    if not callable(stepper) or isinstance(stepper, type):
        raise InvalidClaim(f"a stepper must be callable as stepper(problem, t_grid), got {stepper!r:.80}")
    if not isinstance(problem, Problem):
        raise InvalidProblem(f"a convergence study needs a verimono.Problem, got {type(problem).__name__} "
                             f"{problem!r:.60}")
    if steps is not None and (isinstance(steps, (str, bytes)) or not hasattr(steps, "__len__")):
        raise InvalidProblem(f"steps must be a list of step sizes or grids, got {steps!r:.80}")
    if step_range is not None:
        step_range_of(step_range)
    reference_refinement = refinement_of(reference_refinement)
    study_executor(executor)
    if expected is not None and not isinstance(expected, Order):
        raise InvalidProblem(f"expected must be a verimono.Order (or None: the problem's), got {expected!r}")
    if adapt is not None and not isinstance(adapt, (bool, np.bool_)):
        raise InvalidProblem(f"adapt must be True, False or None, got {adapt!r}")
    claim = claim_of(stepper)
    solve_tol = claim.solve_tol if solve_tol is None else _solve_tol(solve_tol)
    exp = expected_order(stepper, problem) if expected is None else expected
    given = problem.steps if steps is None else steps
    if step_range is None and (not given or len(given) < 2):
        raise InvalidProblem("a convergence study needs at least two step sizes or grids (or a step_range)")
    design = problem.order.value if problem.order is not None and not problem.order.exact else 1.0
    given_grids = study_grids(problem.T, given) if given else []
    if claim.uniform:       # it runs on uniform grids only: a given nonuniform grid becomes the uniform one of as many cells
        given_grids = [np.linspace(0.0, problem.T, len(g)) for g in given_grids]
    plan = GridPlan(problem.T, given_grids,
                    None if exp is None or exp.exact else exp.value,
                    adaptive=(steps is None) if adapt is None else bool(adapt), step_range=step_range,
                    design_order=design)
    runner = GridRunner(stepper, problem, executor, reference_refinement)
    grids: list[np.ndarray] = []
    results: list[Any] = []
    added: list[int] = []
    batch = plan.initial
    while batch:
        own = [not plan.is_given(g) for g in batch]      # the grids the study chose: a stepper may refuse them
        added += [len(grids) + j for j, o in enumerate(own) if o]
        grids += batch
        results += runner.run(batch, tolerant=own)
        study = _assemble(stepper, problem, grids, results, runner, exp, solve_tol, claim.order, added, plan.refined)
        if exp is None or exp.exact:
            break
        want = decide(study.data(can_coarsen=plan.adaptive and not plan.coarsened,
                                 can_refine=plan.can_refine(grids)))
        batch = (plan.coarser(grids) if want.action == "coarsen" else
                 plan.finer(grids) if want.action == "refine" else [])
    return study


def _assemble(stepper, problem, grids, results, runner, exp, solve_tol, claimed, added, refined) -> ConvergenceStudy:
    """The study of ``grids`` so far, ordered coarse to fine, with the window of its verdict fitted."""
    order = sorted(range(len(grids)), key=lambda i: len(grids[i]))
    grids = [grids[i] for i in order]
    results = [results[i] for i in order]
    added = sorted(order.index(i) for i in added)
    errors = {n: [r.errors[n] for r in results] for n in NORMS}
    scale = max([1.0] + [r.scale for r in results if r.scale is not None and math.isfinite(r.scale)])
    precision = coarser(*[r.precision for r in results], *runner.reference_precisions)
    observe(precision)          # jobs run in other processes report it here
    floor = roundoff_floor(scale, precision)
    mesh = [float(np.max(np.diff(g))) for g in grids]
    floors = None if not solve_tol else [floor + solve_floor(len(g) - 1, solve_tol, scale) for g in grids]
    reference = "exact solution" if problem.exact is not None else (
        "fine-grid solution of the same stepper (h = " + ", ".join(f"{h:.3g}" for h in runner.references) + ")")
    failures = [[i, r.failure] for i, r in enumerate(results) if r.failure]
    study = ConvergenceStudy(problem.name, subject_name(stepper), mesh, [len(g) - 1 for g in grids], errors, {}, exp,
                             reference, floor, [r.seconds for r in results], floors, solve_tol or None, scale,
                             claimed, added, refined, failures, float(problem.T))
    left_out = {i for i in added if not math.isfinite(errors["sup"][i])}      # coarse grids the stepper refused
    window = study.decision().window or ([i for i in range(len(grids)) if i not in left_out] if left_out else None)
    fl = study.grid_floors
    study.fits = {n: fit_order(mesh, errors[n], fl, within=window) for n in NORMS}
    return study


__all__ = ["convergence_study", "expected_order", "inexact_order", "study_grids", "ConvergenceStudy", "OrderFit", "fit_order",
           "least_squares_slope", "grid_errors", "exact_on", "solve_floor", "ErrorAccumulator", "Sampler",
           "Decision", "NORMS", "ORDER_SLACK", "ASYMPTOTIC_SPREAD", "STALL_MARGIN", "STALL_FRACTION", "MIN_GRIDS",
           "PARALLEL_MIN_STEPS", "ROUNDOFF_FACTOR", "_timed_run"]
