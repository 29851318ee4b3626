"""The README's "Three ways in", run as a reader runs them: its ``mysolver.py`` and ``test_mysolver.py`` written to
a fresh folder, the pytest suite run there, the gate's four commands run with the input term then lost, and the
order table ``verimono run`` prints compared with the README's quoted one.  (The Python blocks of the README and
of docs/ are executed by ``tests/project/test_docs.py``; the quick start by CI.)"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow   # subprocesses: whole verimono runs and a pytest session

REPO = Path(__file__).resolve().parents[2]
README = (REPO / "README.md").read_text(encoding="utf-8")


def section(heading: str) -> str:
    match = re.search(rf"^#+ {re.escape(heading)}\n(.*?)(?=^#+ |\Z)", README, re.S | re.M)
    assert match, f"README has no section {heading!r}"
    return match.group(1)


def code(text: str, lang: str) -> list[str]:
    return re.findall(rf"^```{lang}\n(.*?)^```", text, re.S | re.M)


def readme_file(name: str) -> str:
    found = [b for b in code(README, "python") if b.splitlines()[0] == f"# {name}"]
    assert len(found) == 1, f"README has {len(found)} file blocks # {name}"
    return found[0]


def run(words: list[str], cwd: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "CI": "1", "PYTHONPATH": str(cwd), "VERIMONO_EXECUTOR": "serial"}
    env.pop("HYPOTHESIS_PROFILE", None)
    exe = [sys.executable, "-m", "verimono.cli"] if words[0] == "verimono" else [sys.executable, "-m", "pytest"]
    return subprocess.run(exe + words[1:], cwd=cwd, env=env, capture_output=True, text=True, timeout=600)


@pytest.fixture
def reader(tmp_path: Path) -> Path:
    (tmp_path / "mysolver.py").write_text(readme_file("mysolver.py"))
    (tmp_path / "test_mysolver.py").write_text(readme_file("test_mysolver.py"))
    return tmp_path


def test_the_pytest_suite_passes(reader):
    out = run(["pytest", "-q", "-p", "no:cacheprovider", "-n", "0", "test_mysolver.py"], reader)
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-2000:]
    assert "verimono checks" in out.stdout and " 0 failed" in out.stdout


def test_the_gate_names_the_regressions_the_readme_quotes(reader):
    text = section("3. The regression gate")
    (block,) = code(text, "sh")
    commands = [shlex.split(line) for line in block.splitlines() if line.strip()]
    assert [c[:2] for c in commands] == [["verimono", "check"], ["verimono", "baseline"], ["verimono", "check"],
                                         ["verimono", "gate"]]
    for words in commands[:2]:
        first = run(words, reader)
        assert first.returncode == 0, first.stdout[-3000:] + first.stderr[-2000:]
    source = (reader / "mysolver.py").read_text()
    lost = "\n".join(line for line in source.splitlines() if "# the input term" not in line
                     and "if dU is not None:" not in line)
    assert lost != source
    (reader / "mysolver.py").write_text(lost)
    check = run(commands[2], reader)
    gate = run(commands[3], reader)
    assert check.returncode == 1 and gate.returncode == 1, gate.stdout[-3000:] + gate.stderr[-2000:]
    (quoted,) = code(text, "text")
    for line in quoted.splitlines():
        prefix = line.split("...")[0].rstrip()
        assert any(printed.startswith(prefix) for printed in gate.stdout.splitlines()), (
            f"the README quotes {prefix!r}; the gate printed:\n{gate.stdout[-3000:]}")


def test_the_order_table_is_what_verimono_run_prints(tmp_path):
    (table,) = code(section("1. The verification run and its report"), "text")
    out = run(["verimono", "run", "--profile", "ci", "--stage", "convergence", "--out", str(tmp_path / "out")],
              tmp_path)
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-2000:]
    printed = [line for line in out.stdout.splitlines() if line.startswith("  ")]
    assert printed[:len(table.splitlines())] == table.splitlines()
