"""Regression rules of the gate, each introduced on purpose and seen to fail the gate with its reason."""

from __future__ import annotations

import copy

import pytest

from verimono.checks.orders import check_stepper
from verimono.gate import ERROR_GROWTH, TIMING_GROWTH, IncompatibleBaseline, compare, gate
from verimono.report.schema import SchemaError
from verimono.results import CheckResult, Report
from verimono.stepping import solve

REFS = ["t|x| (n=1)", "moving box"]


@pytest.fixture(scope="module")
def base() -> Report:
    from verimono.reference import get

    rep = check_stepper(solve, [get(n) for n in REFS])
    rep.add(CheckResult("monotone", "Linear", "passed", worst=0.5, bound=1.0))
    rep.add(CheckResult("monotone", "Ball", "passed", worst=0.2, bound=1.0))
    rep.add(CheckResult("siconos_agreement", "DiodeBridge", "passed", worst=0.1, bound=1.0,
                        details={"error": 1e-9}))
    rep.meta.update({"command": "run", "profile": "ci", "target": None, "calibration": 0.05,
                     "stages": [{"name": "operator_laws", "duration": 4.0, "status": "passed", "records": 2}]})
    return Report.from_dict(rep.to_dict())


def fresh(base: Report) -> Report:
    return Report.from_dict(copy.deepcopy(base.to_dict()))


def reasons(base: Report, cur: Report) -> list[str]:
    return [str(c) for c in compare(base, cur).regressions]


def test_identical_results_pass(base):
    comp = compare(base, fresh(base))
    assert comp.ok and comp.compared == len(base)


def test_a_check_that_passed_and_now_fails_regresses(base):
    cur = fresh(base)
    rec = next(r for r in cur if r.key == "monotone[Linear]")
    rec.status, rec.message = "failed", "ratio 1.3 > 1"
    assert reasons(base, cur) == ["REGRESSION status   monotone[Linear]: passed → failed: ratio 1.3 > 1"]


def test_a_removed_check_regresses_by_key_and_by_count(base):
    cur = fresh(base)
    cur.results = [r for r in cur.results if r.key != "monotone[Ball]"]
    msgs = reasons(base, cur)
    assert any("removed" in m and "monotone[Ball]" in m for m in msgs)
    assert any("count" in m and "monotone: executed records fell from 2 to 1" in m for m in msgs)
    assert any("total" in m for m in msgs)


def test_a_skipped_battery_regresses(base):
    cur = fresh(base)
    for r in cur.results:
        if r.check == "monotone":
            r.status, r.message = "skipped", "verimono.checks.operator_laws is not installed"
    msgs = reasons(base, cur)
    assert any("passed → skipped" in m for m in msgs)
    assert any("monotone: executed records fell from 2 to 0" in m for m in msgs)


def test_a_lowered_order_regresses_against_baseline_and_theory(base):
    cur = fresh(base)
    study = next(s for s in cur.studies if s.problem == "moving box")
    fit = study.fits["sup"]
    fit.slope, fit.low, fit.high = 1.0, 0.98, 1.02
    msgs = reasons(base, cur)
    assert any("order" in m and "below the theoretical order 2" in m for m in msgs)
    assert any("sup-norm order fell from 2.000" in m for m in msgs)


def test_a_small_order_wobble_within_the_interval_passes(base):
    cur = fresh(base)
    fit = next(s for s in cur.studies if s.problem == "t|x| (n=1)").fits["sup"]
    fit.slope -= 0.01
    assert compare(base, cur).ok


def test_error_growth_beyond_the_factor_regresses(base):
    cur = fresh(base)
    study = next(s for s in cur.studies if s.problem == "moving box")
    study.errors["sup"] = [e * (ERROR_GROWTH * 1.5) for e in study.errors["sup"]]
    assert any("sup error at h=" in m and "grew" in m for m in reasons(base, cur))
    cur = fresh(base)
    next(r for r in cur if r.subject == "DiodeBridge").details["error"] = 1e-9 * ERROR_GROWTH * 2
    assert any("DiodeBridge" in m and "error grew" in m for m in reasons(base, cur))
    cur = fresh(base)
    next(r for r in cur if r.subject == "DiodeBridge").details["error"] = 1e-9 * ERROR_GROWTH * 0.9
    assert compare(base, cur).ok


def test_timings_are_compared_as_same_job_ratios(base):
    cur = fresh(base)
    cur.meta["calibration"] = 0.10          # a machine twice as slow ...
    cur.meta["stages"][0]["duration"] = 8.0  # ... takes twice as long: no regression
    assert compare(base, cur).ok
    cur.meta["stages"][0]["duration"] = 8.0 * TIMING_GROWTH * 1.2
    assert any("timing" in m and "stage operator_laws" in m for m in reasons(base, cur))


def test_new_records_and_fixes_are_changes_not_regressions(base):
    cur = fresh(base)
    cur.add(CheckResult("monotone", "Box", "passed"))
    comp = compare(base, cur)
    assert comp.ok and any(c.kind == "new" for c in comp.others)


def test_incompatible_runs_fail_closed(base, tmp_path):
    cur = fresh(base)
    cur.meta["profile"] = "dev"
    with pytest.raises(IncompatibleBaseline, match="profile"):
        gate(base, cur)
    (tmp_path / "garbled.json").write_text('{"schema": "verimono.results", "schema_')
    with pytest.raises(SchemaError):
        gate(tmp_path / "garbled.json", cur)
