"""A stage's status says what it verified: a stage whose records were all skipped (or that returned none) verified
nothing and is ``skipped``, never ``passed`` (``Report.verified``); ``failed`` and ``undecided`` as their records."""

from __future__ import annotations

import io

import pytest

from verimono.execution.profiles import get_profile
from verimono.records.results import CheckResult, Report
from verimono.run.progress import Progress
from verimono.run.stages import STAGES, RunContext, register_stage, run_stages


@pytest.fixture
def stage_of():
    before = dict(STAGES)

    def make(name, statuses):
        @register_stage(name)
        def fn(profile, context):
            return Report([CheckResult("law", f"{name} #{i}", s, worst=0.5 if s == "passed" else None, bound=1.0,
                                       message=f"{s} here") for i, s in enumerate(statuses)])
        return name

    yield make
    STAGES.clear()
    STAGES.update(before)


@pytest.mark.parametrize("statuses, expected", [((), "skipped"), (("skipped", "skipped"), "skipped"),
                                                (("skipped", "xfail"), "skipped"), (("skipped", "passed"), "passed"),
                                                (("passed", "undecided"), "undecided"),
                                                (("passed", "undecided", "failed"), "failed")])
def test_a_stage_that_verified_nothing_is_skipped(stage_of, statuses, expected):
    name = stage_of("status_probe", statuses)
    stream = io.StringIO()
    progress = Progress(stream=stream)
    rep = run_stages([name], get_profile("ci"), RunContext(seed=0), on_start=progress.start, on_done=progress.done)
    assert [s["status"] for s in rep.meta["stages"]] == [expected]
    assert f"status_probe: {expected}" in stream.getvalue()
