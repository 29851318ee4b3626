"""The stages verimono ships: convergence orders, operator laws, trajectory laws, assumptions, Section 7,
Siconos agreement and speed — each a list of independent units of work run on the run's executor.

Units travel to worker processes by pickling: each is a module-level function and its arguments, never a
lambda.  The heavy modules (the checks, hypothesis, the reference catalog) are imported where a stage
runs, so ``verimono --help`` stays light.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Iterable

import numpy as np

from .. import performance
from ...core._jsonable import to_jsonable
from ...core.adaptive import Adaptive
from ...core.adaptive_proximal import solve_adaptive
from ...core.errors import StageUnavailable
from ...core.qp import load_optimizers
from ...execution.executors import Unit
from ...core.grids import uniform_grid
from ...execution.profiles import Profile
from ...records.results import SKIPPED, CheckResult, Report
from ...records.report.plots import keep_extrema
from ...records.verdicts import new_record
from ...core.stepping import solve
from ...execution.timeouts import current_budget, run_unit, time_limit
from ...checks.core import laws_of
from ...checks.core import subject_name as _name
from ...checks.own_steps import check_adaptive
from ...checks.orders import check_convergence_order
from ...checks.picard import check_picard
from ...checks.pseudo_distance import check_pseudo_distance
from ...checks.shared_runs import note_partitions, shared_runs
from ...checks.siconos import check_siconos_case, check_siconos_lcps
from ...checks.generated_problems import SEED_STRIDE, draw, generated_problems
from ...checks.stepper_battery import stepper_checks
from .registry import UNIT_TIME, RunContext, register_stage, timed_unit

#: at most how many evenly spaced points of a long trajectory the report keeps for its plot (enough for a smooth
#: curve: its markers are fewer), besides the extremes between them
TRAJECTORY_SAMPLES = 400


def sample_trajectory(stepper: Callable, problem: Any, h: float | None = None) -> dict[str, Any]:
    """A plot sample: ``stepper`` on a uniform grid of step ``h`` (default: the problem's coarsest
    recommended step) next to the exact solution, thinned to every k-th point (at most :data:`TRAJECTORY_SAMPLES`) and
    the highest and lowest point of each plotted component between two of them."""
    h = h or (max(problem.steps) if problem.steps else problem.T / 50)
    t = uniform_grid(problem.T, h)
    x = np.asarray(stepper(problem, t), dtype=float)
    first = (lambda a: a[:, 0] if a.ndim == 3 else a)  # a batch: plot its first member
    # evenly spaced, and each segment's extremes (records.report.plots.keep_extrema): a spike is kept, not stepped over
    cols = first(x).reshape(len(t), -1)[:, :4].T if len(t) > TRAJECTORY_SAMPLES and x.shape[:1] == t.shape else []
    keep = (np.unique(np.concatenate([keep_extrema(c, TRAJECTORY_SAMPLES - 1) for c in cols])) if len(cols)
            else np.unique(np.linspace(0, len(t) - 1, min(len(t), TRAJECTORY_SAMPLES)).round().astype(int)))
    fine = np.linspace(0.0, problem.T, TRAJECTORY_SAMPLES)
    exact = None
    if problem.exact is not None:
        exact = np.array([np.asarray(problem.exact(s), dtype=float) for s in fine])
    return to_jsonable({"problem": problem.name, "stepper": _name(stepper), "h": float(h),
                        "t": t[keep], "x": first(x)[keep],
                        "t_exact": fine if exact is not None else None,
                        "exact": first(exact) if exact is not None else None})


def _convergence_unit(stepper: Callable, problem: Any, step_range: Any = None) -> Report:
    """One reference: its convergence-order record and study (in ``step_range`` when given), and a trajectory
    sample for the plots."""
    report = Report()
    kw = {} if step_range is None else {"step_range": step_range}
    rec = report.add(run_unit(lambda: check_convergence_order(stepper, problem, **kw),
                              check="convergence_order", subject=f"{_name(stepper)} on {problem.name}"))
    if rec.study is not None:
        report.studies.append(rec.study)
    if rec.details.get("timeout") is not None:      # the stepper ran out of time: no unbounded extra call
        rec.details["trajectory_error"] = "not sampled: the unit ran out of time"
        return report
    try:
        with time_limit(current_budget(), f"the trajectory sample of {rec.subject}"):
            report.trajectories.append(sample_trajectory(stepper, problem))
    except Exception as exc:  # noqa: BLE001 - a plot sample: its failure (a UnitTimeout too) is noted, not fatal
        rec.details["trajectory_error"] = f"{type(exc).__name__}: {exc}"
    return report


def _merged(reports: Iterable[Report]) -> Report:
    out = Report()
    for rep in reports:
        out.extend(rep)
    return out


def _load_optimizers(profile: Profile, context: RunContext) -> None:
    """SciPy's optimizers (``scipy.optimize``: the laws' searches, the QPs of the paper's Example and of
    Section 7), imported before the workers fork (:func:`prepare_stages`) for the stages whose units use them:
    inherited by both workers, as when the checks imported them at their top.  A stepper's ``verimono check``
    (convergence, trajectory laws) does not ask for them: the worker whose unit solves the paper's Example's
    QPs (its a-priori bounds) imports them there, off this process's path (0.15-0.5 s)."""
    load_optimizers()


@register_stage("convergence", "every analytic reference's convergence study against its expected order",
                overlap=True, writes=("costs", "partitions"))
def convergence_stage(profile: Profile, context: RunContext) -> Report:
    """Every analytic reference's convergence study, plus a trajectory sample for the report's plots;
    one unit per reference."""
    stepper = solve if context.stepper is None else context.stepper
    problems = context.catalog()
    units = [Unit("convergence", p.name, _convergence_unit, (stepper, p, context.step_range)) for p in problems]
    reports = context.run_units(profile, units)
    for p, rep in zip(problems, reports):     # what the stepper costs on each: the later stages' guide
        context.costs[p.name] = sum(r.duration or 0.0 for r in rep.results)
        for study in rep.studies:             # the grids the step laws judge too (the study's finest, its shortfalls)
            context.partitions[p.name] = (float(p.T), [len(g) - 1 for g in study.step_law_grids()])
    return _merged(reports)


def restore_convergence(previous: Report, context: RunContext) -> None:
    """What the convergence stage leaves in ``context`` for the later stages (:attr:`RunContext.partitions`,
    which the trajectory laws judge the stepper on too, and :attr:`RunContext.costs`), rebuilt from ``previous``,
    an interrupted run whose convergence stage finished (``verimono run --resume``): its studies, read back from
    the results file, give the same grids (without them a resumed run's trajectory_laws records differed from an
    uninterrupted run's, 21 worst ratios in a ci run).  The costs, which only order units, are its units' walls."""
    labels: set[str] = set()
    for stage in previous.meta.get("stages") or []:
        if isinstance(stage, dict) and stage.get("name") == "convergence":
            for u in stage.get("units") or []:
                if isinstance(u, dict) and isinstance(u.get("label"), str):
                    labels.add(u["label"])
                    if isinstance(u.get("wall"), (int, float)):
                        context.costs.setdefault(u["label"], float(u["wall"]))
    for study in previous.studies:        # the convergence stage's own: one per reference it studied
        name, T = getattr(study, "problem", None), getattr(study, "T", None)
        if name in labels and T is not None and name not in context.partitions:
            context.partitions[name] = (float(T), [len(g) - 1 for g in study.step_law_grids()])


@register_stage("adaptive", "a stepper choosing its own steps (verimono.Adaptive): its rate in the tolerance, the "
                "laws local to steps on its own partitions, located switching times", default=False, overlap=True)
def adaptive_stage(profile: Profile, context: RunContext) -> Report:
    """:func:`verimono.checks.own_steps.check_adaptive` on every reference, one unit per reference: the stepper
    under test when it is a :class:`verimono.Adaptive` (``verimono check`` chooses this stage for one), else
    verimono's own :data:`verimono.solve_adaptive`.  Not part of a run that names no stage."""
    stepper = context.stepper if isinstance(context.stepper, Adaptive) else solve_adaptive
    problems = context.catalog()
    units = [Unit("adaptive", p.name, _adaptive_unit, (stepper, p)) for p in problems]
    return _merged(context.run_units(profile, units))


def _adaptive_unit(stepper: Any, problem: Any) -> Report:
    return check_adaptive(stepper, [problem])


def _catalog_operators(context: RunContext) -> list[tuple[str, Any]]:
    """Distinct operators of the reference catalog, named by their problem."""
    seen, out = set(), []
    for p in context.catalog():
        key = (type(p.operator).__name__, getattr(p.operator, "name", ""), p.dim)
        if key not in seen:
            seen.add(key)
            out.append((f"{getattr(p.operator, 'name', type(p.operator).__name__)} ({p.name})", p.operator))
    return out


def _generated_operators(profile: Profile, seed: int | None) -> list[tuple[str, Any]]:
    """``profile.generated_subjects`` operators drawn from ``verimono.strategies.maximal_monotone_operators``
    in dimensions 1-3, reproducibly from ``seed`` (a fresh draw when ``seed`` is None).

    Drawn like the stepper battery's problems, by :func:`verimono.checks.generated_problems.draw`: one choice
    sequence from the seed by hypothesis' own provider, the constants it would collect from the imported
    modules switched off.  Hypothesis' test engine (``@given`` under ``@seed``, used before) mixed those
    constants in, so any number literal added to any module the run imports moved the six operators and the
    baseline's records with them.  Operator ``k`` of dimension ``n`` is draw ``(seed * 7919 + n) * SEED_STRIDE
    + k``."""
    import random

    from ...strategies.operators import maximal_monotone_operators

    base = random.SystemRandom().randrange(2 ** 31) if seed is None else seed
    drawn: list[tuple[int, Any]] = []
    dims = (1, 2, 3)
    per_dim = max(1, profile.generated_subjects // len(dims))
    for n in dims:
        strategy = maximal_monotone_operators(n)
        for k in range(per_dim):
            op = draw(strategy, (base * 7919 + n) * SEED_STRIDE + k)
            drawn.append((op.dim, op))
    # the label is the record key the gate compares: it must not depend on what the draw produced (a
    # different hypothesis release draws different operators from the same seed); the operator's repr
    # stays in each record's details["operator"]
    return [(f"generated #{i} (n={n}, seed {seed})", op) for i, (n, op) in enumerate(drawn)]


def _load_operator_battery(profile: Profile, context: RunContext) -> None:
    """SciPy's optimizers (:func:`_load_optimizers`) and the operator battery with the search engine and
    hypothesis, imported before the workers fork: the stage's units name ``check_operator``, which each worker
    imported again when it unpickled its first unit (0.17 s CPU each; an operator's ``verimono check``: the one
    worker and this process, at once)."""
    load_optimizers()
    from ...checks.operator_battery import check_operator  # noqa: F401  (imported for the workers to inherit)


@register_stage("operator_laws", "resolvent and Yosida laws on the catalog operators and generated families",
                prepare=_load_operator_battery, overlap=True)
def operator_laws_stage(profile: Profile, context: RunContext) -> Report:
    """``check_operator`` on each catalog operator (or the user's) and on generated families.

    Records are renamed ``subject = <label>`` (the operator's problem or draw) so keys stay unique."""
    from ...checks.operator_battery import check_operator

    report = Report()
    if context.operators is not None:
        subjects = list(context.operators)
    else:
        subjects = _catalog_operators(context)
        try:
            subjects += _generated_operators(profile, context.seed_for(profile))
        except StageUnavailable as exc:
            report.add(new_record("stage", "operator_laws: generated families", SKIPPED,
                                  message=str(exc) or type(exc).__name__))
    units = [Unit("operator_laws", label, _operator_unit,
                  (check_operator, label, op, context.seed_for(profile), profile.law_examples))
             for label, op in subjects]
    return report.extend(_merged(context.run_units(profile, units)))


def _operator_unit(check_operator: Callable, label: str, op: Any, seed: int | None, examples: Any) -> Report:
    """One operator's law battery, its records renamed ``subject = label`` (the operator's problem or draw)."""
    rep = check_operator(op, seed=seed, examples=examples)
    for r in rep.results:
        r.details.setdefault("operator", r.subject)
        r.subject = label
    return rep


def _draw_generated(profile: Profile, context: RunContext) -> None:
    """The stage's generated problems, drawn before the workers fork (:func:`prepare_stages`): hypothesis and
    the strategies they are made of are then imported once, here, not again by every worker unpickling them."""
    if context.problems is None and profile.generated_subjects:
        seed = context.seed_for(profile)
        generated_problems(0 if seed is None else seed, profile.generated_subjects)


@register_stage("trajectory_laws", "contraction, uniqueness of the limit, domain, a-priori bounds, selections",
                prepare=_draw_generated, overlap=True, after=("convergence",))   # its costs and partitions
def trajectory_laws_stage(profile: Profile, context: RunContext) -> Report:
    """The trajectory laws of the stepper under test on every reference (and, without a user-given
    problem list, on ``profile.generated_subjects`` sampled problems)."""
    stepper = solve if context.stepper is None else context.stepper
    seed = context.seed_for(profile)
    checks = [] if context.problems == [] else \
        list(stepper_checks(stepper, context.problems, seed=0 if seed is None else seed,
                            generated=profile.generated_subjects, orders=False))   # [] under `check --only`
    if context.extra_problems:      # --problem: besides the references and the sampled problems
        checks += stepper_checks(stepper, context.extra_problems, seed=0 if seed is None else seed, orders=False)
    # one unit per subject problem (the battery of checks ``law[problem]`` on it), in first-seen order;
    # the records are then put back in the order of ``checks``, as a serial loop over them gives
    groups: dict[str, list[int]] = {}
    for k, (name, _) in enumerate(checks):
        groups.setdefault(name.partition("[")[2].rstrip("]") or name, []).append(k)
    units = [Unit("trajectory_laws", subject, _checks_unit, ([checks[k] for k in ks], stepper,
                                                             {subject: context.partitions[subject]}
                                                             if subject in context.partitions else None))
             for subject, ks in groups.items()]
    slots: list[list[CheckResult]] = [[] for _ in checks]
    costs = [context.costs.get(subject, 0.0) for subject in groups]     # the costliest problems first
    for ks, rep in zip(groups.values(), context.run_units(profile, units, costs)):
        sizes = rep.meta.get("records_per_check")
        if sizes is None or len(sizes) != len(ks):  # a unit that did not finish: its one failed record
            slots[ks[0]].extend(rep.results)
            continue
        it = iter(rep.results)
        for k, n in zip(ks, sizes):
            slots[k].extend(next(it) for _ in range(n))
    return Report([r for slot in slots for r in slot])


def _checks_unit(checks: list[tuple[str, Callable]], subject: Any,
                 partitions: dict[str, tuple[float, list[int]]] | None = None) -> Report:
    """Every ``check(subject)`` of one battery, in order (``meta["records_per_check"]``: how many each gave);
    ``partitions``: the grids of the convergence studies (by problem name: ``(T, cell counts)``) the step laws
    judge the stepper on too."""
    report, sizes = Report(), []
    with shared_runs():             # the laws judge the same runs of the stepper: each is made once
        for name, (T, cells) in (partitions or {}).items():
            note_partitions(subject, (name, T), [uniform_grid(T, steps=k) for k in cells])
        for name, check in checks:
            law, _, problem_name = name.partition("[")
            # each check under the unit time budget: one that does not return is a failed record, the rest go on
            out = run_unit(lambda: check(subject), check=law, subject=f"{_name(subject)} on {problem_name[:-1]}")
            before = len(report)
            report.extend(out) if isinstance(out, Report) else report.add(out)
            sizes.append(len(report) - before)
    report.meta["records_per_check"] = sizes
    return report


@register_stage("assumptions", "sampled evidence for (A1), (A2), (A3), (LG), (YB) on every reference",
                prepare=_load_optimizers, overlap=True)
def assumptions_stage(profile: Profile, context: RunContext) -> Report:
    """``check_assumptions(problem)`` on every reference (evidence, never proof).

    Theorem ``thm:main`` needs (A1)–(A3) and *one of* (LG) or (YB): the composite law
    :func:`verimono.checks.assumptions.thm_main` states it (an ``xfail`` for the alternative that fails
    while the other holds, one ``assumptions_thm_main`` record per problem)."""
    from ...checks.assumptions import check_assumptions

    seed = context.seed_for(profile)
    units = [Unit("assumptions", p.name, _assumptions_unit, (check_assumptions, p, seed))
             for p in context.catalog()]
    return _merged(context.run_units(profile, units))


def _assumptions_unit(check_assumptions: Callable, p: Any, seed: int | None) -> Report:
    """One reference's assumption records, its ``assumptions_thm_main`` record included."""
    report = Report()
    rep = run_unit(lambda: check_assumptions(p, seed=0 if seed is None else seed), check="assumptions",
                   subject=p.name)
    if isinstance(rep, CheckResult):    # the unit ran out of its time budget: a failed record, go on
        report.add(rep)
    else:
        report.extend(rep)
    return report


@register_stage("section7", "the paper's complementarity example: orders, trajectories, hypotheses",
                prepare=_load_optimizers, overlap=True)
def section7_stage(profile: Profile, context: RunContext) -> Report:
    """The complementarity systems of the paper (``verimono.reference.lcs_example``): convergence order
    of the stepper under test on each, a trajectory sample, and the evidence for the hypotheses of the
    Section 7 theorems (``verimono.lcs.check_hypotheses``); one unit per record (or per system)."""
    from verimono.reference import lcs_example as example

    stepper = solve if context.stepper is None else context.stepper
    in_catalog = {p.name for p in context.catalog()}  # already studied by the convergence stage
    problems = [p for p in (example.ramp_problem(), example.sine_problem()) if p.name not in in_catalog]
    seed = context.seed_for(profile)
    seed = 0 if seed is None else seed
    units = [Unit("section7", p.name, _convergence_unit, (stepper, p)) for p in problems]
    units += [Unit("section7", "closed-form resolvent", _record_unit, ("example_resolvent_closed_form", seed)),
              Unit("section7", "batched scheme", _record_unit, ("example_batched_scheme", seed)),
              Unit("section7", "unbounded pseudo-distance", _record_unit, ("example_pseudo_distance_unbounded",))]
    # def:dis against the exact d_H of catalog sets, and the Picard step of Section 6
    units.append(Unit("section7", "pseudo-distance", _pseudo_distance_unit, (seed,)))
    units.append(Unit("section7", "Hoffman's bound", _hoffman_unit, (seed,)))      # e:hoffman (e: linear case-comp)
    units += [Unit("section7", f"Picard step on {p.name}", _picard_unit, (stepper, p)) for p in context.catalog()
              if p.f is not None and p.lipschitz is not None]
    units += [Unit("section7", f"hypotheses ({label})", _hypotheses_unit, (label, seed)) for label in _INPUTS]
    return _merged(context.run_units(profile, units))


#: the Example's inputs whose hypotheses Section 7 checks (a name each: units travel by name, not by lambda)
_INPUTS = {"v = (−t, 0)": lambda t: np.array([-t, 0.0]), "v = (sin t, 0)": lambda t: np.array([np.sin(t), 0.0])}


def _record_unit(name: str, *args: Any) -> Report:
    """The record of the Example's law ``name`` (:mod:`verimono.checks.example`; ``args``: its seed, if any)."""
    from ...checks import example  # noqa: F401 - the Example's laws join the registry on import

    check = laws_of("system")[name].public
    return Report([check(seed=args[0]) if args else check()])


def _pseudo_distance_unit(seed: int) -> Report:
    return Report([check_pseudo_distance(seed=seed)])


def _hoffman_unit(seed: int) -> Report:
    from ...checks.hoffman import check_hoffman

    return Report([check_hoffman(seed=seed)])


def _picard_unit(stepper: Callable, problem: Any) -> Report:
    return Report([check_picard(stepper, problem)])


def _hypotheses_unit(label: str, seed: int) -> Report:
    """The Section 7 hypotheses of the Example with input ``label``, each record's subject naming it."""
    from verimono.reference import lcs_example

    from ...checks.section7 import check_hypotheses

    rep = check_hypotheses(lcs_example.example_system(_INPUTS[label]), 2.0, seed=seed)
    for r in rep.results:
        r.subject = f"{r.subject} ({label})"
    return rep


@register_stage("siconos", "agreement with the Siconos reference trajectories shipped in verimono/data",
                prepare=_load_optimizers, overlap=True)
def siconos_stage(profile: Profile, context: RunContext) -> Report:
    """Agreement with the Siconos reference trajectories (the packaged data, or ``--data DIR``)."""
    from ...lcs import siconos_cases as cases

    data = Path(context.data_dir) if context.data_dir is not None else cases.PACKAGED_DATA
    units = [Unit("siconos", name, _siconos_unit, (check_siconos_case, name, data)) for name in cases.CASES]
    units.append(Unit("siconos", "LCP test files", _siconos_unit, (check_siconos_lcps, data)))
    return _merged(context.run_units(profile, units))


def _siconos_unit(check: Callable, *args: Any) -> Report:
    """``check(*args)`` (one Siconos trajectory case, or the LCP files) as a report."""
    out = check(*args)
    return out if isinstance(out, Report) else Report([out])


@register_stage("performance", "verimono against bare baselines, as same-job ratios: per-step overhead, "
                "ensembles, DiodeBridge, memory", prepare=_load_optimizers)
def performance_stage(profile: Profile, context: RunContext) -> Report:
    """The speed targets as records (:mod:`verimono.run.performance`), at the sizes of ``profile``; each
    record's ``details["timing_ratio"]`` is gated against the baseline by ratio, never by seconds."""

    aside = None
    if getattr(context.executor, "workers", 1) >= 2:   # a worker is idle: the memory record runs there
        def aside(steps: int, stepper: Any) -> Callable[[], CheckResult]:
            import concurrent.futures

            unit = Unit("performance", "memory", timed_unit, (_memory_unit, (steps, stepper)))

            def run() -> Report:
                rep = context.executor.map([unit], profile.name, lambda done, total, label: None)[0]
                t = rep.meta.pop(UNIT_TIME, None)   # its CPU is the stage's too (the stage's CPU had left it out)
                if isinstance(t, dict):
                    context.unit_times.append({"stage": unit.stage, "label": unit.label, **t})
                return rep

            pool = concurrent.futures.ThreadPoolExecutor(1)
            future = pool.submit(run)
            pool.shutdown(wait=False)
            return lambda: future.result().results[0]
    return performance.performance_report(performance.SIZES[profile.name], stepper=context.stepper, progress=context.progress,
                                   aside=aside)


def _memory_unit(steps: int, stepper: Any) -> Report:
    """The memory record (:func:`verimono.run.performance.check_memory`) as a unit of work."""
    return Report([performance.check_memory(steps=steps, stepper=stepper)])


__all__ = ["sample_trajectory", "TRAJECTORY_SAMPLES", "restore_convergence"]
