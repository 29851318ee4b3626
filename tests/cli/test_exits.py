"""What the command line says of itself and of what it was given (issue 41, items 1, 2, 6): ``--version``,
references by a short ASCII id, messages that agree with the exit status, output that never costs the results,
and a subject's own exit that never ends a run with a false status."""

from __future__ import annotations

import importlib.metadata
import re
from pathlib import Path

import pytest

from verimono.cli import main
from verimono.reference import catalog, get, ids


# -- 6. --version, --reference by id ----------------------------------------------------------------------------------

def test_version_prints_the_installed_package_version(capsys):
    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out.strip() == f"verimono {importlib.metadata.version('verimono')}"


def test_every_reference_has_a_stable_ascii_id_and_get_takes_either():
    refs = catalog()
    table = ids()
    assert sorted(table.values()) == sorted(p.name for p in refs)      # one id per reference, no other
    for rid, name in table.items():
        assert re.fullmatch(r"[a-z0-9]+(-[a-z0-9]+)*", rid), rid
        assert get(rid).name == name and get(name).name == name
    # the display name with an ASCII minus for the Unicode one (what a keyboard types) is the same reference
    assert get("Example ex, v = (-t, 0)").name == "Example ex, v = (\u2212t, 0)"
    assert table["example-ramp"] == "Example ex, v = (\u2212t, 0)" and table["tnorm-1"] == "t|x| (n=1)"
    with pytest.raises(KeyError, match="example-ramp"):       # the ids are listed when a name is unknown
        get("no such reference")


def test_the_command_line_resolves_references_by_id():
    import argparse

    from verimono.cli import _context

    ctx = _context(argparse.Namespace(reference=["tnorm-1", "example-ramp", "moving box"]))
    assert [p.name for p in ctx.problems] == ["t|x| (n=1)", "Example ex, v = (\u2212t, 0)", "moving box"]


@pytest.mark.slow
def test_run_takes_a_reference_by_its_id(tmp_path, capsys):
    code = main(["run", "--profile", "ci", "--stage", "convergence", "--reference", "tnorm-1",
                 "--reference", "example-ramp", "--executor", "serial", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "t|x| (n=1)" in out and "Example ex, v = (\u2212t, 0)" in out


# -- 2. output never costs results ------------------------------------------------------------------------------------

class _BrokenPipe:
    """A console whose reader went away (``| head -c 20`` after 20 bytes)."""

    def __init__(self, after: int = 0):
        self.left = after

    def write(self, text):
        if self.left <= 0:
            raise BrokenPipeError(32, "Broken pipe")
        self.left -= len(text)
        return len(text)

    def flush(self):
        if self.left <= 0:
            raise BrokenPipeError(32, "Broken pipe")

    def isatty(self):
        return False


@pytest.fixture(scope="module")
def passing_results(tmp_path_factory):
    from verimono import check_stepper, solve

    d = tmp_path_factory.mktemp("results")
    rep = check_stepper(solve, [get("tnorm-1")], laws=False)
    rep.meta.update({"command": "run", "profile": "ci", "target": None, "calibration": 0.05})
    rep.save(d / "results.json")
    return d / "results.json"


@pytest.mark.parametrize("stream", ["stdout", "stderr", "both"])
@pytest.mark.parametrize("after", [0, 20])
def test_a_broken_console_ends_printing_not_the_command(passing_results, tmp_path, monkeypatch, stream, after):
    """In-process: ``baseline --from`` then ``gate`` with the console's reader gone; before, BrokenPipeError
    out of main.  The files are written and the statuses are the verdicts' (0: no regression)."""
    base = tmp_path / "baseline.json"
    for name in (("stdout", "stderr") if stream == "both" else (stream,)):
        monkeypatch.setattr(f"sys.{name}", _BrokenPipe(after))
    assert main(["baseline", "--from", str(passing_results), "--out", str(base)]) == 0
    assert base.is_file()
    assert main(["gate", "--baseline", str(base), "--results", str(passing_results)]) == 0
    assert main(["report", "--results", str(passing_results), "--out", str(tmp_path / "r.html")]) == 0
    assert (tmp_path / "r.html").is_file()


def test_a_closed_stderr_is_no_stream_at_all(passing_results, tmp_path, monkeypatch):
    """``2>&-``: Python starts with ``sys.stderr = None``; ``sys.stderr.flush()`` before a fork raised."""
    monkeypatch.setattr("sys.stderr", None)
    base = tmp_path / "baseline.json"
    assert main(["baseline", "--from", str(passing_results), "--out", str(base)]) == 0 and base.is_file()


def test_the_console_is_given_back_after_the_command(passing_results, tmp_path):
    import sys

    found = sys.stdout, sys.stderr
    main(["gate", "--baseline", str(passing_results), "--results", str(passing_results)])
    assert (sys.stdout, sys.stderr) == found


GOOD = "from verimono.core.stepping import solve\n"
LAGGED = '''
import numpy as np


def solve(problem, t_grid):          # the moving set evaluated at the start of each step: order lost
    t = np.asarray(t_grid, dtype=float)
    x = [np.array(problem.x0, dtype=float)]
    for k in range(1, len(t)):
        x.append(np.asarray(problem.operator.resolvent(x[-1], t[k] - t[k - 1], t[k - 1]), dtype=float))
    return np.array(x)
'''


def _shell(tmp_path, source: str, redirect: str, *extra: str):
    """``verimono check`` of ``source``'s ``solve`` on two references, its output redirected by ``redirect``
    (a pipe into ``head -c 20``, a closed stream); the exit status of verimono itself, as a wrapper script sees
    it (``PIPESTATUS``), and the output folder."""
    import shlex
    import subprocess
    import sys
    from pathlib import Path

    (tmp_path / "subject.py").write_text(source)
    out = tmp_path / "out"
    exe = Path(sys.executable).with_name("verimono")
    cmd = " ".join(shlex.quote(str(a)) for a in [exe, "check", "subject.py:solve", "--profile", "ci", "--reference",
                                                 "moving-box", "--reference", "tnorm-1", "--out", out, *extra])
    script = f"{cmd} {redirect}\necho \"status=${{PIPESTATUS[0]}}\" >&3\n"
    proc = subprocess.run(["bash", "-c", f"exec 3>&1; {script}"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=600)
    status = re.search(r"status=(\d+)", proc.stdout)
    assert status, proc.stdout + proc.stderr
    return int(status.group(1)), out


@pytest.mark.slow
@pytest.mark.parametrize("source, verdict", [(GOOD, 0), (LAGGED, 1)], ids=["correct", "lagged"])
@pytest.mark.parametrize("redirect", ["| head -c 20 >/dev/null", "2>&1 | head -c 20 >/dev/null", ">&- 2>&-",
                                      "2>&- | head -c 1 >/dev/null"],
                         ids=["stdout into head", "both into head", "both closed", "stderr closed, stdout into head"])
def test_a_pipe_or_a_closed_stream_never_costs_the_results(tmp_path, source, verdict, redirect):
    from verimono.records.results import load

    status, out = _shell(tmp_path, source, redirect)
    assert (out / "results.json").is_file() and (out / "report.html").is_file()
    assert not (out / "results.json.in-progress").exists()
    rep = load(out / "results.json")
    assert status == verdict == (0 if rep.ok else 1), (status, rep.summary())


# -- 1. one exit path: what a subject raises or calls is a failed record of it ------------------------------------------

EXITING = '''
import os
import sys

import numpy as np

import verimono as vm

calls = [0]


def exits(problem, t_grid):               # a stepper that ends "its" program on the {n}th call
    calls[0] += 1
    if calls[0] >= {n}:
        {how}
    return vm.solve(problem, t_grid).x


def _resolvent(x, lam, t):
    calls[0] += 1
    if calls[0] >= {n}:
        {how}
    return np.asarray(x, dtype=float) / (1.0 + lam)


op = vm.operator_from_resolvent(_resolvent, 2, name="exits")
'''


def _exiting(tmp_path, how: str, n: int = 1) -> str:
    name = f"exiting_{abs(hash((how, n)))}"
    (tmp_path / f"{name}.py").write_text(EXITING.format(how=how, n=n))
    return str(tmp_path / f"{name}.py")


_SLOW = pytest.mark.slow


@pytest.mark.parametrize("how, n, target", [
    ("sys.exit(0)", 4, "exits"),               # after some grids of the study ran
    pytest.param("sys.exit(0)", 1, "exits", marks=_SLOW),
    pytest.param("sys.exit(3)", 1, "exits", marks=_SLOW),
    pytest.param("raise SystemExit", 2, "exits", marks=_SLOW),
    pytest.param("raise GeneratorExit", 1, "exits", marks=_SLOW),
    pytest.param("sys.exit(0)", 1, "op", marks=_SLOW),                  # a resolvent
    pytest.param("raise GeneratorExit", 3, "op", marks=_SLOW),
], ids=["stepper sys.exit(0) 4th call", "stepper sys.exit(0)", "stepper sys.exit(3)", "stepper SystemExit 2nd call",
        "stepper GeneratorExit", "resolvent sys.exit(0)", "resolvent GeneratorExit 3rd call"])
def test_a_subject_ending_the_program_is_a_failed_record_and_exit_1(tmp_path, capsys, how, n, target):
    from verimono.records.results import load

    out = tmp_path / "out"
    code = main(["check", f"{_exiting(tmp_path, how, n)}:{target}", "--profile", "ci", "--executor", "serial",
                 "--reference", "tnorm-1", "--out", str(out)])
    assert code == 1, capsys.readouterr()
    rep = load(out / "results.json")
    kind = "GeneratorExit" if "GeneratorExit" in how else "SystemExit"
    failed = [r for r in rep.results if r.status == "failed"]
    assert failed and all(kind in r.message for r in failed if "Exit" in r.message), [r.message for r in failed]
    assert any(kind in r.message for r in failed)


@pytest.mark.parametrize("how", ["sys.exit(0)", "raise GeneratorExit"])
def test_check_stepper_records_a_subject_that_ends_the_program(tmp_path, how):
    import importlib.util

    import verimono as vm

    spec = importlib.util.spec_from_file_location("exiting_api", _exiting(tmp_path, how))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    rep = vm.check_stepper(mod.exits, [get("tnorm-1")], laws=["contraction"])
    assert [r.status for r in rep.results] == ["failed", "failed"]
    assert all(("SystemExit" if "exit" in how else "GeneratorExit") in r.message for r in rep.results)


def test_a_real_interrupt_is_not_taken_for_the_subjects(tmp_path):
    """KeyboardInterrupt (Ctrl-C, and SIGTERM as the run raises it) still stops the battery: it is the user's."""
    import importlib.util

    import verimono as vm

    spec = importlib.util.spec_from_file_location("interrupted_api", _exiting(tmp_path, "raise KeyboardInterrupt"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    with pytest.raises(KeyboardInterrupt):
        vm.check_stepper(mod.exits, [get("tnorm-1")], laws=["contraction"])


def test_check_operator_records_a_resolvent_that_ends_the_program(tmp_path):
    import importlib.util

    import verimono as vm

    spec = importlib.util.spec_from_file_location("exiting_op", _exiting(tmp_path, "sys.exit(0)", 5))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    rep = vm.check_operator(mod.op, examples=4, seed=0)
    failed = [r for r in rep.results if r.status == "failed"]
    assert failed and any("SystemExit(0)" in r.message for r in failed), [r.message for r in rep.results]
    assert not rep.ok


@pytest.mark.slow
def test_os_exit_in_a_worker_is_a_failed_record_and_exit_1(tmp_path):
    """``os._exit(0)`` cannot be caught in the process that calls it; in a worker process it ends the worker, and
    the run records the unit as failed (under ``--executor serial`` it ends the run: the in-progress mark stays,
    and the gate refuses the files, docs/run.md).  In a process of its own, as a user runs it (a pytest process
    with threads would spawn its workers)."""
    import subprocess
    import sys
    from pathlib import Path

    from verimono.records.results import load

    out = tmp_path / "out"
    exe = Path(sys.executable).with_name("verimono")
    proc = subprocess.run([str(exe), "check", f"{_exiting(tmp_path, 'os._exit(0)')}:exits", "--profile", "ci",
                           "--executor", "process:2", "--reference", "tnorm-1", "--out", str(out)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 1, proc.stderr
    rep = load(out / "results.json")
    assert rep.failures and all("worker process died" in r.message for r in rep.failures)


@pytest.mark.parametrize("exc", [SystemExit(0), SystemExit(None), GeneratorExit()], ids=["exit(0)", "exit()", "gen"])
def test_an_exit_raised_outside_any_check_is_no_verdict_not_a_pass(monkeypatch, capsys, exc, passing_results):
    import verimono.cli as cli

    def ends(args):
        raise exc
    monkeypatch.setattr(cli, "_cmd_gate", ends)
    assert main(["gate", "--baseline", str(passing_results), "--results", str(passing_results)]) == 2
    assert "no verdict" in capsys.readouterr().err


@pytest.mark.slow
@pytest.mark.parametrize("command", [["check", "verimono:solve", "--stage", "convergence"], ["run", "--stage", "section7"]])
def test_a_command_started_in_a_deleted_folder_is_a_clear_error(command, tmp_path):
    """A run started from a working directory deleted under the shell died on os.getcwd() with a traceback (and
    `check` exited 0): now one line saying so, exit 2, before any work."""
    import os
    import subprocess
    import sys

    gone = tmp_path / "gone"
    gone.mkdir()
    code = ("import os, sys; os.chdir(sys.argv[1]); os.rmdir(sys.argv[1]); from verimono.cli import main; "
            "sys.exit(main(sys.argv[2:]))")
    proc = subprocess.run([sys.executable, "-c", code, str(gone), *command, "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=300,
                          env=dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[2])))
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert "working directory no longer exists" in proc.stderr and "Traceback" not in proc.stderr
    assert not (tmp_path / "out").exists()
