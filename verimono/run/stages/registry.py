"""The verification run as a list of *stages*: a small registry ``name → callable(profile, context) → Report``.

``verimono run`` runs every registered stage in order (or those named with ``--stage``), merges their
reports and records, per stage, its status, record count and duration in ``report.meta["stages"]``.

A stage never prints and never raises: :func:`run_stages` judges what a stage raised by the checks' one
exception policy (:func:`verimono.checks.core.classify`) — :class:`verimono.StageUnavailable`, data that
are absent, is one *skipped* record ``stage[<name>]``, so a missing battery is counted and the gate sees
the count of checks shrink; anything else, a crash, one *failed* record with its traceback.

To add a battery::

    from verimono.run.stages import register_stage

    @register_stage("my_laws", "what it verifies")
    def my_laws(profile, context):          # profile: verimono.execution.profiles.Profile; context: RunContext
        return check_something(context.stepper, seed=context.seed)     # a verimono.Report
"""

from __future__ import annotations

import dataclasses
import os
import time
import traceback
from pathlib import Path
from typing import Any, Callable, Iterable

from ...checks.core import classify
from ...core.errors import StageUnavailable, UnknownStage
from ...execution.executors import SerialRunner
from ...execution.calibration import slices_after
from ...execution.timing import cpu_now, subject_cpu
from ...lcs.siconos import PACKAGED_DATA, siconos_root
from ...execution.profiles import Profile
from ...records.results import FAILED, SKIPPED, Report
from ...records.verdicts import SUBJECT_EXITS, new_record


@dataclasses.dataclass
class RunContext:
    """What every stage may use.

    ``stepper`` is the time-stepper under test (``verimono.solve`` for ``verimono run``); ``problems``
    the references (``None``: the whole catalog); ``operators`` extra operators to verify (``verimono
    check`` on an operator); ``data_dir`` the data folder (Siconos references) or ``None``;
    ``progress(done, total, label)`` reports progress within a stage; ``executor`` runs the stages'
    independent units (:mod:`verimono.execution.executors`; serially when ``None``); ``costs`` holds what an earlier
    stage measured of a subject (seconds, by problem name), so a later stage can start its costliest units
    first (:meth:`run_units`).
    """

    stepper: Callable | None = None
    problems: list[Any] | None = None
    operators: list[tuple[str, Any]] | None = None
    seed: int | None = None
    data_dir: Path | None = None
    progress: Callable[[int, int, str], None] = lambda done, total, label: None
    executor: Any = None
    costs: dict[str, float] = dataclasses.field(default_factory=dict)
    #: problems checked besides the references (``verimono check --problem``): added to :meth:`catalog`
    extra_problems: list[Any] = dataclasses.field(default_factory=list)
    #: the CPU and wall seconds of every unit run so far (:func:`timed_unit`), in the order they came back
    unit_times: list[dict[str, Any]] = dataclasses.field(default_factory=list)
    partitions: dict[str, tuple[float, list[int]]] = dataclasses.field(default_factory=dict)
    #: ``(h_min, h_max)``: every convergence study on uniform grids with steps in that range only
    step_range: tuple[float, float] | None = None

    _catalog: list[Any] | None = dataclasses.field(default=None, repr=False)

    def catalog(self) -> list[Any]:
        """``problems`` if given, else the reference catalog (built once per run); then ``extra_problems``."""
        if self.problems is not None:
            return list(self.problems) + list(self.extra_problems)
        if self._catalog is None:
            from verimono.reference import catalog

            self._catalog = catalog()
        return self._catalog + list(self.extra_problems)

    def run_units(self, profile: Profile, units: list[Any], costs: list[float] | None = None) -> list[Report]:
        """The reports of ``units`` (:class:`verimono.execution.executors.Unit`), in their order, run on
        ``executor`` (serially here when it is ``None``); a unit that raises, whose worker dies or that
        times out gives one failed record ``unit[<stage>: <label>]`` and the other units' records stay.

        ``costs`` (one guess per unit, e.g. from :attr:`costs`): on worker processes the units start
        costliest first, so that no long unit starts last while the other workers idle; the reports come
        back in the units' order all the same."""
        runner = self.executor if self.executor is not None else SerialRunner()
        timed = [dataclasses.replace(u, fn=timed_unit, args=(u.fn, u.args)) for u in units]
        if costs is None or isinstance(runner, SerialRunner):
            out = runner.map(timed, profile.name, self.progress)
        else:
            order = sorted(range(len(units)), key=lambda i: -costs[i])
            reports = runner.map([timed[i] for i in order], profile.name, self.progress)
            out = [Report()] * len(units)
            for i, rep in zip(order, reports):
                out[i] = rep
        for u, rep in zip(units, out):
            t = rep.meta.pop(UNIT_TIME, None)     # absent: a unit that died or timed out (its record says so)
            if isinstance(t, dict):
                self.unit_times.append({"stage": u.stage, "label": u.label, **t})
        return out

    def seed_for(self, profile: Profile) -> int | None:
        """The seed a randomized battery uses: ``seed`` if given, else 0 under a derandomized profile
        (``ci``: the same records in every job), else ``None`` (a fresh seed, recorded in each record)."""
        if self.seed is not None:
            return self.seed
        return 0 if profile.derandomize else None


#: ``Report.meta`` key under which :func:`timed_unit` hands a unit's times back (popped by ``run_units``)
UNIT_TIME = "unit_time"


def timed_unit(fn: Callable[..., Report], args: tuple) -> Report:
    """``fn(*args)`` with its times in ``meta[UNIT_TIME]``: ``cpu``, the CPU seconds of the process that ran
    it (:func:`verimono.execution.timing.cpu_now`: a worker process runs one unit at a time, and a subject that computes on
    threads of its own, XLA's, is counted), ``wall``, and ``pid``, so that the run does not count twice the
    units that ran in its own process (a serial run: :func:`run_stages` times those itself); and
    ``calibration_cpu``, slices of the calibration workload measured right after it in the same process
    (:func:`verimono.execution.calibration.slices_after`), what the stage's CPU time is stated against."""
    pid, c0, w0, (s0, n0) = os.getpid(), cpu_now(), time.perf_counter(), subject_cpu()
    rep = fn(*args)
    if isinstance(rep, Report):
        s1, n1 = subject_cpu()
        cpu = cpu_now() - c0
        rep.meta[UNIT_TIME] = {"cpu": cpu, "wall": time.perf_counter() - w0, "pid": pid,
                               "subject_cpu": s1 - s0, "subject_calls": n1 - n0,
                               "calibration_cpu": slices_after(cpu)}
    return rep


@dataclasses.dataclass(frozen=True)
class Stage:
    """A stage: ``fn(profile, context) -> Report``; ``default``: part of a run that names no stage (a stage on
    request runs only when named, ``--stage NAME``, or when ``verimono check`` chooses it for its target)."""
    name: str
    fn: Callable[[Profile, RunContext], Report]
    description: str = ""
    default: bool = True
    #: ``prepare(profile, context)``, run in this process before the worker processes start (:func:`prepare_stages`):
    #: what the stage's units will unpickle is then imported once, here, and inherited by forked workers
    prepare: Callable[[Profile, RunContext], None] | None = None


STAGES: dict[str, Stage] = {}


def prepare_stages(names: Iterable[str] | None, profile: Profile, context: RunContext) -> None:
    """Each stage's ``prepare`` (:class:`Stage`) for the stages ``names`` (``None``: the default ones); one that
    raises is left to its stage, which meets the same error and records it."""
    for n in default_stages() if names is None else names:
        stage = STAGES.get(n)
        if stage is not None and stage.prepare is not None:
            try:
                stage.prepare(profile, context)
            except Exception:  # noqa: BLE001 - the stage itself reports it
                pass


def default_stages() -> list[str]:
    """The stages a run that names none runs, in registration order."""
    return [n for n, s in STAGES.items() if s.default]


def register_stage(name: str, description: str = "", *, default: bool = True,
                   prepare: Callable[[Profile, RunContext], None] | None = None) -> Callable:
    """Decorator registering ``fn(profile, context) -> Report`` as the stage ``name`` (replaces same name);
    ``default=False``: a stage on request; ``prepare``: run before the workers start (:class:`Stage`)."""

    def deco(fn: Callable[[Profile, RunContext], Report]) -> Callable:
        STAGES[name] = Stage(name, fn, description or (fn.__doc__ or "").strip().split("\n")[0], default, prepare)
        return fn

    return deco


def _stage_failure(name: str, exc: BaseException, duration: float) -> tuple[Report, str, str]:
    """The one record of a stage that raised, judged by the checks' exception policy."""
    status, message = classify(exc)
    rec = new_record("stage", name, status, message=message, duration=duration)
    if status == FAILED:
        rec.details["traceback"] = traceback.format_exc(limit=6)
        return Report([rec]), "error", message
    return Report([rec]), "skipped" if status == SKIPPED else status, message


def run_stages(names: Iterable[str] | None, profile: Profile, context: RunContext,
               on_start: Callable[[Stage, int, int], None] | None = None,
               on_done: Callable[[Stage, Report, dict], None] | None = None) -> Report:
    """Run the stages ``names`` (``None``: the default ones, in registration order) and merge their reports."""
    names = default_stages() if names is None else list(names)
    for n in names:
        if n not in STAGES:
            raise UnknownStage(f"unknown stage {n!r}; registered stages: {', '.join(STAGES)}")
    total = Report(meta={"stages": []})
    for i, n in enumerate(names):
        stage = STAGES[n]
        if on_start:
            on_start(stage, i, len(names))
        start = time.perf_counter()
        serial = context.executor is None or isinstance(context.executor, SerialRunner)
        # this process's part: all of it when the units run here; else this thread's (it hands out the units
        # and merges what comes back; a report warm-up thread of this process is not the stage's)
        own_cpu = cpu_now if serial else time.thread_time
        cpu0, (subj0, calls0), n_units = own_cpu(), subject_cpu(), len(context.unit_times)
        try:
            rep = stage.fn(profile, context)
            if not isinstance(rep, Report):
                raise TypeError(f"stage {n} returned {type(rep).__name__}, expected a verimono.Report")
            status = "failed" if rep.failures else ("undecided" if not rep.ok else "passed")
            message = rep.summary()
        except (Exception, *SUBJECT_EXITS) as exc:  # noqa: BLE001 - a crash is a failure of the run, recorded
            rep, status, message = _stage_failure(n, exc, time.perf_counter() - start)
        duration = time.perf_counter() - start
        units = context.unit_times[n_units:]
        elsewhere = [u for u in units if u.get("pid") != os.getpid()]
        cpu = own_cpu() - cpu0 + sum(u["cpu"] for u in elsewhere)
        subj1, calls1 = subject_cpu()
        subj = subj1 - subj0 + sum(u.get("subject_cpu", 0.0) for u in elsewhere)
        calls = calls1 - calls0 + sum(u.get("subject_calls", 0) for u in elsewhere)
        info = {"name": n, "status": status, "records": len(rep), "duration": duration, "cpu": cpu,
                "message": message}
        if calls:
            info.update({"subject_cpu": subj, "subject_calls": calls})
        slices = [c for u in units for c in u.get("calibration_cpu") or []]
        if not slices or sum(u["cpu"] for u in units) < 0.5 * cpu:   # the stage's work is mostly not its units'
            slices += slices_after(cpu)
        info["calibration_cpu"] = [round(c, 5) for c in slices]
        if units:
            info["units"] = [{"label": u["label"], "cpu": round(u["cpu"], 4), "wall": round(u["wall"], 4)}
                             for u in units]
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


def _reference_names() -> frozenset[str]:
    """Names ``verimono run --reference NAME`` accepts (the reference catalog's)."""
    from verimono.reference import names   # the catalog builds every reference: on first use only

    return names()


def locate_data(explicit: str | os.PathLike | None = None) -> Path:
    """The data folder of the siconos stage: ``explicit``, else ``$VERIMONO_SHARED`` if it is a folder, else
    the Siconos data shipped in the package (``verimono/data``); a given folder must hold that layout."""
    env = os.environ.get("VERIMONO_SHARED")
    if explicit is not None:
        path = Path(explicit)
    elif env and Path(env).is_dir():
        path = Path(env)
    else:
        return PACKAGED_DATA
    try:
        siconos_root(path)
    except FileNotFoundError as exc:
        raise StageUnavailable(f"data folder {path}: {exc}") from None
    return path


__all__ = ["STAGES", "Stage", "default_stages", "RunContext", "register_stage", "run_stages", "prepare_stages", "locate_data", "timed_unit", "UNIT_TIME"]
