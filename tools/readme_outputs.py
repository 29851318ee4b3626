"""Regenerate the printed output the README quotes, and compare it with the README (issue 33, item 5).

The README quotes what four things print: the walk-through's failures of the stepper that forgot its input
(``check_stepper(my_stepper)``), the regression gate after that refactoring (``verimono gate``, section "3. The
regression gate"), the ``verimono checks`` summary of the README's pytest suite under ``CI=1``, and
``verimono run --profile ci``.  This script rebuilds ``mysolver.py`` from the README's own code (the
"Verify your own solver" walk-through: ``disc_projection``, ``moving_disc``, the first ``my_stepper`` — the one
that forgot ``u(t)`` — and the last, corrected one), runs each in a temporary folder, and prints the output.

    python tools/readme_outputs.py                       # print every block (run: 1-3 minutes)
    python tools/readme_outputs.py --only walkthrough gate
    python tools/readme_outputs.py --check README.md     # exit 1 when a quoted block differs from today's

``--check``: every ```` ``` ```` block of the README that quotes one of these outputs (found by its first
line) must match the regenerated one line by line, up to timings (``0.2 s``, ``in 4.45s``) and trailing
spaces; a README line ``...`` (alone, indented or not) stands for any number of lines.  A test can call
:func:`stale` the same way.
"""

from __future__ import annotations

import argparse
import ast
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


# -- the README's code ------------------------------------------------------------------------------------

def _section(readme: str, heading: str) -> str:
    match = re.search(rf"^#{{2,4}} {re.escape(heading)}\n(.*?)(?=^#{{2,4}} |\Z)", readme, re.S | re.M)
    if not match:
        raise SystemExit(f"the README has no section {heading!r}")
    return match.group(1)


def _python_blocks(readme: str, heading: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", _section(readme, heading), re.S)


def mysolver(readme: str, fixed: bool) -> str:
    """``mysolver.py`` from the walk-through: its imports, ``disc_projection``, ``moving_disc`` and the first
    ``my_stepper`` (``fixed=False``: it forgot ``u(t)``) or the last (``fixed=True``)."""
    imports: list[str] = []
    keep: dict[str, str] = {}
    steppers: list[str] = []
    for block in _python_blocks(readme, "Verify your own solver"):
        for node in ast.parse(block).body:
            src = ast.get_source_segment(block, node)
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                imports.append(src)
            elif isinstance(node, ast.FunctionDef) and node.name == "my_stepper":
                steppers.append(src)
            elif isinstance(node, ast.FunctionDef):
                keep[node.name] = src
            elif isinstance(node, ast.Assign) and [getattr(t, "id", None) for t in node.targets] == ["moving_disc"]:
                keep["moving_disc"] = src
    if len(steppers) < 2 or "moving_disc" not in keep:
        raise SystemExit("the walk-through no longer defines moving_disc and two versions of my_stepper")
    chosen = steppers[-1] if fixed else steppers[0]
    return "\n".join(dict.fromkeys(imports)) + "\n\n" + "\n\n".join([*keep.values(), chosen]) + "\n"


# -- running ------------------------------------------------------------------------------------------------

def _env(**extra: str) -> dict[str, str]:
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", **extra)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (".", str(REPO), env.get("PYTHONPATH", "")) if p)
    return env


def _run(cmd: list[str], cwd: Path, **extra: str) -> tuple[int, str]:
    proc = subprocess.run(cmd, cwd=cwd, env=_env(**extra), capture_output=True, text=True)
    return proc.returncode, proc.stdout


def _verimono(*args: str) -> list[str]:
    return [sys.executable, "-m", "verimono.cli", *args]


def walkthrough(readme: str, work: Path) -> str:
    """The failures ``check_stepper(my_stepper)`` prints for the stepper that forgot ``u(t)``."""
    (work / "mysolver.py").write_text(mysolver(readme, fixed=False))
    code = ("import verimono as vm\nfrom mysolver import my_stepper\n"
            "for r in vm.check_stepper(my_stepper).failures:\n    print(r)\n")
    return _run([sys.executable, "-c", code], work)[1]


def gate(readme: str, work: Path) -> str:
    """Section 3: check the corrected stepper, record it as the baseline, check the one that forgot ``u(t)``,
    and gate (the README's commands, in the README's folders)."""
    (work / "mysolver.py").write_text(mysolver(readme, fixed=True))
    ci = {"CI": "1"}
    _run(_verimono("check", "mysolver:my_stepper", "--profile", "ci"), work, **ci)
    _run(_verimono("baseline", "--from", "reports/check/results.json", "--out", "reports/baseline.json"), work, **ci)
    (work / "mysolver.py").write_text(mysolver(readme, fixed=False))
    _run(_verimono("check", "mysolver:my_stepper", "--profile", "ci"), work, **ci)
    return _run(_verimono("gate", "--baseline", "reports/baseline.json", "--results", "reports/check/results.json"),
                work, **ci)[1]


def pytest_summary(readme: str, work: Path) -> str:
    """The ``verimono checks`` section of the README's pytest suite under ``CI=1``, to the closing line."""
    (work / "mysolver.py").write_text(mysolver(readme, fixed=True))
    (block,) = re.findall(r"```python\n(.*?)```", _section(readme, "2. pytest"), re.S)
    (work / "test_mysolver.py").write_text(block)
    out = _run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-n", "0", "test_mysolver.py"], work,
               CI="1")[1]
    lines = out.splitlines()
    start = next((i for i, ln in enumerate(lines) if "verimono checks" in ln), None)
    return "\n".join(lines[start:]) + "\n" if start is not None else out


def run_ci(readme: str, work: Path) -> str:
    """``verimono run --profile ci`` (its stage lines, the order table and the summary)."""
    return _run(_verimono("run", "--profile", "ci"), work, CI="1")[1]


OUTPUTS = {"walkthrough": walkthrough, "gate": gate, "pytest": pytest_summary, "run": run_ci}


def regenerate(names: list[str] | None = None, readme: str | None = None) -> dict[str, str]:
    """``{name: printed output}`` for the outputs ``names`` (default all), each in a fresh temporary folder."""
    readme = readme if readme is not None else (REPO / "README.md").read_text()
    out = {}
    for name in names or list(OUTPUTS):
        with tempfile.TemporaryDirectory(prefix=f"readme-{name}-") as tmp:
            out[name] = OUTPUTS[name](readme, Path(tmp))
    return out


# -- comparing -----------------------------------------------------------------------------------------------

_TIMES = [(re.compile(r"\b\d+(?:\.\d+)? s\b"), "<t> s"), (re.compile(r"\bin \d+(?:\.\d+)?s\b"), "in <t>s")]


def normalize(line: str) -> str:
    """A line up to what changes from run to run: durations, trailing spaces."""
    for pattern, repl in _TIMES:
        line = pattern.sub(repl, line)
    return line.rstrip()


def _matches(quoted: list[str], actual: list[str]) -> bool:
    """Whether the README's lines ``quoted`` are ``actual`` (normalized), a ``...`` line standing for any run."""
    q, a = [normalize(x) for x in quoted], [normalize(x) for x in actual]

    def match(i: int, j: int) -> bool:
        if i == len(q):
            return j == len(a) or all(not x for x in a[j:])
        if q[i].strip() == "...":
            return any(match(i + 1, k) for k in range(j, len(a) + 1))
        return j < len(a) and q[i] == a[j] and match(i + 1, j + 1)

    return match(0, 0)


def quoted_blocks(readme: str) -> list[str]:
    """Every plain or ``text`` fenced block of the README."""
    return re.findall(r"^```(?:text)?\n(.*?)^```", readme, re.S | re.M)


def stale(readme: str, outputs: dict[str, str]) -> list[str]:
    """What differs: for each output, the README block that quotes it (the one whose first line is among
    the output's lines) and does not match it, or a note that no block quotes it."""
    problems = []
    for name, text in outputs.items():
        actual = text.splitlines()
        keys = {normalize(x) for x in actual if x.strip()}
        blocks = [b.splitlines() for b in quoted_blocks(readme)]
        candidates = [b for b in blocks if b and normalize(b[0]) in keys]
        if not candidates:
            problems.append(f"{name}: no README block quotes it; today it prints:\n{text}")
        for b in candidates:
            if not _matches(b, actual):
                problems.append(f"{name}: the README quotes\n" + "\n".join(b) + f"\nbut today it prints:\n{text}")
    return problems


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", nargs="+", choices=list(OUTPUTS), default=None)
    ap.add_argument("--check", metavar="README", default=None, help="compare with this README (exit 1 if stale)")
    args = ap.parse_args()
    readme = Path(args.check).read_text() if args.check else (REPO / "README.md").read_text()
    outputs = regenerate(args.only, readme)
    if args.check:
        problems = stale(readme, outputs)
        for p in problems:
            print(p, end="\n\n")
        print(f"{len(outputs) - len({p.split(':')[0] for p in problems})} of {len(outputs)} quoted outputs are "
              "today's")
        return 1 if problems else 0
    for name, text in outputs.items():
        print(f"== {name}\n{text}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
