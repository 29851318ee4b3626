"""The shared queue of ``verimono run`` (:mod:`verimono.execution.schedule`): the untimed stages at once, their
units in one queue over the workers, longest expected first — and a report that does not depend on it: the
same records in the same order as one stage after another, each stage its own ``meta["stages"]`` entry, a
stage that reads another's results started after it, and a gate that judges the stages that overlapped by the
wall of their group (a baseline made one stage after another: no false regression)."""

from __future__ import annotations

import copy

import pytest

from verimono.execution.executors import ProcessRunner, Unit
from verimono.execution.profiles import get_profile
from verimono.execution.schedule import SharedQueue, _Job
from verimono.records.results import CheckResult, Report
from verimono.run.gate import compare
from verimono.run.stages import STAGES, RunContext, register_stage, run_stages

BUSY = {"cpu_waiting": 0.99, "foreign_cpu": 0.75, "loadavg": 5.1}
QUIET = {"cpu_waiting": 0.02, "foreign_cpu": 0.01, "loadavg": 0.1}


def stage(name, *, cpu, slices, wall, machine=QUIET):       # as tests/run/test_gate_cpu.py writes them
    return {"name": name, "status": "passed", "records": 1, "duration": wall, "cpu": cpu,
            "calibration_cpu": list(slices), **machine}


def run(*stages, cal=0.065) -> Report:
    rep = Report([CheckResult("convergence_order", "solve on box", "passed", worst=0.5, bound=1.0)])
    rep.meta.update({"command": "run", "profile": "ci", "executor": "process:2", "calibration": cal,
                     "calibrations": [cal, cal], "stages": [dict(s) for s in stages]})
    return rep


def spread(center, n=14, width=0.04):
    return [center * (1 - width + 2 * width * i / (n - 1)) for i in range(n)]


def _square_unit(stage: str, k: int) -> Report:
    """A unit whose record is a closed form: k^2 (the worst ratio k^2 / (k^2 + 1) < 1)."""
    return Report([CheckResult("square", f"{stage} #{k}", "passed", worst=k * k / (k * k + 1.0), bound=1.0,
                               details={"value": k * k})])


@pytest.fixture
def three_stages():
    """``sq_a`` (3 units), ``sq_b`` (2 units, reads what ``sq_a`` left in the context), ``sq_c`` (4 units)."""
    seen = {}

    @register_stage("sq_a", overlap=True)
    def sq_a(profile, context):
        reps = context.run_units(profile, [Unit("sq_a", f"a{k}", _square_unit, ("sq_a", k)) for k in range(3)])
        context.costs["sq_a"] = float(sum(len(r) for r in reps))
        return Report([r for rep in reps for r in rep.results])

    @register_stage("sq_b", overlap=True, after=("sq_a",))
    def sq_b(profile, context):
        seen["sq_a"] = context.costs.get("sq_a")       # sq_a has ended: its 3 records are known
        reps = context.run_units(profile, [Unit("sq_b", f"b{k}", _square_unit, ("sq_b", k)) for k in (5, 6)])
        return Report([r for rep in reps for r in rep.results])

    @register_stage("sq_c", overlap=True)
    def sq_c(profile, context):
        reps = context.run_units(profile, [Unit("sq_c", f"c{k}", _square_unit, ("sq_c", k)) for k in range(7, 11)])
        return Report([r for rep in reps for r in rep.results])

    yield seen
    for n in ("sq_a", "sq_b", "sq_c"):
        STAGES.pop(n, None)


def _records(rep: Report) -> list[tuple]:
    return [(r.check, r.subject, r.status, r.worst, r.bound, r.details.get("value"), r.details.get("stage"))
            for r in rep.results]


@pytest.mark.slow   # two worker processes start (1-2 s); `verimono run` in tests/execution covers the path by default
def test_stages_at_once_give_the_report_of_one_after_another(three_stages):
    """Same records, same order, one entry per stage in the stages' order; the dependent stage saw its
    predecessor's result; the stages that ran at once say so, with the wall of their group."""
    names, profile = ["sq_a", "sq_b", "sq_c"], get_profile("ci")
    runner = ProcessRunner(2)
    try:
        done = []
        shared = run_stages(names, profile, RunContext(executor=runner),
                            on_done=lambda st, rep, info: done.append(st.name))
        assert three_stages["sq_a"] == 3.0
        alone = run_stages(names, profile, RunContext(executor=runner, schedule="stages"))
    finally:
        runner.close()
    assert _records(shared) == _records(alone) and len(shared) == 9
    assert [r.details["value"] for r in shared.results] == [0, 1, 4, 25, 36, 49, 64, 81, 100]
    assert done == names == [s["name"] for s in shared.meta["stages"]]
    for info in shared.meta["stages"]:
        assert sorted(info["overlapped"] + [info["name"]]) == names
        assert info["group_duration"] >= info["duration"] > 0 and len(info["units"]) == {"sq_a": 3, "sq_b": 2,
                                                                                        "sq_c": 4}[info["name"]]
    assert all("overlapped" not in info for info in alone.meta["stages"])


class _Conn:
    def __init__(self, sent):
        self.sent = sent

    def send_bytes(self, payload):
        self.sent.append(payload)


def test_the_queue_hands_out_a_stage_others_wait_for_first_then_the_longest_expected():
    """Three idle workers, units of two stages: the unit of the stage another waits for goes first whatever
    its cost, then the two longest expected of any stage (a FIFO or per-stage order fails this)."""

    class Fake:
        spec, workers, timeout, on_report, _pool = "fake", 3, None, None, []

    queue = SharedQueue(Fake(), first=["conv"])
    conv = _Job(0, [Unit("conv", "c0", _square_unit, ("conv", 0))], None, lambda *a: None, [0.01], "conv")
    other = _Job(1, [Unit("ops", f"o{k}", _square_unit, ("ops", k)) for k in range(4)], None, lambda *a: None,
                 [0.2, 5.5, 0.4, 3.5], "ops")
    sent: list = []
    idle = [(None, _Conn(sent)) for _ in range(3)]
    busy: dict = {}
    queue._assign(idle, busy, [(j, i) for j in (conv, other) for i in j.pending])
    handed = [job.units[i].label for _, job, i, _ in busy.values()]
    assert len(sent) == 3 and handed == ["c0", "o1", "o3"], handed
    assert other.pending == [0, 2] and conv.pending == []


def _overlapped(name, others, wall, group, machine=QUIET):
    st = stage(name, cpu=0.9, slices=spread(0.065), wall=wall, machine=machine)
    st.update(overlapped=others, group_duration=group)
    return st


def test_the_gate_judges_stages_that_ran_at_once_by_their_groups_wall():
    """A baseline of two stages one after another (3 s + 4 s) against a run of the same stages at once: a
    group of 5 s (each stage's own span ~5 s, more than its old wall) is no regression; a group of 15 s on a
    quiet machine with the CPU unchanged is (time off the CPU), on a busy machine it is not judged."""
    base = run(stage("a", cpu=0.9, slices=spread(0.065), wall=3.0),
               stage("b", cpu=0.9, slices=spread(0.065), wall=4.0))
    fast = run(_overlapped("a", ["b"], 4.9, 5.0), _overlapped("b", ["a"], 5.0, 5.0))
    assert compare(base, fast).ok and not [c for c in compare(base, fast).changes if c.kind == "timing"]
    slow = run(_overlapped("a", ["b"], 14.9, 15.0), _overlapped("b", ["a"], 15.0, 15.0))
    regs = [str(c) for c in compare(base, slow).regressions]
    assert len(regs) == 1 and "stage a + b" in regs[0] and "off the CPU" in regs[0], regs
    busy = run(_overlapped("a", ["b"], 14.9, 15.0, BUSY), _overlapped("b", ["a"], 15.0, 15.0, BUSY))
    assert compare(base, busy).ok
    # the new schedule as the baseline too: group against group
    assert compare(copy.deepcopy(fast), slow).regressions and compare(fast, fast).ok


def test_a_group_whose_stages_all_read_each_other_runs_one_after_another():
    """``verimono check``'s convergence and trajectory_laws (the second reads the first): nothing could overlap, so
    no thread and no queue; a stage that reads neither may overlap; a chain through a third stage is a chain."""
    from verimono.run.stages.ordering import _some_run_at_once

    made = {"ch_a": (), "ch_b": ("ch_a",), "ch_c": ("ch_b",), "ch_d": ()}
    for name, after in made.items():
        register_stage(name, overlap=True, after=after)(lambda profile, context: Report())
    try:
        assert not _some_run_at_once(["ch_a", "ch_b"])
        assert not _some_run_at_once(["ch_a", "ch_b", "ch_c"])        # ch_c reads ch_a through ch_b
        assert _some_run_at_once(["ch_a", "ch_b", "ch_d"])            # ch_d reads neither
        assert _some_run_at_once(["ch_a", "ch_d"])
    finally:
        for name in made:
            STAGES.pop(name, None)


def test_a_stage_named_twice_never_runs_at_once_with_itself(monkeypatch):
    """``verimono run --stage siconos --stage siconos``: the two were one group, two threads of the same stage
    keyed by one name (one slot, one end event): the same report given twice, each entry listing both threads'
    units and ``overlapped`` empty.  A name already in a group now starts the next group, as one stage after
    another runs it twice."""
    from verimono.run.stages import runner

    for name in ("dup_a", "dup_b"):
        register_stage(name, overlap=True)(lambda profile, context: Report())
    groups = []
    monkeypatch.setattr(runner, "_can_share", lambda context: True)
    monkeypatch.setattr(runner, "_run_together", lambda group, *a: groups.append(list(group)))

    class _Started:
        def start_all(self):
            return True
    try:
        run_stages(["dup_a", "dup_a", "dup_b", "dup_a"], get_profile("ci"), RunContext(executor=_Started()))
    finally:
        for name in ("dup_a", "dup_b"):
            STAGES.pop(name, None)
    assert groups == [["dup_a", "dup_b"]]     # dup_a alone, then dup_a with dup_b, then dup_a alone


def test_the_console_line_of_a_stage_that_shared_the_workers_says_so():
    """``[6/7] siconos: passed — 29 records, 19.8 s``: siconos' units took 1.9 s of that span; the rest was the
    other five stages' units on the same workers.  The line says the span was shared (docs/run.md: ``duration``
    is the span, ``overlapped`` the stages it ran with); a stage that ran alone is told as before."""
    import io

    from verimono.run.progress import Progress

    out = io.StringIO()
    progress, rep = Progress(out, enabled=False), Report([CheckResult("square", "x", "passed", worst=0.5, bound=1.0)])
    progress.total = 7
    info = {"name": "siconos", "status": "passed", "records": 29, "duration": 19.8, "message": ""}
    progress.done(STAGES["siconos"], rep, {**info, "overlapped": ["convergence", "operator_laws", "trajectory_laws",
                                                                  "assumptions", "section7"]})
    progress.done(STAGES["siconos"], rep, info)
    shared, alone = out.getvalue().splitlines()
    assert "29 records, 19.8 s at once with 5 other stages (" in shared
    assert "29 records, 19.8 s (" in alone
