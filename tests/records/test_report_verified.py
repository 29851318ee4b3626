"""A report is ``ok`` only when it verified something: a check that evaluated nothing is never a pass.

An empty report, or one whose records were all skipped (no operator member, no exact solution) or all expected
failures, verified nothing: ``Report.ok`` is False there, and the HTML report says so instead of "All checks hold".
"""

from __future__ import annotations

import pytest

from verimono.records.report.html import render
from verimono.records.results import CheckResult, Report


def _rec(status: str, check: str = "monotone") -> CheckResult:
    return CheckResult(check, "subject", status, worst=0.5 if status == "passed" else None, bound=1.0,
                       message=f"{status} record")


@pytest.mark.parametrize("statuses", [(), ("skipped",), ("skipped", "skipped", "xfail"), ("xfail",)])
def test_a_report_that_verified_nothing_is_not_ok(statuses):
    rep = Report([_rec(s) for s in statuses])
    assert not rep.verified and not rep.ok
    page = render(rep)
    assert "All checks hold" not in page and "Nothing verified" in page


@pytest.mark.parametrize("statuses, ok", [(("passed",), True), (("passed", "skipped", "xfail"), True),
                                          (("passed", "failed"), False), (("passed", "undecided"), False)])
def test_one_passed_record_verifies(statuses, ok):
    rep = Report([_rec(s) for s in statuses])
    assert rep.verified and rep.ok is ok
    page = render(rep)
    assert ("All checks hold" in page) is ok and "Nothing verified" not in page
