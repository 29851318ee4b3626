"""What every stage may use: :class:`RunContext` (the stepper, the problems, the executor, the results earlier stages
wrote) and its ``run_units``, which runs a stage's units on the executor, timed (:mod:`.unit_timing`)."""

from __future__ import annotations

import dataclasses
import statistics
import threading
from pathlib import Path
from typing import Any, Callable

from ...execution.executors import SerialRunner
from ...execution.profiles import Profile
from ...execution.schedule import SharedQueue
from ...records.results import Report
from .current import _running_stage
from .results import StageResults
from .unit_timing import UNIT_TIME, timed_unit


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
    #: how the stages run on a worker pool of 2 or more processes: ``"shared"``, the stages that may overlap
    #: (:attr:`Stage.overlap`) at once, their units in one queue over the workers, longest expected first
    #: (:mod:`verimono.execution.schedule`); ``"stages"``, one stage after another, as before
    schedule: str = "shared"
    #: the expected seconds of a unit by ``(stage, label)``, e.g. the baseline's (:func:`expected_costs`): the
    #: order of the shared queue only (a wrong or missing figure costs speed, never a record)
    expected: dict[tuple[str, str], float] = dataclasses.field(default_factory=dict)

    _catalog: list[Any] | None = dataclasses.field(default=None, repr=False)

    def __post_init__(self) -> None:
        # what one stage writes for the later ones: a read by a stage that did not declare the writer is an error
        self.costs = StageResults("costs", self.costs)
        self.partitions = StageResults("partitions", self.partitions)

    def catalog(self) -> list[Any]:
        """``problems`` if given, else the reference catalog (built once per run); then ``extra_problems``."""
        if self.problems is not None:
            return list(self.problems) + list(self.extra_problems)
        with _CATALOG_LOCK:          # stages running at once build it once
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
        if isinstance(runner, SharedQueue):     # one queue with the other stages' units, longest expected first
            out = runner.map(timed, profile.name, self.progress, costs=self._expected(units, costs),
                             stage=_running_stage())
        elif costs is None or isinstance(runner, SerialRunner):
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
                self.unit_times.append({"stage": u.stage, "label": u.label, "run_stage": _running_stage(), **t})
        return out

    def _expected(self, units: list[Any], costs: list[float] | None) -> list[float]:
        """Each unit's expected seconds in the shared queue: its figure in :attr:`expected`, else the median of
        its stage's figures there, else its ``costs`` guess (another scale: it only orders a stage without
        figures), else 0 (the units then go in their stages' and their own order)."""
        by_stage: dict[str, list[float]] = {}
        for (stage, _), sec in self.expected.items():
            by_stage.setdefault(stage, []).append(sec)
        out = []
        for i, u in enumerate(units):
            sec = self.expected.get((u.stage, u.label))
            if sec is None and by_stage.get(u.stage):
                sec = statistics.median(by_stage[u.stage])
            out.append(float(sec) if sec is not None else float(costs[i]) if costs is not None else 0.0)
        return out

    def seed_for(self, profile: Profile) -> int | None:
        """The seed a randomized battery uses: ``seed`` if given, else 0 under a derandomized profile
        (``ci``: the same records in every job), else ``None`` (a fresh seed, recorded in each record)."""
        if self.seed is not None:
            return self.seed
        return 0 if profile.derandomize else None


_CATALOG_LOCK = threading.Lock()
