"""`verimono gate` and a check or run gated against a baseline say in their normal output, in one line, that a
stage's wall time grew but could not be judged (a run with one calibration: `verimono check`), which only
`verimono gate -v` listed before."""

from __future__ import annotations

from verimono.cli import _finish, main
from verimono.records.results import CheckResult, Report

QUIET = {"cpu_waiting": 0.02, "foreign_cpu": 0.01, "loadavg": 0.1}


def _doc(wall: float, cals: list[float]) -> Report:
    rep = Report([CheckResult("convergence_order", "my_stepper on box", "passed", worst=0.5, bound=1.0)])
    slices = [0.065 * (0.96 + 0.08 * i / 13) for i in range(14)]
    rep.meta.update({"command": "check", "target": "mysolver:my_stepper", "profile": "ci", "executor": "process:2",
                     "calibration": min(cals), "calibrations": cals,
                     "stages": [{"name": "convergence", "status": "passed", "records": 1, "duration": wall,
                                 "cpu": 0.9, "subject_cpu": 0.45, "subject_calls": 77, "calibration_cpu": slices,
                                 **QUIET}]})
    return rep


def test_gate_says_unjudged_wall_growth_without_verbose(tmp_path, capsys):
    base, cur = tmp_path / "base.json", tmp_path / "cur.json"
    _doc(0.6, [0.065, 0.065]).save(base)
    _doc(1.8, [0.065]).save(cur)              # a stepper that sleeps, checked: one calibration
    assert main(["gate", "--baseline", str(base), "--results", str(cur)]) == 0
    out = capsys.readouterr().out
    lines = [ln for ln in out.splitlines() if "not judged" in ln]
    assert len(lines) == 1 and "stage convergence" in lines[0] and "one calibration" in lines[0], out
    _doc(0.6, [0.065]).save(cur)              # no growth: no line
    assert main(["gate", "--baseline", str(base), "--results", str(cur)]) == 0
    assert "not judged" not in capsys.readouterr().out


def test_a_check_against_a_baseline_says_it_too(tmp_path, capsys):
    _finish(_doc(1.8, [0.065]), tmp_path / "out", _doc(0.6, [0.065, 0.065]))
    out = capsys.readouterr().out
    lines = [ln for ln in out.splitlines() if "not judged" in ln]
    assert len(lines) == 1 and "stage convergence" in lines[0] and "3.0x" in lines[0], out
