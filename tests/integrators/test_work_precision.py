"""Work–precision: the verdict on constructed curves (each outcome, both works), the records, the report's
section and the notebook display; end to end under the timing tier; `verimono compare` in the slow tier."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import verimono as vm
from verimono.records.report.html import render
from verimono.records.results import Report
from verimono.run.work_precision import Curve, WorkPrecisionSet, envelope

REPO = Path(__file__).resolve().parents[2]


def curve(name, seconds, errors, spread=0.05, steps=None):
    s = np.asarray(seconds, float)
    return Curve(name, "tolerance", [10.0 ** -k for k in range(len(s))], list(steps or (s * 1e4).astype(int)),
                 {n: list(errors) for n in ("sup", "l2", "final")}, list(s), list(s * (1 - spread)),
                 list(s * (1 + spread)), [[v] * 9 for v in s])


def wp(*curves):
    return WorkPrecisionSet("p", list(curves), "sup", 1e-14, 9, 0.0125)


def test_envelope_is_the_best_run_within_the_work():
    w, e = np.array([1.0, 4.0, 2.0]), np.array([1e-2, 1e-3, 1e-1])     # not monotone: the 2.0 run is worse
    got = envelope(w, e, np.array([0.5, 1.0, 2.0, 8.0]))
    assert got[0] == np.inf and got[1] == 1e-2 and got[2] == 1e-2 and got[3] == 1e-3


@pytest.mark.parametrize("scale", [1.0, 1e-3])
def test_verdicts(scale):
    t = scale * np.array([1.0, 2.0, 4.0, 8.0])
    fast = curve("fast", t, [1e-3, 1e-4, 1e-5, 1e-6])
    slow = curve("slow", 3 * t, [1e-3, 1e-4, 1e-5, 1e-6])              # the same errors at 3x the time
    assert wp(fast, slow).compare("fast", "slow")[0] == "passed"
    status, msg, _ = wp(slow, fast).compare("slow", "fast")
    assert status == "failed" and "more accurate" in msg
    # 3% slower, timed with 20% noise: the noise cannot tell
    noisy = [curve("a", t, [1e-3, 1e-4, 1e-5, 1e-6], 0.2), curve("b", 1.03 * t, [1e-3, 1e-4, 1e-5, 1e-6], 0.2)]
    status, msg, _ = wp(*noisy).compare("a", "b")
    assert status == "undecided" and "noise" in msg
    rec = {r.check: r for r in wp(*noisy).records()}
    assert rec["work_precision"].details["undecided_reason"] == "timing noise"
    # against the number of steps there is no noise: equal curves hold both ways
    assert rec["work_precision_steps"].status == "passed"
    # a high-order curve measured where the other was too: judged over the common range only
    hi_order = curve("hi", scale * np.array([0.1, 0.2, 4.0]), [1e-6, 1e-9, 1e-12])
    assert wp(hi_order, slow).compare("hi", "slow")[0] == "passed"
    assert wp(slow, hi_order).compare("slow", "hi")[0] == "failed"


@pytest.mark.parametrize("work", ["time", "steps"])
def test_disjoint_work_ranges_are_undecided(work):
    # the runs: my_rk45 measured between 0.00026 and 0.0018 s, Radau between 0.00235 and 0.0201 s; Radau
    # was credited "465x more accurate" at works my_rk45 never ran at.  Neither is compared beyond its runs
    mine = curve("my_rk45", [0.00026, 0.0006, 0.0018], [1e-3, 1e-4, 1e-5])
    radau = curve("Radau", [0.00235, 0.006, 0.0201], [1e-7, 1e-10, 1e-12])
    for a, b in (("my_rk45", "Radau"), ("Radau", "my_rk45")):
        status, msg, worst = wp(mine, radau).compare(a, b, work)
        assert status == "undecided" and "share no range of work" in msg and worst != worst, msg
        assert "noise" not in msg                  # not the timing noise: a run with it exits 2, not 0
    rec = {r.check: r for r in wp(mine, radau).records()}
    key = "work_precision" if work == "time" else "work_precision_steps"
    assert rec[key].status == "undecided" and rec[key].details["undecided_reason"] == "work ranges do not overlap"
    # the control: overlapping by one run, the same curves are judged (Radau more accurate where both ran)
    radau_wide = curve("Radau", [0.0015, 0.006, 0.0201], [1e-7, 1e-10, 1e-12])
    assert wp(mine, radau_wide).compare("my_rk45", "Radau", work)[0] == "failed"


def test_records_report_section_and_notebook():
    t = np.array([1e-3, 2e-3, 4e-3])
    s = wp(curve("A", t, [1e-3, 1e-4, 1e-5]), curve("B", 2 * t, [1e-3, 1e-4, 1e-5]), curve("C", 4 * t, [1e-2, 1e-3, 1e-4]))
    recs = s.records()
    assert [(r.check, r.subject, r.status) for r in recs] == [
        ("work_precision", "A vs B on p", "passed"), ("work_precision_steps", "A vs B on p", "passed"),
        ("work_precision", "A vs C on p", "passed"), ("work_precision_steps", "A vs C on p", "passed")]
    back = WorkPrecisionSet.from_dict(json.loads(json.dumps(s.to_dict())))
    assert back.compare("A", "C") == s.compare("A", "C")
    html = render(Report(recs))
    section = html[html.index('<section id="work_precision">'):html.index('<section id="trajectories">')]
    assert section.count("<svg") == 1 and "A vs C on p" in section and "CPU time per run" in section
    nb = s._repr_html_()
    assert "<svg" in nb and "A vs B on p" in nb and 'class="vm-nb"' in nb
    assert "No work–precision comparison" in render(Report())


def test_refusals():
    from verimono.reference import linear

    with pytest.raises(vm.InvalidCheckArgument):
        vm.work_precision([vm.solve], linear.linear())
    with pytest.raises(vm.InvalidCheckArgument):
        vm.work_precision([vm.solve, vm.solve], linear.linear())           # the same name twice
    with pytest.raises(vm.InvalidProblem):
        vm.work_precision([vm.solve, vm.solve_adaptive], linear.linear().replace(exact=None))


@pytest.mark.timing
def test_end_to_end_a_slower_copy_is_not_as_good():
    from verimono.reference import subdifferential

    p = subdifferential.t_norm()

    def twice(problem, t_grid):            # the same states at twice the work
        vm.solve(problem, t_grid)
        return vm.solve(problem, t_grid)

    slow = vm.Stepper(twice, name="solve twice")
    steps = [p.T / k for k in (400, 800, 1600, 3200)]
    s = vm.work_precision([vm.solve, slow], p, controls=steps)
    verdicts = {v["work"]: v["status"] for v in s.verdicts()}
    assert verdicts == {"time": "passed", "steps": "passed"}
    back = {v["work"]: v["status"] for v in s.verdicts("solve twice")}
    assert back["steps"] == "passed" and back["time"] in ("failed", "undecided")


@pytest.mark.slow
def test_verimono_compare_writes_the_diagram(tmp_path):
    targets = [f"tests/integrators/compare_targets.py:{n}" for n in ("radau", "adaptive", "proximal")]
    out = subprocess.run([sys.executable, "-m", "verimono.cli", "compare", *targets, "--problem",
                          "tests/integrators/compare_targets.py:problem", "--out", str(tmp_path)],
                         cwd=REPO, capture_output=True, text=True, timeout=600)
    assert out.returncode in (0, 2), out.stderr
    data = json.loads((tmp_path / "results.json").read_text())
    checks = sorted((r["check"], r["subject"]) for r in data["results"])
    assert checks == sorted((c, f"solve_ivp Radau vs {b} on Lipschitz field and input")
                            for c in ("work_precision", "work_precision_steps") for b in ("solve_adaptive", "solve (uniform)"))
    steps = {r["subject"]: r["status"] for r in data["results"] if r["check"] == "work_precision_steps"}
    assert set(steps.values()) == {"passed"}       # Radau (order 5) beats order-1 schemes step for step
    html = (tmp_path / "report.html").read_text()
    section = html[html.index('<section id="work_precision">'):html.index('<section id="trajectories">')]
    assert section.count("<svg") == 1 and "solve_ivp Radau (tolerances)" in section


@pytest.mark.slow
def test_import_verimono_does_not_load_work_precision():
    code = ("import sys, verimono as vm; assert 'verimono.run.work_precision' not in sys.modules; "
            "assert 'verimono.checks' not in sys.modules; vm.work_precision; "
            "assert 'verimono.run.work_precision' in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)
