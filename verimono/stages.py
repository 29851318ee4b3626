"""The verification run as a list of *stages*: a small registry ``name → callable(profile, context) → Report``.

``verimono run`` runs every registered stage in order (or those named with ``--stage``), merges their
reports and records, per stage, its status, record count and duration in ``report.meta["stages"]``.

A stage never prints and never raises: :func:`run_stages` turns an exception into one *failed* record
``stage[<name>]`` (a crash fails the run) and :class:`StageUnavailable` — a battery whose module is not
installed, or data that are absent — into one *skipped* record, so a missing battery is counted and the
gate sees the count of checks shrink.

To add a battery::

    from verimono.stages import register_stage

    @register_stage("my_laws", "what it verifies")
    def my_laws(profile, context):          # profile: verimono.profiles.Profile; context: RunContext
        return check_something(context.stepper, seed=context.seed)     # a verimono.Report
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import os
import time
import traceback
from pathlib import Path
from typing import Any, Callable, Iterable

import numpy as np

from .errors import StageUnavailable, UnknownStage, VerimonoError
from .profiles import Profile
from .grids import uniform_grid
from .results import FAILED, PASSED, SKIPPED, XFAIL, CheckResult, Report, to_jsonable
from .executors import SerialRunner, Unit
from .stepping import solve
from .timeouts import run_unit
from . import timing

#: how many points of a trajectory the report keeps for its plot (enough for a smooth curve)
TRAJECTORY_SAMPLES = 400


@dataclasses.dataclass
class RunContext:
    """What every stage may use.

    ``stepper`` is the time-stepper under test (``verimono.solve`` for ``verimono run``); ``problems``
    the references (``None``: the whole catalog); ``operators`` extra operators to verify (``verimono
    check`` on an operator); ``data_dir`` the shared data folder (Siconos references) or ``None``;
    ``progress(done, total, label)`` reports progress within a stage.
    """

    stepper: Callable | None = None
    problems: list[Any] | None = None
    operators: list[tuple[str, Any]] | None = None
    seed: int | None = None
    data_dir: Path | None = None
    progress: Callable[[int, int, str], None] = lambda done, total, label: None
    executor: Any = None

    _catalog: list[Any] | None = dataclasses.field(default=None, repr=False)

    def catalog(self) -> list[Any]:
        """``problems`` if given, else the reference catalog (built once per run)."""
        if self.problems is not None:
            return self.problems
        if self._catalog is None:
            from verimono.reference import catalog

            self._catalog = catalog()
        return self._catalog

    def run_units(self, profile: Profile, units: list[Any]) -> list[Report]:
        """The reports of ``units`` (:class:`verimono.executors.Unit`), in their order, run on
        ``executor`` (serially here when it is ``None``); a unit that raises, whose worker dies or that
        times out gives one failed record ``unit[<stage>: <label>]`` and the other units' records stay."""
        runner = self.executor if self.executor is not None else SerialRunner()
        return runner.map(units, profile.name, self.progress)

    def seed_for(self, profile: Profile) -> int | None:
        """The seed a randomized battery uses: ``seed`` if given, else 0 under a derandomized profile
        (``ci``: the same records in every job), else ``None`` (a fresh seed, recorded in each record)."""
        if self.seed is not None:
            return self.seed
        return 0 if profile.derandomize else None


@dataclasses.dataclass(frozen=True)
class Stage:
    name: str
    fn: Callable[[Profile, RunContext], Report]
    description: str = ""


STAGES: dict[str, Stage] = {}


def register_stage(name: str, description: str = "") -> Callable:
    """Decorator registering ``fn(profile, context) -> Report`` as the stage ``name`` (replaces same name)."""

    def deco(fn: Callable[[Profile, RunContext], Report]) -> Callable:
        STAGES[name] = Stage(name, fn, description or (fn.__doc__ or "").strip().split("\n")[0])
        return fn

    return deco


def optional_module(name: str) -> Any:
    """Import ``name``; :class:`StageUnavailable` if that module (not one of its imports) is missing."""
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as exc:
        if exc.name and (name == exc.name or name.startswith(exc.name + ".")):
            raise StageUnavailable(f"{name} is not installed in this version of verimono") from None
        raise


def _stage_record(name: str, status: str, message: str, duration: float) -> CheckResult:
    return CheckResult("stage", name, status, message=message, duration=duration)


def run_stages(names: Iterable[str] | None, profile: Profile, context: RunContext,
               on_start: Callable[[Stage, int, int], None] | None = None,
               on_done: Callable[[Stage, Report, dict], None] | None = None) -> Report:
    """Run the stages ``names`` (``None``: all, in registration order) and merge their reports."""
    names = list(STAGES) if names is None else list(names)
    for n in names:
        if n not in STAGES:
            raise UnknownStage(f"unknown stage {n!r}; registered stages: {', '.join(STAGES)}")
    total = Report(meta={"stages": []})
    for i, n in enumerate(names):
        stage = STAGES[n]
        if on_start:
            on_start(stage, i, len(names))
        start = time.perf_counter()
        try:
            rep = stage.fn(profile, context)
            if not isinstance(rep, Report):
                raise TypeError(f"stage {n} returned {type(rep).__name__}, expected a verimono.Report")
            status = "failed" if rep.failures else ("undecided" if not rep.ok else "passed")
            message = rep.summary()
        except StageUnavailable as exc:
            rep = Report([_stage_record(n, SKIPPED, str(exc), time.perf_counter() - start)])
            status, message = "skipped", str(exc)
        except Exception as exc:  # a crash is a failure of the run, recorded, never swallowed
            tb = traceback.format_exc(limit=6)
            rec = _stage_record(n, FAILED, f"{type(exc).__name__}: {exc}", time.perf_counter() - start)
            rec.details["traceback"] = tb
            rep = Report([rec])
            status, message = "error", f"{type(exc).__name__}: {exc}"
        duration = time.perf_counter() - start
        info = {"name": n, "status": status, "records": len(rep), "duration": duration, "message": message}
        for r in rep.results:
            r.details.setdefault("stage", n)
            cx = r.counterexample if isinstance(r.counterexample, dict) else {}
            if isinstance(cx.get("problem"), str) and cx["problem"] in _reference_names():
                r.details.setdefault("reference", cx["problem"])  # `--reference NAME` reproduces it
        total.extend(rep)
        total.meta["stages"].append(info)
        if on_done:
            on_done(stage, rep, info)
    return total


@functools.lru_cache(maxsize=1)
def _reference_names() -> frozenset[str]:
    """Names ``verimono run --reference NAME`` accepts (the reference catalog's)."""
    from verimono.reference import catalog

    return frozenset(p.name for p in catalog())


def calibrate(repeats: int = 3) -> float:
    """Seconds of a fixed NumPy-and-Python workload like the harness's (best of ``repeats``):
    :func:`verimono.timing.calibrate`, where the time budgets (:mod:`verimono.timeouts`) find it too.

    Stage durations divided by this number are comparable between jobs on different machines: the gate
    compares these ratios, measured in the same job, never absolute seconds.
    """
    return timing.calibrate(repeats)


def locate_data(explicit: str | os.PathLike | None = None) -> Path | None:
    """The shared data folder: ``explicit``, else ``$VERIMONO_SHARED``, else ``../shared`` beside the
    current directory or beside the verimono checkout; ``None`` when none exists."""
    if explicit is not None:
        path = Path(explicit)
        if not path.is_dir():
            raise StageUnavailable(f"data folder {path} does not exist")
        return path
    candidates = []
    if os.environ.get("VERIMONO_SHARED"):
        candidates.append(Path(os.environ["VERIMONO_SHARED"]))
    candidates += [Path.cwd().parent / "shared", Path(__file__).resolve().parents[1].parent / "shared"]
    return next((c for c in candidates if c.is_dir()), None)


def _name(obj: Any) -> str:
    return getattr(obj, "__name__", None) or getattr(obj, "name", None) or type(obj).__name__


# ---------------------------------------------------------------------------------------------------
# the stages verimono ships


def sample_trajectory(stepper: Callable, problem: Any, h: float | None = None) -> dict[str, Any]:
    """A plot sample: ``stepper`` on a uniform grid of step ``h`` (default: the problem's coarsest
    recommended step) next to the exact solution, thinned to :data:`TRAJECTORY_SAMPLES` points."""
    h = h or (max(problem.steps) if problem.steps else problem.T / 50)
    t = uniform_grid(problem.T, h)
    x = np.asarray(stepper(problem, t), dtype=float)
    keep = np.unique(np.linspace(0, len(t) - 1, min(len(t), TRAJECTORY_SAMPLES)).round().astype(int))
    fine = np.linspace(0.0, problem.T, TRAJECTORY_SAMPLES)
    exact = None
    if problem.exact is not None:
        exact = np.array([np.asarray(problem.exact(s), dtype=float) for s in fine])
    first = (lambda a: a[:, 0] if a.ndim == 3 else a)  # a batch: plot its first member
    return to_jsonable({"problem": problem.name, "stepper": _name(stepper), "h": float(h),
                        "t": t[keep], "x": first(x)[keep],
                        "t_exact": fine if exact is not None else None,
                        "exact": first(exact) if exact is not None else None})


def _convergence_unit(stepper: Callable, problem: Any) -> Report:
    """One reference: its convergence-order record and study, and a trajectory sample for the plots."""
    from .checks.orders import check_convergence_order

    report = Report()
    rec = report.add(run_unit(lambda: check_convergence_order(stepper, problem), check="convergence_order",
                              subject=f"{_name(stepper)} on {problem.name}"))
    if rec.study is not None:
        report.studies.append(rec.study)
    try:
        report.trajectories.append(sample_trajectory(stepper, problem))
    except (VerimonoError, ArithmeticError, ValueError) as exc:
        rec.details["trajectory_error"] = f"{type(exc).__name__}: {exc}"
    return report


def _merged(reports: Iterable[Report]) -> Report:
    out = Report()
    for rep in reports:
        out.extend(rep)
    return out


@register_stage("convergence", "every analytic reference's convergence study against its expected order")
def convergence_stage(profile: Profile, context: RunContext) -> Report:
    """Every analytic reference's convergence study, plus a trajectory sample for the report's plots;
    one unit per reference."""
    stepper = solve if context.stepper is None else context.stepper
    units = [Unit("convergence", p.name, _convergence_unit, (stepper, p)) for p in context.catalog()]
    return _merged(context.run_units(profile, units))


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
    in dimensions 1-3 (reproducibly from ``seed``; a fresh draw when ``seed`` is None)."""
    strategies = optional_module("verimono.strategies")
    family = getattr(strategies, "maximal_monotone_operators", None)
    if family is None:
        raise StageUnavailable("verimono.strategies has no maximal_monotone_operators")
    from hypothesis import HealthCheck, Phase, given, settings
    from hypothesis import seed as hseed

    drawn: list[tuple[int, Any]] = []
    dims = (1, 2, 3)
    per_dim = max(1, profile.generated_subjects // len(dims))
    for n in dims:
        # skip hypothesis' first, simplest example (the zero operator) so the draws exercise real cases
        @settings(max_examples=per_dim + 1, derandomize=False, database=None, phases=[Phase.generate],
                  deadline=None, suppress_health_check=list(HealthCheck))
        @given(family(n))
        def collect(op):
            drawn.append((op.dim, op))

        if seed is not None:
            collect = hseed(seed * 7919 + n)(collect)
        before = len(drawn)
        collect()
        del drawn[before]
    # the label is the record key the gate compares: it must not depend on what the draw produced (a
    # different hypothesis release draws different operators from the same seed); the operator's repr
    # stays in each record's details["operator"]
    return [(f"generated #{i} (n={n}, seed {seed})", op) for i, (n, op) in enumerate(drawn)]


@register_stage("operator_laws", "resolvent and Yosida laws on the catalog operators and generated families")
def operator_laws_stage(profile: Profile, context: RunContext) -> Report:
    """``check_operator`` on each catalog operator (or the user's) and on generated families.

    Records are renamed ``subject = <label>`` (the operator's problem or draw) so keys stay unique."""
    laws = optional_module("verimono.checks.operator_laws")
    report = Report()
    if context.operators is not None:
        subjects = list(context.operators)
    else:
        subjects = _catalog_operators(context)
        try:
            subjects += _generated_operators(profile, context.seed_for(profile))
        except StageUnavailable as exc:
            report.add(CheckResult("stage", "operator_laws: generated families", SKIPPED, message=str(exc)))
    units = [Unit("operator_laws", label, _operator_unit,
                  (laws.check_operator, label, op, context.seed_for(profile), profile.law_examples))
             for label, op in subjects]
    return report.extend(_merged(context.run_units(profile, units)))


def _operator_unit(check_operator: Callable, label: str, op: Any, seed: int | None, examples: Any) -> Report:
    """One operator's law battery, its records renamed ``subject = label`` (the operator's problem or draw)."""
    rep = check_operator(op, seed=seed, examples=examples)
    for r in rep.results:
        r.details.setdefault("operator", r.subject)
        r.subject = label
    return rep


@register_stage("trajectory_laws", "contraction, uniqueness of the limit, domain, a-priori bounds, selections")
def trajectory_laws_stage(profile: Profile, context: RunContext) -> Report:
    """The trajectory laws of the stepper under test on every reference (and, without a user-given
    problem list, on ``profile.generated_subjects`` sampled problems)."""
    mod = optional_module("verimono.checks.trajectory_laws")
    stepper = solve if context.stepper is None else context.stepper
    seed = context.seed_for(profile)
    checks = list(mod.stepper_checks(stepper, context.problems, seed=0 if seed is None else seed,
                                     generated=profile.generated_subjects, orders=False))
    # one unit per subject problem (the battery of checks ``law[problem]`` on it), in first-seen order;
    # the records are then put back in the order of ``checks``, as a serial loop over them gives
    groups: dict[str, list[int]] = {}
    for k, (name, _) in enumerate(checks):
        groups.setdefault(name.partition("[")[2].rstrip("]") or name, []).append(k)
    units = [Unit("trajectory_laws", subject, _checks_unit, ([checks[k] for k in ks], stepper))
             for subject, ks in groups.items()]
    slots: list[list[CheckResult]] = [[] for _ in checks]
    for ks, rep in zip(groups.values(), context.run_units(profile, units)):
        sizes = rep.meta.get("records_per_check")
        if sizes is None or len(sizes) != len(ks):  # a unit that did not finish: its one failed record
            slots[ks[0]].extend(rep.results)
            continue
        it = iter(rep.results)
        for k, n in zip(ks, sizes):
            slots[k].extend(next(it) for _ in range(n))
    return Report([r for slot in slots for r in slot])


def _checks_unit(checks: list[tuple[str, Callable]], subject: Any) -> Report:
    """Every ``check(subject)`` of one battery, in order (``meta["records_per_check"]``: how many each gave)."""
    report, sizes = Report(), []
    for name, check in checks:
        law, _, problem_name = name.partition("[")
        # each check under the unit time budget: one that does not return is a failed record, the rest go on
        out = run_unit(lambda: check(subject), check=law, subject=f"{_name(subject)} on {problem_name[:-1]}")
        before = len(report)
        report.extend(out) if isinstance(out, Report) else report.add(out)
        sizes.append(len(report) - before)
    report.meta["records_per_check"] = sizes
    return report


@register_stage("assumptions", "sampled evidence for (A1), (A2), (A3), (LG), (YB) on every reference")
def assumptions_stage(profile: Profile, context: RunContext) -> Report:
    """``check_assumptions(problem)`` on every reference (evidence, never proof).

    Theorem ``thm:main`` needs (A1)–(A3) and *one of* (LG) or (YB): the composite law
    :func:`verimono.checks.assumptions.thm_main` states it (an ``xfail`` for the alternative that fails
    while the other holds, one ``assumptions_thm_main`` record per problem)."""
    mod = optional_module("verimono.checks.assumptions")
    seed = context.seed_for(profile)
    units = [Unit("assumptions", p.name, _assumptions_unit, (mod.check_assumptions, p, seed))
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


@register_stage("section7", "the paper's complementarity example: orders, trajectories, hypotheses")
def section7_stage(profile: Profile, context: RunContext) -> Report:
    """The complementarity systems of the paper (``verimono.reference.lcs_example``): convergence order
    of the stepper under test on each, a trajectory sample, and the evidence for the hypotheses of the
    Section 7 theorems (``verimono.lcs.check_hypotheses``); one unit per record (or per system)."""
    example = optional_module("verimono.reference.lcs_example")
    optional_module("verimono.lcs")
    stepper = solve if context.stepper is None else context.stepper
    in_catalog = {p.name for p in context.catalog()}  # already studied by the convergence stage
    problems = [p for p in (example.ramp_problem(), example.sine_problem()) if p.name not in in_catalog]
    seed = context.seed_for(profile)
    seed = 0 if seed is None else seed
    units = [Unit("section7", p.name, _convergence_unit, (stepper, p)) for p in problems]
    units += [Unit("section7", "closed-form resolvent", _record_unit, ("check_closed_form_resolvent", seed))]
    if hasattr(example, "check_batched_scheme"):   # a batch of trajectories in one simulate (issue 15)
        units.append(Unit("section7", "batched scheme", _record_unit, ("check_batched_scheme", seed)))
    units.append(Unit("section7", "unbounded pseudo-distance", _record_unit, ("check_pseudo_distance_unbounded",)))
    # def:dis against the exact d_H of catalog sets, and the Picard step of Section 6 (issue 13)
    units.append(Unit("section7", "pseudo-distance", _pseudo_distance_unit, (seed,)))
    units += [Unit("section7", f"Picard step on {p.name}", _picard_unit, (stepper, p)) for p in context.catalog()
              if p.f is not None and p.lipschitz is not None]
    units += [Unit("section7", f"hypotheses ({label})", _hypotheses_unit, (label, seed)) for label in _INPUTS]
    return _merged(context.run_units(profile, units))


#: the Example's inputs whose hypotheses Section 7 checks (a name each: units travel by name, not by lambda)
_INPUTS = {"v = (−t, 0)": lambda t: np.array([-t, 0.0]), "v = (sin t, 0)": lambda t: np.array([np.sin(t), 0.0])}


def _record_unit(name: str, *args: Any) -> Report:
    """One record of ``verimono.reference.lcs_example`` (``name(*args)``, ``args`` the seed if any)."""
    fn = getattr(optional_module("verimono.reference.lcs_example"), name)
    return Report([fn(seed=args[0]) if args else fn()])


def _pseudo_distance_unit(seed: int) -> Report:
    from .checks.pseudo_distance import check_pseudo_distance

    return Report([check_pseudo_distance(seed=seed)])


def _picard_unit(stepper: Callable, problem: Any) -> Report:
    from .checks.picard import check_picard

    return Report([check_picard(stepper, problem)])


def _hypotheses_unit(label: str, seed: int) -> Report:
    """The Section 7 hypotheses of the Example with input ``label``, each record's subject naming it."""
    example = optional_module("verimono.reference.lcs_example")
    rep = optional_module("verimono.lcs").check_hypotheses(example.example_system(_INPUTS[label]), 2.0, seed=seed)
    for r in rep.results:
        r.subject = f"{r.subject} ({label})"
    return rep


@register_stage("siconos", "agreement with the Siconos reference trajectories in the shared data folder")
def siconos_stage(profile: Profile, context: RunContext) -> Report:
    """Agreement with the Siconos reference trajectories (needs ``../shared`` or ``--data DIR``)."""
    cases = optional_module("verimono.lcs.siconos_cases")
    if context.data_dir is None:
        raise StageUnavailable("Siconos reference data not found: pass --data DIR or set VERIMONO_SHARED")
    data = Path(context.data_dir)
    units = [Unit("siconos", name, _siconos_unit, ("check_siconos_case", name, data)) for name in cases.CASES]
    units.append(Unit("siconos", "LCP test files", _siconos_unit, ("check_siconos_lcps", data)))
    return _merged(context.run_units(profile, units))


def _siconos_unit(name: str, *args: Any) -> Report:
    """``verimono.lcs.siconos_cases.<name>(*args)`` as a report (one trajectory case, or the LCP files)."""
    out = getattr(optional_module("verimono.lcs.siconos_cases"), name)(*args)
    return out if isinstance(out, Report) else Report([out])


@register_stage("performance", "verimono against bare baselines, as same-job ratios: per-step overhead, "
                "ensembles, DiodeBridge, memory")
def performance_stage(profile: Profile, context: RunContext) -> Report:
    """The issue 6 targets as records (``verimono.performance``), at the sizes of ``profile``; each
    record's ``details["timing_ratio"]`` is gated against the baseline by ratio, never by seconds."""
    perf = optional_module("verimono.performance")
    aside = None
    if getattr(context.executor, "workers", 1) >= 2:   # a worker is idle: the memory record runs there
        def aside(steps: int, stepper: Any) -> Callable[[], CheckResult]:
            import concurrent.futures

            unit = Unit("performance", "memory", _memory_unit, (steps, stepper))
            pool = concurrent.futures.ThreadPoolExecutor(1)
            future = pool.submit(context.executor.map, [unit], profile.name, lambda done, total, label: None)
            pool.shutdown(wait=False)
            return lambda: future.result()[0].results[0]
    return perf.performance_report(perf.SIZES[profile.name], stepper=context.stepper, progress=context.progress,
                                   aside=aside)


def _memory_unit(steps: int, stepper: Any) -> Report:
    """The memory record (:func:`verimono.performance.check_memory`) as a unit of work."""
    return Report([optional_module("verimono.performance").check_memory(steps=steps, stepper=stepper)])


__all__ = ["STAGES", "Stage", "RunContext", "StageUnavailable", "UnknownStage", "register_stage",
           "run_stages", "calibrate", "locate_data", "optional_module", "sample_trajectory"]
