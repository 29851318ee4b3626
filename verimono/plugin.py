"""pytest plugin of verimono (entry point ``pytest11: verimono = verimono.plugin``).

* Registers the hypothesis profiles ``dev``, ``ci``, ``thorough`` (:mod:`verimono.execution.profiles`) and loads
  ``$HYPOTHESIS_PROFILE``, else ``ci`` when ``$CI`` is set, else ``dev`` — unless ``--hypothesis-profile``
  was given, which wins.
* ``--verimono-report DIR`` collects the result records of the session — every record a test hands to
  the ``verimono_report`` fixture, every record :func:`verimono.records.results.emit`-ted during a test (as
  ``verimono.testing.parametrize_with_checks`` does), and every record a ``verimono`` check passed in as
  a test argument returns — and writes ``DIR/results.json`` and ``DIR/report.html``, the same report as
  ``verimono run``.
* ``--verimono-baseline FILE`` gates the session on those records: a regression against ``FILE`` turns a
  green session red (exit status 1) with the reasons in the terminal summary.  A baseline the gate cannot
  use fails closed with pytest's usage-error status 4 (``pytest.ExitCode.USAGE_ERROR``): a missing,
  garbled or empty one (no executed record) before any test runs, with the reason on stderr; one from
  another kind of run (e.g. ``verimono run`` rather than pytest, another profile) at the end of the
  session, which then exits 4 — even if tests failed — with the reason in the terminal summary.
* Under pytest-xdist (``-n N``) each worker attaches the records of a test to that test's call report
  (the attribute ``verimono_records``, a JSON string that xdist carries to the controller with the report);
  the controller collects them and writes the report and gates, in collection order, so ``pytest -n N``
  gives the same records, statuses and summary as ``pytest``.  A call report that arrives without that
  attribute, or made by another process that kept its records (``pid:N``: a forked test), comes from a
  process whose records cannot reach this report (a parallel runner verimono does not know): the session
  says how many tests that was and fails (exit status 1) instead of writing a report that is silently short.
"""

from __future__ import annotations

import functools
import json
import os
import time
from pathlib import Path
from typing import Any

import pytest

from .records.atomic import ensure_writable_dir
from .core.errors import OutputNotWritable
from .records.results import FAILED, MISSING_RECORDS, XFAIL, XFAIL_DECLARED, CheckResult, Report, listening

_KEY = pytest.StashKey["_Collector"]()


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("verimono", "verimono verification report and regression gate")
    group.addoption("--verimono-report", metavar="DIR", default=None,
                    help="write the session's verimono records to DIR/results.json and DIR/report.html")
    group.addoption("--verimono-baseline", metavar="FILE", default=None,
                    help="fail the session when its verimono records regress against this baseline")


def _load_profile(config: pytest.Config) -> str | None:
    """The session's profile — ``--hypothesis-profile`` when given, else the environment's default
    (:func:`verimono.execution.config.from_environment`) — loaded into hypothesis and installed as the
    session's run configuration (:func:`verimono.execution.config.install`), which the checks' search and
    budgets read."""
    from .execution.config import RunConfig, from_environment, install
    from .execution.profiles import load_hypothesis_profile, register_hypothesis_profiles

    register_hypothesis_profiles()
    explicit = config.getoption("hypothesis_profile", default=None)
    if explicit:
        install(RunConfig(profile=explicit, source="--hypothesis-profile"))
        return explicit
    default = from_environment()
    try:
        name = load_hypothesis_profile(default.profile)
    except Exception as exc:  # an unknown $HYPOTHESIS_PROFILE is the user's error: say so
        raise pytest.UsageError(f"verimono: {exc}") from None
    install(default)
    return name


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "verimono: a test whose result records feed the verimono report")
    from .testing import pytest_configure as register_battery_counter

    register_battery_counter(config)  # counts of parametrize_with_checks batteries, in every run
    profile = _load_profile(config)
    out = config.getoption("verimono_report")
    baseline_path = config.getoption("verimono_baseline")
    if not out and not baseline_path:
        return
    baseline = None
    if baseline_path:
        from .run.gate import check_baseline
        from .records.results import SchemaError, load

        try:
            baseline = load(baseline_path)
            check_baseline(baseline)
        except SchemaError as exc:
            raise pytest.UsageError(f"verimono baseline unusable: {exc}") from None
    worker = hasattr(config, "workerinput")  # a pytest-xdist worker: ships its records, writes nothing
    if out and not worker:   # checked before the session's work, not after it
        try:
            ensure_writable_dir(out)
        except OutputNotWritable as exc:
            raise pytest.UsageError(f"--verimono-report: {exc}") from None
    collector = _Collector(None if worker else (Path(out) if out else None), None if worker else baseline,
                           profile, worker=worker)
    config.stash[_KEY] = collector
    config.pluginmanager.register(collector, "verimono-collector")


class _Collector:
    """Session-wide sink of result records (registered only with ``--verimono-report/-baseline``)."""

    #: the attribute of a call report that carries its test's records from an xdist worker
    ATTR = "verimono_records"

    def __init__(self, out: Path | None, baseline: Report | None, profile: str | None, worker: bool = False) -> None:
        self.out, self.baseline, self.profile, self.worker = out, baseline, profile, worker
        self.extras: dict[str, dict[str, list]] = {}   # nodeid -> studies and trajectories of added Reports
        self.order: dict[str, int] = {}                # nodeid -> position in the collection
        self.hidden: list[str] = []                    # call reports whose records could not reach us
        self.crashed: list[str] = []                   # tests whose xdist worker died while running them
        self.report = Report(meta={"command": "pytest", "target": None, "profile": profile, "seed": None})
        self.nodeid: str | None = None
        self.seen: set[int] = set()
        self.by_node: dict[str, list[CheckResult]] = {}
        self.comparison: Any = None
        self.gate_error: str | None = None
        self.start = time.perf_counter()

    def add(self, item: Any) -> None:
        records = item.results if isinstance(item, Report) else [item]
        studies, trajectories = [], []
        for r in records:
            if not isinstance(r, CheckResult) or id(r) in self.seen:
                continue
            self.seen.add(id(r))
            if self.nodeid:
                r.details.setdefault("pytest_nodeid", self.nodeid)
                self.by_node.setdefault(self.nodeid, []).append(r)
            self.report.add(r)
            if r.study is not None and not isinstance(item, Report):
                studies.append(r.study)
        if isinstance(item, Report):
            known = {id(s) for s in self.report.studies}
            studies += [s for s in item.studies if id(s) not in known]
            trajectories = list(item.trajectories)
        self.report.studies.extend(studies)
        self.report.trajectories.extend(trajectories)
        if self.nodeid and (studies or trajectories):
            extra = self.extras.setdefault(self.nodeid, {"studies": [], "trajectories": []})
            extra["studies"].extend(studies)
            extra["trajectories"].extend(trajectories)

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_call(self, item: pytest.Item):
        self.nodeid = item.nodeid
        with listening(self.add):
            yield
        self.nodeid = None

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_makereport(self, item: pytest.Item, call: Any):
        """Mark the call report as seen by verimono; on an xdist worker, attach the test's records."""
        outcome = yield
        report = outcome.get_result()
        if call.when != "call":
            return
        if not self.worker:  # recorded in this process: only say which one (a forked test's records stay
            setattr(report, self.ATTR, f"pid:{os.getpid()}")   # in its child, and the report must say so)
            return
        records = self.by_node.pop(item.nodeid, [])
        extra = self.extras.pop(item.nodeid, {"studies": [], "trajectories": []})
        self.report.results.clear()          # a worker keeps nothing once shipped
        self.report.studies.clear()
        self.report.trajectories.clear()
        self.seen.clear()
        setattr(report, self.ATTR, json.dumps({
            "results": [r.to_dict() for r in records],
            "studies": [s.to_dict() if hasattr(s, "to_dict") else s for s in extra["studies"]],
            "trajectories": extra["trajectories"]}, default=str))

    def pytest_collection_finish(self, session: pytest.Session) -> None:
        self.order = {it.nodeid: i for i, it in enumerate(session.items)}

    @pytest.hookimpl(optionalhook=True)
    def pytest_xdist_node_collection_finished(self, node: Any, ids: list[str]) -> None:
        if not self.order:
            self.order = {nodeid: i for i, nodeid in enumerate(ids)}

    def _receive(self, report: pytest.TestReport) -> None:
        """Records of a test that ran elsewhere (an xdist worker), carried by its call report."""
        from .records.results import CheckResult, to_jsonable
        from .records.schema import study_from_dict

        data = json.loads(getattr(report, self.ATTR))
        self.nodeid = report.nodeid
        try:
            self.add(Report([CheckResult.from_dict(d) for d in data["results"]],
                            [study_from_dict(s, i) for i, s in enumerate(data["studies"])],
                            trajectories=to_jsonable(data["trajectories"])))
        finally:
            self.nodeid = None

    def pytest_runtest_logreport(self, report: pytest.TestReport) -> None:
        """Records from a worker; then: a test marked xfail that failed as declared has its failed records
        as expected failures, the xfail's reason in ``details["xfail_declared"]``."""
        if self.worker:
            return
        if report.when == "call":
            carried = getattr(report, self.ATTR, None)
            if carried is None or (carried.startswith("pid:") and carried != f"pid:{os.getpid()}"):
                self.hidden.append(report.nodeid)   # records held by a process that does not send them here
            elif not carried.startswith("pid:"):
                self._receive(report)
        wasxfail = getattr(report, "wasxfail", None)
        if report.when == "call" and report.skipped and wasxfail is not None:
            for r in self.by_node.get(report.nodeid, []):
                if r.status == FAILED:
                    r.status = XFAIL
                    r.message = f"expected failure ({wasxfail}): {r.message}"
                    r.details[XFAIL_DECLARED] = wasxfail or "declared with pytest.mark.xfail"

    @pytest.hookimpl(tryfirst=True)
    def pytest_pyfunc_call(self, pyfuncitem: pytest.Function) -> None:
        """Wrap verimono checks passed in as arguments so the records they return are collected."""
        for name, value in list(pyfuncitem.funcargs.items()):
            if _is_verimono_check(value):
                pyfuncitem.funcargs[name] = _recording(value, self.add)

    def _in_collection_order(self) -> None:
        """Records, studies and trajectories of parallel workers arrive as tests finish: put them in
        collection order (stably), so the report does not depend on how tests were spread over workers."""
        if not self.order:
            return
        last = len(self.order)
        rank = {id(r): self.order.get(r.details.get("pytest_nodeid"), last) for r in self.report.results}
        self.report.results.sort(key=lambda r: rank[id(r)])
        for kind in ("studies", "trajectories"):
            where = {id(x): self.order.get(nodeid, last) for nodeid, extra in self.extras.items()
                     for x in extra[kind]}
            getattr(self.report, kind).sort(key=lambda x: where.get(id(x), last))

    @pytest.hookimpl(optionalhook=True)
    def pytest_handlecrashitem(self, crashitem: str, report: Any, sched: Any) -> None:
        """An xdist worker died while running ``crashitem``: whatever records that test had made died with it."""
        self.crashed.append(crashitem)

    def pytest_sessionfinish(self, session: pytest.Session, exitstatus: int) -> None:
        if self.worker:
            return
        from .records.environment import environment

        self._in_collection_order()
        if (self.hidden or self.crashed) and session.exitstatus == pytest.ExitCode.OK:
            session.exitstatus = pytest.ExitCode.TESTS_FAILED
        if self.hidden or self.crashed:
            # the records of these tests are missing: the results are short, never a baseline (verimono
            # baseline --from refuses them; the gate shows what they lack against a baseline)
            self.report.meta[MISSING_RECORDS] = {"crashed": list(self.crashed), "hidden": list(self.hidden)}
        self.report.meta.update({"duration": time.perf_counter() - self.start, "environment": environment()})
        stopped = _stopped_early(session, exitstatus)
        if stopped:
            # an interrupted session (Ctrl-C, SIGTERM: pytest's exit status 2) or one told to stop early (-x,
            # --maxfail) verified only part of what it collected: its report says so, and the gate and
            # `verimono baseline --from` refuse it as they refuse an interrupted `verimono run`
            self.report.meta.update({"incomplete": True, "stopped": stopped})
        if self.baseline is not None:
            from .run.gate import check_runs_compatible, compare
            from .records.results import SchemaError

            try:
                check_runs_compatible(self.baseline, self.report)
                self.comparison = compare(self.baseline, self.report)
            except SchemaError as exc:  # IncompatibleBaseline: the gate cannot decide, so it fails closed
                self.gate_error = str(exc)
            if self.gate_error and session.exitstatus in (pytest.ExitCode.OK, pytest.ExitCode.TESTS_FAILED):
                session.exitstatus = pytest.ExitCode.USAGE_ERROR
            elif not self.gate_error and not self.comparison.ok and session.exitstatus == pytest.ExitCode.OK:
                session.exitstatus = pytest.ExitCode.TESTS_FAILED
        if self.out is not None:
            from .records.report import write

            self.paths = write(self.report, self.out, changes=self.comparison)

    def pytest_terminal_summary(self, terminalreporter: Any) -> None:
        if self.worker:
            return
        tr = terminalreporter
        tr.section("verimono")
        tr.write_line(f"{len(self.report)} verimono records: {self.report.summary()} "
                      f"(hypothesis profile {self.profile})")
        if self.hidden:
            tr.write_line(f"verimono: {len(self.hidden)} tests ran where their verimono records cannot reach this "
                          f"report (a parallel runner verimono does not know?), e.g. {self.hidden[0]}: the "
                          "report is incomplete and the session fails (exit status 1); run without that "
                          "runner, or with pytest-xdist (-n N)", red=True)
        if self.out is not None:
            tr.write_line(f"report: {self.out / 'report.html'}  records: {self.out / 'results.json'}")
        if self.report.meta.get("incomplete"):
            tr.write_line(f"verimono: the session stopped early ({self.report.meta.get('stopped')}): its report is "
                          "marked incomplete (the gate and `verimono baseline --from` refuse it)", red=True)
        if self.gate_error:
            tr.write_line(f"verimono gate: cannot compare: {self.gate_error} (exit status 4)", red=True)
        elif self.comparison is not None:
            for c in self.comparison.regressions:
                tr.write_line(f"  {c}", red=True)
            tr.write_line(f"verimono gate: {self.comparison.summary()}",
                          green=self.comparison.ok, red=not self.comparison.ok)


def _stopped_early(session: pytest.Session, exitstatus: Any) -> str | None:
    """Why ``session`` ended before every collected test ran (``None`` when it did not): interrupted, or
    told to stop (``-x``, ``--maxfail``)."""
    if exitstatus == pytest.ExitCode.INTERRUPTED or session.exitstatus == pytest.ExitCode.INTERRUPTED:
        return "interrupted"
    why = session.shouldstop or session.shouldfail
    return str(why) if why else None


def _is_verimono_check(value: Any) -> bool:
    fn = value.func if isinstance(value, functools.partial) else value
    module = getattr(fn, "__module__", "") or ""
    return (callable(value) and not isinstance(value, type) and module.startswith("verimono.")
            and (getattr(fn, "__name__", "") or "").startswith("check"))


def _recording(check: Any, sink: Any) -> Any:
    @functools.wraps(check)
    def recorded(*args: Any, **kwargs: Any) -> Any:
        try:
            out = check(*args, **kwargs)
        except BaseException as exc:  # a check wrapper that fails the test may carry its record
            for attr in ("result", "record", "report"):
                if isinstance(getattr(exc, attr, None), (CheckResult, Report)):
                    sink(getattr(exc, attr))
            raise
        if isinstance(out, (CheckResult, Report)):
            sink(out)
        return out

    return recorded


class RecordSink:
    """What the ``verimono_report`` fixture gives a test: ``add(record_or_report)`` collects it."""

    def __init__(self, collector: _Collector | None) -> None:
        self._collector = collector
        self.report = Report()

    def add(self, item: CheckResult | Report) -> CheckResult | Report:
        if not isinstance(item, (CheckResult, Report)):
            raise TypeError(f"verimono_report.add takes a CheckResult or a Report, got {type(item).__name__}")
        self.report.extend(item) if isinstance(item, Report) else self.report.add(item)
        if self._collector is not None:
            self._collector.add(item)
        return item


@pytest.fixture
def verimono_report(request: pytest.FixtureRequest) -> RecordSink:
    """Hand result records to the session's verimono report: ``verimono_report.add(check_operator(op))``."""
    return RecordSink(request.config.stash.get(_KEY, None))
