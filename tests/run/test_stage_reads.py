"""A stage that reads another stage's results (``context.costs``, ``context.partitions``) must declare it
(``register_stage(..., after=...)``): undeclared, on worker processes it runs at once with the writer and reads
whatever is there.  Reading it undeclared is now a typed error, :class:`verimono.core.errors.UndeclaredStageRead`
(a failed ``stage[...]`` record), under every executor alike (issue 43, the fourth probe's item 3).  On 9e58e7d
the undeclared reader read silently: here, after the writer in a serial run, the value; on the shared queue,
nothing."""

from __future__ import annotations

import pickle

import pytest

from verimono.core.errors import UndeclaredStageRead
from verimono.execution.profiles import get_profile
from verimono.records.results import CheckResult, Report
from verimono.run.stages import STAGES, RunContext, StageResults, register_stage, run_stages


@pytest.fixture
def user_stages():
    before = dict(STAGES)

    @register_stage("probe4_writer", overlap=True, writes=("costs",))
    def writer(profile, context):
        context.costs["subject"] = 2.0
        return Report([CheckResult("wrote", "subject", "passed", worst=0.5, bound=1.0)])

    def reader(profile, context):
        seen = context.costs.get("subject")
        return Report([CheckResult("read", "subject", "passed" if seen == 2.0 else "failed", worst=0.5, bound=1.0,
                                   details={"seen": seen})])

    yield reader
    STAGES.clear()
    STAGES.update(before)


def test_a_stage_reading_an_undeclared_stages_results_fails_with_a_typed_error(user_stages):
    register_stage("probe4_reader", overlap=True)(user_stages)          # no after=
    rep = run_stages(["probe4_writer", "probe4_reader"], get_profile("ci"), RunContext(seed=0))
    (rec,) = [r for r in rep.results if r.subject == "probe4_reader"]
    assert rec.check == "stage" and rec.status == "failed"
    assert "UndeclaredStageRead" in rec.message and "after=('probe4_writer',)" in rec.message
    assert [s["status"] for s in rep.meta["stages"]] == ["passed", "error"]


def test_the_same_stage_declaring_the_writer_reads_its_value(user_stages):
    register_stage("probe4_reader", overlap=True, after=("probe4_writer",))(user_stages)
    rep = run_stages(["probe4_writer", "probe4_reader"], get_profile("ci"), RunContext(seed=0))
    assert [(r.check, r.status) for r in rep.results] == [("wrote", "passed"), ("read", "passed")]


def test_a_writer_not_in_the_run_and_reads_outside_a_stage_are_not_checked(user_stages):
    register_stage("probe4_reader", overlap=True)(user_stages)
    ctx = RunContext(seed=0, costs={"subject": 2.0})
    rep = run_stages(["probe4_reader"], get_profile("ci"), ctx)          # the writer is not part of this run
    assert [(r.check, r.status) for r in rep.results] == [("read", "passed")]
    assert ctx.costs["subject"] == 2.0 and isinstance(ctx.costs, StageResults) and ctx.costs.run == ()
    assert STAGES["convergence"].writes == ("costs", "partitions") and "convergence" in STAGES["trajectory_laws"].after
    assert type(pickle.loads(pickle.dumps(ctx.costs))) is dict


def test_the_error_is_a_verimono_error():
    from verimono.core.errors import VerimonoError

    assert issubclass(UndeclaredStageRead, VerimonoError)


def test_a_stage_named_before_the_stage_it_reads_runs_after_it(user_stages):
    """``after`` promises the reader starts once the writer has ended; named first (``--stage trajectory_laws
    --stage convergence``) it ran first and read nothing — on 9e58e7d trajectory_laws so judged 21 worst ratios
    other than a whole run's (the convergence studies' grids missing)."""
    register_stage("probe4_reader", overlap=True, after=("probe4_writer",))(user_stages)
    rep = run_stages(["probe4_reader", "probe4_writer", "probe4_reader"], get_profile("ci"), RunContext(seed=0))
    assert [s["name"] for s in rep.meta["stages"]] == ["probe4_writer", "probe4_reader", "probe4_reader"]
    assert [(r.check, r.status) for r in rep.results] == [("wrote", "passed"), ("read", "passed"), ("read", "passed")]
