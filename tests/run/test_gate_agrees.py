"""The gate agrees with what ``verimono baseline`` said of it (issue 41, item 6).

``verimono baseline`` of a run with failing checks warns that "the gate will only catch new ones"; the gate then
reported the order below the theoretical one as a regression on that very run — an absolute rule applied
whatever the baseline held.  A study below its theoretical order is now a regression only when it is new: the
baseline's study of the same stepper on the same problem was not below it (or there was none)."""

from __future__ import annotations

import copy

import pytest

from verimono.checks import check_stepper
from verimono.cli import main
from verimono.core.stepping import solve
from verimono.records.results import Report
from verimono.reference import get
from verimono.run.gate import compare


@pytest.fixture(scope="module")
def good() -> Report:
    rep = check_stepper(solve, [get("moving box"), get("tnorm-1")], laws=False)
    rep.meta.update({"command": "run", "profile": "ci", "target": None, "calibration": 0.05})
    return Report.from_dict(rep.to_dict())


def _lowered(rep: Report, problem: str = "moving box") -> Report:
    """``rep`` with the order of its study of ``problem`` at 1 (theory: 2), its record failed."""
    out = Report.from_dict(copy.deepcopy(rep.to_dict()))
    fit = next(s for s in out.studies if s.problem == problem).fits["sup"]
    fit.slope, fit.low, fit.high = 1.0, 0.98, 1.02
    rec = next(r for r in out.results if r.check == "convergence_order" and problem in r.subject)
    rec.status, rec.message = "failed", "measured 1.000 [0.980, 1.020], expected 2"
    return out


def test_an_order_below_theory_that_the_baseline_recorded_is_not_a_regression(good):
    bad = _lowered(good)
    comp = compare(bad, _lowered(good))
    assert comp.ok, [str(c) for c in comp.regressions]
    assert any(c.kind == "order" and "as in the baseline" in c.message for c in comp.others)


def test_an_order_newly_below_theory_regresses(good):
    msgs = [str(c) for c in compare(good, _lowered(good)).regressions]
    assert any("below the theoretical order 2" in m for m in msgs), msgs
    # moved: the baseline below on another problem does not excuse this one
    msgs = [str(c) for c in compare(_lowered(good, "t|x| (n=1)"), _lowered(good)).regressions]
    assert any("moving box" in m and "below the theoretical order 2" in m for m in msgs), msgs


def test_baseline_of_a_failing_run_then_gate_on_it_agree(good, tmp_path, capsys):
    results, base = tmp_path / "results.json", tmp_path / "baseline.json"
    _lowered(good).save(results)
    assert main(["baseline", "--from", str(results), "--out", str(base)]) == 0
    assert "the gate will only catch new ones" in capsys.readouterr().err
    code = main(["gate", "--baseline", str(base), "--results", str(results)])
    out = capsys.readouterr()
    assert code == 0, out.out + out.err
    assert "REGRESSION" not in out.out
