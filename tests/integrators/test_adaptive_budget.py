"""Steppers that choose their own steps under the unit budget, and `verimono compare` judged only where both
curves were measured, its report's reproduction line run as printed (issue 40, item 6)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

import verimono as vm
from verimono.execution.timeouts import budget

REPO = Path(__file__).resolve().parents[2]
TARGETS = "tests/integrators/budget_targets.py"


@pytest.mark.slow
def test_a_slow_adaptive_stepper_is_stopped_by_the_budget_and_undecided():
    from verimono.run.targets import load_target

    problem, slow = (load_target(f"{REPO / TARGETS}:{n}") for n in ("problem", "slow"))   # 0.2 s a call, 5 tolerances

    start = time.perf_counter()
    with budget(0.5):
        rep = vm.check_adaptive(slow, [problem])
    took = time.perf_counter() - start
    rec = {r.check: r for r in rep}["tolerance_rate"]
    assert took < 5.0, took                      # the 0.5 s budget, not the study's 1 s and more
    assert rec.status == "undecided" and rec.details["undecided_reason"] == "time budget", rec.message
    assert "2 tolerance runs, all of which held" in rec.message
    # the control: with room for its five runs the same stepper is judged, and passes (explicit Euler: rate 1)
    with budget(30.0):
        assert {r.check: r for r in vm.check_adaptive(slow, [problem])}["tolerance_rate"].status == "passed"


@pytest.mark.slow
def test_verimono_check_on_a_slow_adaptive_stepper_ends_within_its_timeout(tmp_path):
    from verimono.cli import main

    start = time.perf_counter()
    code = main(["check", f"{REPO / TARGETS}:slow", "--reference", "linear", "--timeout", "0.5", "--executor", "serial",
                 "--profile", "dev", "--out", str(tmp_path)])
    assert time.perf_counter() - start < 30.0
    assert code == 2                              # undecided: no verdict earned, never a pass and never a hang
    records = json.loads((tmp_path / "results.json").read_text())["results"]
    rate = [r for r in records if r["check"] == "tolerance_rate"]
    assert [r["status"] for r in rate] == ["undecided"] and "time budget" in rate[0]["message"]


@pytest.mark.slow
def test_compare_on_disjoint_cpu_ranges_is_undecided_and_its_reproduce_line_runs_as_printed(tmp_path):
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"}
    first = subprocess.run(["verimono", "compare", f"{TARGETS}:euler", f"{TARGETS}:proximal", "--problem",
                            f"{TARGETS}:coarse", "--out", str(tmp_path / "a")], cwd=REPO, env=env,
                           capture_output=True, text=True, timeout=300)
    doc = json.loads((tmp_path / "a" / "results.json").read_text())
    time_rec = next(r for r in doc["results"] if r["check"] == "work_precision")
    # euler's runs cost well under 20 ms of CPU, every run of the other more: no common range of CPU time
    assert time_rec["status"] == "undecided", time_rec["message"]
    assert time_rec["details"]["undecided_reason"] == "work ranges do not overlap"
    assert first.returncode == (1 if any(r["status"] == "failed" for r in doc["results"]) else 2), first.stderr
    line = time_rec["details"]["reproduce"]
    html = (tmp_path / "a" / "report.html").read_text()
    assert "verimono compare " in html and "--profile" not in line
    again = subprocess.run(line, shell=True, cwd=REPO, env=env, capture_output=True, text=True, timeout=300)
    assert "usage:" not in again.stderr and again.returncode == first.returncode, again.stderr
    redo = json.loads((tmp_path / "a" / "results.json").read_text())
    assert redo["meta"]["run_id"] != doc["meta"]["run_id"]
    assert sorted((r["check"], r["subject"]) for r in redo["results"]) == \
        sorted((r["check"], r["subject"]) for r in doc["results"])
