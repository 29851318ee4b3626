"""Records the gate can trust (issue 33, item 4): a pass that contradicts its own figures, the short results
of a session whose worker crashed, a negative number of generated problems, a run killed before its mark or
after some stages."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import verimono as vm
from verimono.cli import main
from verimono.core.errors import InvalidCheckArgument
from verimono.records.results import MISSING_RECORDS, CheckResult, Report, SchemaError, load
from verimono.run.gate import compare
from zoo_runs import stage_killer

pytest_plugins = ["pytester"]


def sample() -> Report:
    rep = Report([CheckResult("monotone", "Linear", "passed", worst=0.5, bound=1.0),
                  CheckResult("monotone", "Ball", "passed", worst=0.2, bound=1.0)])
    rep.meta.update({"command": "pytest", "profile": "ci", "target": None})
    return rep


def _run(capsys, *argv: str) -> tuple[int, str]:
    capsys.readouterr()
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.err + out.out


# -- a passed record whose worst exceeds its bound ------------------------------------------------------------

@pytest.mark.parametrize("role", ["baseline", "results"])
@pytest.mark.parametrize("worst, bound", [(5.0, 1.0), (1.0 + 1e-9, 1.0), (3e-3, 1e-3)])
def test_a_pass_with_worst_above_its_bound_is_invalid_exit_2(tmp_path, capsys, role, worst, bound):
    """Such a record was accepted by the gate (and passed against itself); no check of verimono writes one."""
    good, bad = sample(), sample()
    bad.results[1].worst, bad.results[1].bound = worst, bound
    files = {"baseline": good.save(tmp_path / "good.json"), "results": good.save(tmp_path / "good.json")}
    files[role] = bad.save(tmp_path / "bad.json")
    code, text = _run(capsys, "gate", "--baseline", str(files["baseline"]), "--results", str(files["results"]))
    assert code == 2 and "monotone[Ball]" in text and "above its bound" in text and "bad.json" in text
    with pytest.raises(SchemaError, match="above its bound"):
        compare(good, bad) if role == "results" else compare(bad, good)
    code, text = _run(capsys, "baseline", "--from", str(tmp_path / "bad.json"), "--out", str(tmp_path / "b.json"))
    assert code == 2 and "above its bound" in text and not (tmp_path / "b.json").exists()


def test_a_pass_at_its_bound_and_a_failure_above_it_are_valid():
    edge, failed = sample(), sample()
    edge.results[1].worst = 1.0
    failed.results[1].status, failed.results[1].worst = "failed", 5.0
    assert compare(edge, edge).ok and not compare(edge, failed).ok


# -- the short results of a session whose worker crashed ---------------------------------------------------

@pytest.mark.parametrize("how", ["crashed", "hidden"])
def test_short_results_of_a_session_are_refused_as_a_baseline(tmp_path, capsys, how):
    short = sample()
    short.meta[MISSING_RECORDS] = {"crashed": [], "hidden": [], how: ["test_mine.py::test_my_code[moving disc]"]}
    short.save(tmp_path / "results.json")
    code, text = _run(capsys, "baseline", "--from", str(tmp_path / "results.json"), "--out", str(tmp_path / "b.json"))
    assert code == 2 and "short" in text and "test_my_code[moving disc]" in text
    assert not (tmp_path / "b.json").exists()
    whole = sample()
    whole.save(tmp_path / "whole.json")
    assert _run(capsys, "baseline", "--from", str(tmp_path / "whole.json"), "--out", str(tmp_path / "b.json"))[0] == 0


@pytest.mark.slow
def test_a_crashed_xdist_worker_marks_the_session_short(pytester):
    """``pytest -n 2`` where one test kills its worker: xdist reports it and runs on, the records of that test
    are lost, and the session's results were accepted by `verimono baseline --from`."""
    pytest.importorskip("xdist")
    pytester.makepyfile(test_short=textwrap.dedent('''
        import os
        import pytest
        import verimono as vm
        from verimono.testing import parametrize_with_checks

        def test_dies():
            os._exit(3)

        @parametrize_with_checks([vm.NormalCone(vm.sets.Box([-1.0], [1.0]))], examples=5)
        def test_box(subject, check):
            check(subject)
    '''))
    out = pytester.path / "out"
    result = pytester.runpytest_subprocess("-n", "2", "-p", "no:cacheprovider", "--verimono-report", str(out))
    assert result.ret == 1
    meta = json.loads((out / "results.json").read_text())["meta"]
    assert meta[MISSING_RECORDS]["crashed"] == ["test_short.py::test_dies"]
    assert main(["baseline", "--from", str(out / "results.json"), "--out", str(pytester.path / "b.json")]) == 2


# -- generated=-1 -----------------------------------------------------------------------------------------

@pytest.mark.parametrize("generated", [-1, 2.5, True, "4"])
def test_a_number_of_generated_problems_that_is_not_a_count_is_refused(generated):
    from verimono.testing import checks_for, registry_size

    with pytest.raises(InvalidCheckArgument, match="generated"):
        vm.check_stepper(vm.solve, generated=generated, orders=False)
    with pytest.raises(InvalidCheckArgument, match="generated"):
        registry_size(vm.solve, generated=generated)
    with pytest.raises(InvalidCheckArgument, match="generated"):
        checks_for(vm.solve, generated=generated)


def test_zero_generated_problems_is_the_catalog_alone():
    from verimono.testing import checks_for, registry_size

    assert len(checks_for(vm.solve, generated=0)) == registry_size(vm.solve, generated=0) > 0


# -- the mark first, and stages on disk as they finish -------------------------------------------------------

def _env() -> dict[str, str]:
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    env["PYTHONPATH"] = os.pathsep.join([str(Path(vm.__file__).resolve().parent.parent),
                                         env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    return env


ONE_REF = ["--reference", "moving box", "--profile", "ci", "--executor", "serial"]


@pytest.mark.slow
def test_a_check_killed_while_importing_its_target_leaves_the_mark(tmp_path, capsys):
    """SIGKILL before the mark left the previous check's files unmarked, and the gate took them for this one's:
    here the target kills the process as it is imported (the mark was written after that, and after the
    checks' imports)."""
    out = tmp_path / "out"
    (tmp_path / "good.py").write_text("from verimono import solve as my_stepper\n")
    (tmp_path / "killer.py").write_text("import os, signal\nos.kill(os.getpid(), signal.SIGKILL)\n")
    env = _env()
    env["PYTHONPATH"] = os.pathsep.join([str(tmp_path), env["PYTHONPATH"]])
    cmd = [sys.executable, "-m", "verimono.cli", "check", "--stage", "convergence", *ONE_REF, "--out", str(out)]
    done = subprocess.run([*cmd, "good:my_stepper"], env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    killed = subprocess.run([*cmd, "killer:anything"], env=env, capture_output=True, text=True, timeout=300)
    assert killed.returncode == -signal.SIGKILL
    assert (out / "results.json.in-progress").exists()
    code, text = _run(capsys, "gate", "--baseline", str(out / "results.json"), "--results", str(out / "results.json"))
    assert code == 2 and "never completed" in text


STAGE_KILLER = stage_killer('section7')


@pytest.mark.slow
def test_resume_continues_a_run_killed_after_finished_stages(tmp_path, capsys):
    """A run killed with SIGKILL lost its finished stages (written only on an interrupt or at the end), and
    `--resume` had nothing to continue; now each stage is on disk as it finishes."""
    out = tmp_path / "out"
    args = ["run", "--stage", "convergence", "--stage", "section7", *ONE_REF, "--out", str(out)]
    proc = subprocess.run([sys.executable, "-c", STAGE_KILLER, *args], env=_env(), capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == -signal.SIGKILL, proc.stderr[-2000:]
    partial = load(out / "results.json.partial")     # beside the results, never over them
    mark = json.loads((out / "results.json.in-progress").read_text())
    assert partial.meta["incomplete"] and partial.meta["finished_stages"] == ["convergence"]
    assert partial.meta["run_id"] == mark["run_id"] and not (out / "results.json").exists()
    resumed = subprocess.run([sys.executable, "-m", "verimono.cli", *args, "--resume"], env=_env(), capture_output=True,
                             text=True, timeout=300)   # a process of its own, as the killed one
    assert resumed.returncode == 0, resumed.stderr[-2000:]
    done = load(out / "results.json")
    assert [s["name"] for s in done.meta["stages"]] == ["convergence", "section7"]
    assert done.meta["resumed_from"] == mark["run_id"] and not (out / "results.json.in-progress").exists()
    assert not (out / "results.json.partial").exists()


@pytest.mark.slow
def test_a_run_killed_halfway_leaves_the_previous_results_and_report_intact(tmp_path, capsys):
    """Each finished stage was saved over results.json: a SIGKILL halfway left the previous run's results (and its
    report, now of another run id) replaced by partial ones.  Now the previous pair stays byte for byte until a new
    run completes; the killed run's stages wait beside it (results.json.partial) for --resume, and the gate refuses
    the folder meanwhile (the mark)."""
    out = tmp_path / "out"
    args = ["run", "--stage", "convergence", "--stage", "section7", *ONE_REF, "--out", str(out)]
    first = subprocess.run([sys.executable, "-m", "verimono.cli", *args], env=_env(), capture_output=True, text=True,
                           timeout=300)
    assert first.returncode == 0, first.stderr[-2000:]
    before = {name: (out / name).read_bytes() for name in ("results.json", "report.html")}
    proc = subprocess.run([sys.executable, "-c", STAGE_KILLER, *args], env=_env(), capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == -signal.SIGKILL, proc.stderr[-2000:]
    assert {name: (out / name).read_bytes() for name in before} == before
    mark = json.loads((out / "results.json.in-progress").read_text())
    assert load(out / "results.json.partial").meta["run_id"] == mark["run_id"]
    code, text = _run(capsys, "gate", "--baseline", str(out / "results.json"), "--results", str(out / "results.json"))
    assert code == 2 and "never completed" in text
    resumed = subprocess.run([sys.executable, "-m", "verimono.cli", *args, "--resume"], env=_env(), capture_output=True,
                             text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr[-2000:]
    done = load(out / "results.json")
    assert done.meta["resumed_from"] == mark["run_id"] and [s["name"] for s in done.meta["stages"]] == [
        "convergence", "section7"]
    assert not (out / "results.json.partial").exists() and not (out / "results.json.in-progress").exists()
