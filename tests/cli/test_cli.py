"""The command line: run, check, baseline, gate, report — exit statuses and what they print."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import pytest

import verimono as vm

from verimono.cli import main
from verimono.records.results import load

REF = ["--reference", "moving box", "--reference", "t|x| (n=1)"]

BROKEN = '''
"""A stepper that evaluates the moving set at the start of each step instead of its end."""
import numpy as np
from verimono.core.stepping import solve as _solve


def solve(problem, t_grid):
    t = np.asarray(t_grid, dtype=float)
    lagged = np.concatenate([[0.0], t[:-1]])
    op = problem.operator
    x = [np.array(problem.x0, dtype=float)]
    for k in range(1, len(t)):
        x.append(np.asarray(op.resolvent(x[-1], t[k] - t[k - 1], lagged[k]), dtype=float))
    return np.array(x)
'''


@pytest.fixture(scope="module")
def steppers(tmp_path_factory):
    d = tmp_path_factory.mktemp("steppers")
    (d / "lagged.py").write_text(textwrap.dedent(BROKEN))
    (d / "good.py").write_text("from verimono.core.stepping import solve\n")
    return d


@pytest.fixture(scope="module")
def good_check(steppers, tmp_path_factory):
    out = tmp_path_factory.mktemp("good")
    code = main(["check", str(steppers / "good.py") + ":solve", "--profile", "ci", "--out", str(out), *REF])
    assert code == 0
    return out


def test_run_writes_report_and_results_and_exits_0(tmp_path, capsys):
    code = main(["run", "--profile", "ci", "--stage", "convergence", *REF, "--out", str(tmp_path)])
    out = capsys.readouterr()
    assert code == 0
    assert (tmp_path / "report.html").stat().st_size > 10_000
    rep = load(tmp_path / "results.json")
    assert len(rep) == 2 and rep.ok and rep.meta["profile"] == "ci"
    assert "[1/1] convergence: passed" in out.err  # plain lines when not on a terminal
    assert "2 passed, 0 failed" in out.out
    table = [line.split() for line in out.out.splitlines() if line.startswith("  ")]
    assert table[0][:2] == ["reference", "expected"]
    assert ["moving", "box", "2", "2.000", "[2.000,", "2.000]", "ok"] in table      # the order table


def test_baseline_then_gate_is_green(good_check, tmp_path, capsys):
    base = tmp_path / "baseline.json"
    assert main(["baseline", "--from", str(good_check / "results.json"), "--out", str(base)]) == 0
    assert main(["gate", "--baseline", str(base), "--results", str(good_check / "results.json")]) == 0
    assert "no regressions" in capsys.readouterr().out


def test_a_broken_stepper_fails_check_and_gate_with_reasons(steppers, good_check, tmp_path, capsys):
    base = tmp_path / "baseline.json"
    main(["baseline", "--from", str(good_check / "results.json"), "--out", str(base)])
    capsys.readouterr()
    # the same name ("solve") from another module: compare it as the same target
    bad_out = tmp_path / "bad"
    code = main(["check", str(steppers / "lagged.py") + ":solve", "--profile", "ci", "--out", str(bad_out), *REF])
    assert code == 1
    assert any(line.split()[:3] == ["moving", "box", "2"] and line.endswith("MISSED")
               for line in capsys.readouterr().out.splitlines())
    bad = load(bad_out / "results.json")
    bad.meta["target"] = load(base).meta["target"]
    bad.save(bad_out / "results.json")
    capsys.readouterr()
    code = main(["gate", "--baseline", str(base), "--results", str(bad_out / "results.json")])
    out = capsys.readouterr().out
    assert code == 1
    assert "convergence_order[solve on moving box]: passed → failed" in out
    assert "below the theoretical order 2" in out
    assert "regression" in out


def test_lowered_order_and_removed_check_fail_the_gate(good_check, tmp_path, capsys):
    base = tmp_path / "baseline.json"
    main(["baseline", "--from", str(good_check / "results.json"), "--out", str(base)])
    doc = json.loads((good_check / "results.json").read_text())
    study = next(s for s in doc["studies"] if s["problem"] == "moving box")
    study["fits"]["sup"].update(slope=1.5, low=1.45, high=1.55)
    doc["results"] = [r for r in doc["results"] if r["check"] != "contraction" or "t|x|" not in r["subject"]]
    changed = tmp_path / "changed.json"
    changed.write_text(json.dumps(doc))
    capsys.readouterr()
    assert main(["gate", "--baseline", str(base), "--results", str(changed)]) == 1
    out = capsys.readouterr().out
    assert "sup-norm order fell from 2.000" in out
    assert "removed  contraction[solve on t|x| (n=1)]" in out
    assert "contraction: executed records fell" in out


@pytest.mark.parametrize("content, message", [
    (None, "does not exist"),
    ("{ garbled", "not valid JSON"),
    ('{"schema": "verimono.results", "schema_version": "0.1", "results": [], "studies": [], "meta": {}}',
     "incompatible schema version"),
])
def test_missing_garbled_or_incompatible_baseline_exits_2(good_check, tmp_path, capsys, content, message):
    base = tmp_path / "baseline.json"
    if content is not None:
        base.write_text(content)
    assert main(["gate", "--baseline", str(base), "--results", str(good_check / "results.json")]) == 2
    assert message in capsys.readouterr().err


def test_baseline_of_another_profile_exits_2(good_check, tmp_path, capsys):
    doc = json.loads((good_check / "results.json").read_text())
    doc["meta"]["profile"] = "thorough"
    base = tmp_path / "baseline.json"
    base.write_text(json.dumps(doc))
    assert main(["gate", "--baseline", str(base), "--results", str(good_check / "results.json")]) == 2
    assert "profile" in capsys.readouterr().err


def test_check_runs_the_operator_battery_on_an_operator(tmp_path, capsys):
    mod = tmp_path / "myops.py"
    mod.write_text("import verimono as vm\nOP = vm.NormSubdifferential(lambda t: 1.0 + t, dim=2)\n")
    code = main(["check", f"{mod}:OP", "--profile", "dev", "--seed", "3", "--out", str(tmp_path / "o")])
    assert code == 0, capsys.readouterr()
    rep = load(tmp_path / "o" / "results.json")
    # named as the API and pytest name it (the operator's own name), not by the target spec: one record key
    # whatever the entry point
    api = vm.check_operator(vm.NormSubdifferential(lambda t: 1.0 + t, dim=2), seed=3, examples=1)
    assert len({r.check for r in rep}) >= 10 and {r.subject for r in rep} == {r.subject for r in api} != {f"{mod}:OP"}
    assert rep.meta["command"] == "check" and rep.meta["seed"] == 3


@pytest.mark.parametrize("target", ["no_such_module_xyz:thing", "verimono:no_such_thing", "verimono",
                                    "verimono.core.sets:Ball"])
def test_bad_targets_exit_2(target, tmp_path, capsys):
    assert main(["check", target, "--out", str(tmp_path)]) == 2
    assert "verimono check:" in capsys.readouterr().err


def test_unknown_reference_exits_2(tmp_path, capsys):
    assert main(["run", "--reference", "nope", "--out", str(tmp_path)]) == 2
    assert "no reference named 'nope'" in capsys.readouterr().err


@pytest.mark.slow
def test_console_entry_exit_status_propagates(good_check, tmp_path):
    base = tmp_path / "b.json"
    base.write_text("garbage")
    proc = subprocess.run([sys.executable, "-m", "verimono.cli", "gate", "--baseline", str(base),
                           "--results", str(good_check / "results.json")], capture_output=True, text=True)
    assert proc.returncode == 2 and "not valid JSON" in proc.stderr


def test_report_rerenders_from_results(good_check, tmp_path):
    out = tmp_path / "r.html"
    assert main(["report", "--results", str(good_check / "results.json"), "--out", str(out)]) == 0
    assert out.read_text().count("<svg") >= 4


def test_a_py_target_is_the_file_itself_not_a_module_of_the_same_name(tmp_path):
    """load_target("…/types.py:solve") imported the standard library's types (already in sys.modules), and
    a second lagged.py the first one: the file named is the module loaded."""
    from verimono.core.errors import BadTarget
    from verimono.run.targets import load_target

    (tmp_path / "types.py").write_text("def solve(problem, t):\n    return 'mine'\n")
    assert load_target(f"{tmp_path}/types.py:solve")(None, None) == "mine"
    for i in (1, 2):
        d = tmp_path / f"copy{i}"
        d.mkdir()
        (d / "lagged.py").write_text(f"def solve(problem, t):\n    return {i}\n")
        assert load_target(f"{d}/lagged.py:solve")(None, None) == i
    with pytest.raises(BadTarget, match="does not exist"):
        load_target(f"{tmp_path}/missing.py:solve")


# -- progress ---------------------------------------------------------------------------------------


class _Stream:
    """A text stream that says whether it is a terminal."""

    def __init__(self, tty: bool) -> None:
        self.tty, self.parts = tty, []

    def isatty(self) -> bool:
        return self.tty

    def write(self, text: str) -> None:
        self.parts.append(text)

    def flush(self) -> None:
        pass

    @property
    def text(self) -> str:
        return "".join(self.parts)


def test_progress_on_a_terminal_shows_units_and_the_current_subject(monkeypatch):
    from verimono.run.progress import Progress
    from verimono.run.execute import execute
    from verimono.reference import get
    from verimono.run.stages import RunContext

    monkeypatch.delenv("CI", raising=False)
    stream = _Stream(tty=True)
    progress = Progress(stream)
    assert progress.tty
    problems = [get("moving box"), get("t|x| (n=1)")]
    execute(command="run", profile_name="ci", stages=["convergence", "assumptions"],
            context=RunContext(problems=problems), progress=progress)
    frames = [p for p in stream.parts if p.startswith("\r[")]
    # every unit of each stage was announced with its subject, and each stage reached all its units
    for stage in ("convergence", "assumptions"):
        assert any(f"{stage}  0/2 units  moving box" in f for f in frames)
        assert any(f"{stage}  1/2 units  t|x| (n=1)" in f for f in frames)
        assert any(f"{stage}  2/2 units" in f for f in frames)
    assert "stage 2/2" in stream.text and "[2/2] assumptions: passed" in stream.text


def test_progress_is_quiet_and_line_oriented_off_a_terminal_or_under_ci(monkeypatch):
    from verimono.run.progress import Progress

    class Stage:
        name = "operator_laws"

    monkeypatch.setenv("CI", "true")
    assert not Progress(_Stream(tty=True)).tty            # CI: no redrawn bar even on a terminal
    monkeypatch.delenv("CI")
    for stream, interval, lines in ((_Stream(tty=False), 60.0, 0), (_Stream(tty=False), 0.0, 2)):
        progress = Progress(stream, interval=interval)
        progress.start(Stage(), 1, 7)
        for done, label in ((0, "a"), (1, "b"), (2, "c"), (3, "")):
            progress.within(done, 3, label)
        assert "\r" not in stream.text
        within = [line for line in stream.text.splitlines() if "units done" in line]
        assert len(within) == lines                         # at most one line per interval, none at 0 or total
        assert all(line.startswith("[2/7] operator_laws: ") for line in within)
    assert within == ["[2/7] operator_laws: 1/3 units done, at b", "[2/7] operator_laws: 2/3 units done, at c"]


def test_a_check_with_no_timed_record_measures_no_end_calibration(good_check):
    """`verimono check`'s records are not timed (no same-job timing ratio): the run keeps its start's
    calibration alone (issue 43: no end calibration when nothing is timed), and the gate then leaves its stages'
    wall growth unjudged (tests/run/test_gate_cpu.py)."""
    rep = load(good_check / "results.json")
    assert not any("timing_ratio" in r.details for r in rep.results)
    assert len(rep.meta["calibrations"]) == 1 and len(rep.meta["calibrations_cpu"]) == 1
    assert rep.meta["calibration"] == rep.meta["calibrations"][0] > 0


@pytest.mark.parametrize("timed", [False, True])
def test_the_end_calibration_is_measured_when_a_record_is_timed(monkeypatch, timed):
    """The same run with a timed record (the performance stage's ``details["timing_ratio"]``) measures its end
    calibration as before: the two ends, and their drift, are what the gate's wall verdicts read."""
    import types

    from verimono.records.results import CheckResult, Report
    from verimono.run import execute as ex
    from verimono.run import stages

    details = {"timing_ratio": 1.1} if timed else {}
    rep = Report([CheckResult("speed", "solve", "passed", worst=0.5, bound=1.0, details=details)])
    monkeypatch.setattr(stages, "run_stages", lambda *a, **k: rep)
    calls = []
    monkeypatch.setattr(ex, "calibrate_times", lambda *a, **k: calls.append(k) or (0.07, [0.06, 0.07, 0.08]))
    context = types.SimpleNamespace(progress=None, executor=None, seed=0, problems=None, data_dir=None)
    out = ex.execute(command="run", profile_name="ci", stages=["performance"], context=context)
    assert ex.has_timed_records(out) is timed
    assert len(out.meta["calibrations"]) == len(out.meta["calibrations_cpu"]) == (2 if timed else 1)
    assert [bool(k.get("agreeing_with")) for k in calls] == ([False, True] if timed else [False])
