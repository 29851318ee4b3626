"""Regression rules of the gate, each introduced on purpose and seen to fail the gate with its reason."""

from __future__ import annotations

import copy

import pytest

from verimono.checks import check_stepper
from verimono.run.gate import ERROR_GROWTH, TIMING_GROWTH, IncompatibleBaseline, compare, gate
from verimono.records.results import SchemaError
from verimono.records.results import CheckResult, Report
from verimono.core.stepping import solve

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
                     "stages": [{"name": "operator_laws", "duration": 4.0, "status": "passed", "records": 2,
                                 "cpu": 3.6, "calibration_cpu": [0.05] * 8}]})
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


def test_stage_times_are_compared_only_between_runs_on_the_same_executor(base):
    """A stage's wall time depends on how many workers ran its units: a serial run against a baseline made
    on process:2 takes about twice as long without being slower (measured: operator_laws 6.8 s on process:2,
    12.4 s serial), so those stage times are reported as not compared, never as a regression."""
    cur = fresh(base)
    base.meta["executor"], cur.meta["executor"] = "process:2", "serial"
    cur.meta["stages"][0]["duration"] = 8.0 * TIMING_GROWTH * 1.2
    comp = compare(base, cur)
    assert comp.ok and any(c.kind == "timing" and "not compared" in c.message for c in comp.others)
    cur.meta["executor"] = "process:2"          # the same executor: compared, and the slowdown regresses
    assert any("timing" in m and "stage operator_laws" in m for m in reasons(base, cur))
    del base.meta["executor"], cur.meta["executor"]   # results from before meta.executor: both serial
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


# -- fail closed: every missing, garbled or incompatible document exits 2 --------------------------------

def _study(doc: dict) -> dict:
    return next(s for s in doc["studies"] if s["problem"] == "moving box")


def _record(doc: dict) -> dict:
    return next(r for r in doc["results"] if r["subject"] == "DiodeBridge")


#: (what is wrong, how to break a valid document, the reason the gate must give)
GARBLED = [
    ("record is a string", lambda d: d["results"].__setitem__(0, "passed"), "result record 0"),
    ("record details null", lambda d: _record(d).update(details=None), "details"),
    ("record details a list", lambda d: _record(d).update(details=[1]), "details"),
    ("record subject not a string", lambda d: _record(d).update(subject=3), "subject"),
    ("record status unknown", lambda d: _record(d).update(status="ok"), "status"),
    ("record worst not a number", lambda d: _record(d).update(worst=[0.1]), "worst"),
    ("study is a string", lambda d: d["studies"].__setitem__(0, "moving box"), "convergence study 0"),
    ("study errors a string", lambda d: _study(d).update(errors="x"), "errors"),
    ("study errors of a norm not a list", lambda d: _study(d)["errors"].update(sup=0.1), "errors"),
    ("study error list shorter than mesh", lambda d: _study(d)["errors"]["sup"].pop(), "errors"),
    ("study error not a number", lambda d: _study(d)["errors"]["l2"].__setitem__(0, "big"), "errors"),
    ("study norm missing", lambda d: _study(d)["errors"].pop("l2"), "errors"),
    ("study steps shorter than mesh", lambda d: _study(d)["steps"].pop(), "steps"),
    ("study fits null", lambda d: _study(d).update(fits=None), "fits"),
    ("study fit without slope", lambda d: _study(d)["fits"]["sup"].pop("slope"), "fits"),
    ("study expected order a string", lambda d: _study(d).update(expected="2"), "expected"),
    ("meta.stages a string", lambda d: d["meta"].update(stages="operator_laws"), "stages"),
    ("meta.stages entry a string", lambda d: d["meta"].update(stages=["operator_laws"]), "stages"),
    ("stage duration a string", lambda d: d["meta"]["stages"][0].update(duration="4 s"), "stages"),
    ("meta.calibration a string", lambda d: d["meta"].update(calibration="fast"), "calibration"),
    ("stage cpu a string", lambda d: d["meta"]["stages"][0].update(cpu="3 s"), "cpu"),
    ("stage cpu negative", lambda d: d["meta"]["stages"][0].update(cpu=-1.0), "cpu"),
    ("stage calibration_cpu holds a zero", lambda d: d["meta"]["stages"][0]["calibration_cpu"].append(0), "calibration_cpu"),
]


def _write(tmp_path, name: str, doc: dict):
    import json

    path = tmp_path / name
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.parametrize("role", ["baseline", "results"])
@pytest.mark.parametrize("what, breaks, reason", GARBLED, ids=[g[0] for g in GARBLED])
def test_a_garbled_document_exits_2(base, tmp_path, capsys, role, what, breaks, reason):
    from verimono.cli import main

    good = _write(tmp_path, "good.json", base.to_dict())
    doc = copy.deepcopy(base.to_dict())
    breaks(doc)
    bad = _write(tmp_path, "bad.json", doc)
    files = {"baseline": good, "results": good, role: bad}
    assert main(["gate", "--baseline", str(files["baseline"]), "--results", str(files["results"])]) == 2
    err = capsys.readouterr().err
    assert "bad.json" in err and reason in err


@pytest.mark.parametrize("keep", ["nothing", "skipped records only"])
def test_a_baseline_without_executed_records_exits_2(base, tmp_path, capsys, keep):
    from verimono.cli import main

    doc = copy.deepcopy(base.to_dict())
    doc["studies"] = []
    if keep == "nothing":
        doc["results"] = []
    else:
        for r in doc["results"]:
            r["status"] = "skipped"
    empty = _write(tmp_path, "empty.json", doc)
    results = _write(tmp_path, "results.json", base.to_dict())
    assert main(["gate", "--baseline", str(empty), "--results", str(results)]) == 2
    assert "no executed records" in capsys.readouterr().err


# -- a non-finite value where the baseline had a finite one is a regression --------------------------------

@pytest.mark.parametrize("bad", ["nan", None, "inf"])
def test_a_non_finite_current_error_regresses(base, bad):
    doc = fresh(base).to_dict()
    _study(doc)["errors"]["sup"][1] = bad
    _record(doc)["details"]["error"] = bad
    msgs = reasons(base, Report.from_dict(doc))
    assert any("moving box" in m and "sup error at h=" in m and "not a finite number" in m for m in msgs)
    assert any("DiodeBridge" in m and "error" in m and "not a finite number" in m for m in msgs)


@pytest.mark.parametrize("bad", ["nan", None])
def test_a_non_finite_current_order_regresses(base, bad):
    doc = fresh(base).to_dict()
    _study(doc)["fits"]["l2"].update(slope=bad, low=bad, high=bad)
    msgs = reasons(base, Report.from_dict(doc))
    assert any("moving box" in m and "l2-norm order" in m and "not a finite number" in m for m in msgs)
