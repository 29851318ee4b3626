"""pytest-xdist: the README's ``parametrize_with_checks`` suite under ``pytest -n 2`` gives the same
records, statuses, studies and battery summary as under plain ``pytest``, and gates the same; records that a
parallel runner hides make the session fail instead of writing an empty, green report."""

from __future__ import annotations

import json
import re
import textwrap
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow   # nested pytest sessions in subprocesses (pytester): the slow tier

pytest.importorskip("xdist")  # the test extra installs it; without it there is nothing to verify here

pytest_plugins = ["pytester"]

README = (Path(__file__).resolve().parents[2] / "README.md").read_text()


def readme_file(name: str) -> str:
    """The README's file block ``# NAME`` (its first line), verbatim: the reader's ``mysolver.py`` and suite."""
    found = [b for b in re.findall(r"```python\n(.*?)```", README, re.S) if b.splitlines()[0] == f"# {name}"]
    assert len(found) == 1, f"README has {len(found)} file blocks # {name}"
    return found[0]


def mysolver_source() -> str:
    """``mysolver.py`` of the README's "Three ways in": ``moving_disc`` and ``my_stepper``."""
    return readme_file("mysolver.py")


def suite_source() -> str:
    """The README's pytest suite (section "2. pytest"), verbatim."""
    block = readme_file("test_mysolver.py")
    assert "parametrize_with_checks([moving_disc, my_stepper])" in block
    return block


def _summary(result: pytest.RunResult) -> list[str]:
    """The ``verimono checks`` section and the ``verimono records`` line of a run's terminal output."""
    lines = result.stdout.lines
    start = next(i for i, line in enumerate(lines) if "verimono checks" in line)
    out = []
    for line in lines[start + 1:]:
        if line.startswith(("=", "-")):
            break
        out.append(line)
    out += [line for line in lines if "verimono records:" in line]
    return out


def _records(path: Path) -> tuple[list, list, list]:
    doc = json.loads(path.read_text())
    records = [(r["check"], r["subject"], r["status"], r["details"].get("pytest_nodeid")) for r in doc["results"]]
    studies = [(s["problem"], s["stepper"], s["steps"]) for s in doc["studies"]]
    return records, studies, [t["problem"] for t in doc["trajectories"]]


@pytest.fixture
def readme_project(pytester: pytest.Pytester, monkeypatch: pytest.MonkeyPatch) -> pytest.Pytester:
    pytester.makepyfile(mysolver=mysolver_source(), test_mysolver=suite_source())
    monkeypatch.setenv("CI", "1")                    # the ci profile, as the README's quoted output
    monkeypatch.delenv("HYPOTHESIS_PROFILE", raising=False)
    monkeypatch.delenv("PYTEST_XDIST_AUTO_NUM_WORKERS", raising=False)
    return pytester


def test_xdist_gives_the_serial_records_summary_and_gate(readme_project):
    serial = readme_project.runpytest_subprocess("-p", "no:cacheprovider", "--verimono-report", "serial")
    assert serial.ret == 0, serial.stdout.str()[-3000:]
    parallel = readme_project.runpytest_subprocess("-p", "no:cacheprovider", "-n", "2", "--verimono-report", "par",
                                                   "--verimono-baseline", "serial/results.json")
    assert parallel.ret == 0, parallel.stdout.str()[-3000:]
    assert "2 workers" in parallel.stdout.str()                      # it really ran on xdist workers

    s_summary, p_summary = _summary(serial), _summary(parallel)
    assert s_summary == p_summary
    collected = int(s_summary[0].split()[0])
    assert collected >= 150 and s_summary[0].startswith(f"{collected} collected, {collected} ran: ")

    s_rec, s_studies, s_traj = _records(readme_project.path / "serial" / "results.json")
    p_rec, p_studies, p_traj = _records(readme_project.path / "par" / "results.json")
    assert len(s_rec) >= collected                                    # every case gave its record(s)
    assert p_rec == s_rec                                             # same keys, statuses, order
    assert p_studies == s_studies and len(s_studies) >= 1
    assert p_traj == s_traj
    parallel.stdout.fnmatch_lines(["verimono gate: no regressions*"])


def test_records_hidden_by_a_parallel_runner_fail_the_session(readme_project):
    # a runner that carries test outcomes but not verimono's records (simulated: the controller loses them)
    readme_project.makeconftest(textwrap.dedent('''
        import pytest

        @pytest.hookimpl(tryfirst=True)
        def pytest_runtest_logreport(report):
            if report.when == "call" and hasattr(report, "verimono_records"):
                del report.verimono_records
    '''))
    readme_project.makepyfile(test_mysolver=textwrap.dedent('''
        from verimono.testing import parametrize_with_checks
        from mysolver import moving_disc

        @parametrize_with_checks([moving_disc])
        def test_my_operator(subject, check):
            check(subject)
    '''))
    result = readme_project.runpytest_subprocess("-p", "no:cacheprovider", "-n", "2", "--verimono-report", "out")
    outcomes = result.parseoutcomes()
    assert outcomes.get("passed", 0) > 0 and outcomes.get("failed", 0) == 0   # every test itself passed
    assert result.ret == pytest.ExitCode.TESTS_FAILED                         # ... and the session fails
    result.stdout.fnmatch_lines(["*verimono: * tests ran where their verimono records cannot reach this report*"])


def test_records_kept_by_a_forked_test_process_fail_the_session(readme_project):
    # a runner that runs each test in a child process and sends back only the report (as pytest-forked
    # does): the child's records never reach the report, and the session must say so
    readme_project.makeconftest(textwrap.dedent('''
        import os
        import pytest
        from _pytest.runner import runtestprotocol

        @pytest.hookimpl(tryfirst=True)
        def pytest_runtest_protocol(item, nextitem):
            ihook = item.ihook
            ihook.pytest_runtest_logstart(nodeid=item.nodeid, location=item.location)
            r, w = os.pipe()
            pid = os.fork()
            if pid == 0:
                os.close(r)
                reports = runtestprotocol(item, log=False)
                data = [item.config.hook.pytest_report_to_serializable(config=item.config, report=rep)
                        for rep in reports]
                os.write(w, repr(data).encode())
                os._exit(0)
            os.close(w)
            chunks = []
            while chunk := os.read(r, 1 << 16):
                chunks.append(chunk)
            os.waitpid(pid, 0)
            for d in eval(b"".join(chunks).decode()):
                rep = item.config.hook.pytest_report_from_serializable(config=item.config, data=d)
                ihook.pytest_runtest_logreport(report=rep)
            ihook.pytest_runtest_logfinish(nodeid=item.nodeid, location=item.location)
            return True
    '''))
    readme_project.makepyfile(test_mysolver=textwrap.dedent('''
        from verimono.records.results import CheckResult, emit

        def test_law():
            emit(CheckResult("my_law", "my operator", "passed", worst=0.5, bound=1.0))
    '''))
    result = readme_project.runpytest_subprocess("-p", "no:cacheprovider", "--verimono-report", "out")
    result.assert_outcomes(passed=1)
    assert result.ret == pytest.ExitCode.TESTS_FAILED
    result.stdout.fnmatch_lines(["*verimono: 1 tests ran where their verimono records cannot reach this report*"])
    # without the forking runner the same test's record is in the report and the session passes
    (readme_project.path / "conftest.py").unlink()
    plain = readme_project.runpytest_subprocess("-p", "no:cacheprovider", "--verimono-report", "out")
    assert plain.ret == 0
    assert [r["check"] for r in json.loads((readme_project.path / "out" / "results.json").read_text())["results"]] \
        == ["my_law"]
