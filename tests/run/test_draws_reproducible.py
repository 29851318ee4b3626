"""The draws that feed records are a function of the seed alone, not of what else is imported.

Hypothesis (≥ 6.131) mixes into its draws, with some probability, the numeric literals of every local
module imported so far (``verimono.core._reproducible``): a test run of it with a fixed ``@seed`` drew other
operators once any engineer added a number literal anywhere, and ``reports/baseline.json`` drifted.  The
stage's generated operators and the stepper battery's generated problems are drawn by
``verimono.checks.generated_problems.draw`` instead (hypothesis' provider with those constants off); here a
module of fresh literals is imported between two draws of each and the draws are compared byte for byte
(their resolvents at fixed points to the last bit, and their reprs).  Seen failing on 747bfae, whose
``_generated_operators`` ran hypothesis' test engine: the second draw of the operators differed.
"""

from __future__ import annotations

import hashlib
import importlib
import inspect
import sys
from pathlib import Path

import numpy as np
import pytest

from verimono.checks.generated_problems import generated_problems
from verimono.execution.profiles import get_profile
from verimono.run.stages.builtin import _generated_operators


def _fingerprint(ops) -> list[str]:
    """Each operator's resolvents at fixed points, times and steps, to the last bit (its repr rounds to 4 digits)."""
    out = []
    for op in ops:
        x = np.linspace(-2.0, 3.0, 5 * op.dim).reshape(5, op.dim)
        vals = [np.asarray(op.resolvent(xi, lam, t), dtype=float) for xi in x for lam in (0.1, 1.0, 7.0)
                for t in (0.0, 0.37, 1.0)]
        out.append(hashlib.sha256(repr(op).encode() + np.concatenate(vals).tobytes()).hexdigest())
    return out


def _import_constants(tmp_path, name: str) -> None:
    """An unrelated module of the user, full of numeric literals hypothesis would collect, imported."""
    values = [0.125 * k for k in range(-80, 81)] + [1e-3 * k for k in range(1, 60)] + [2.0 ** k for k in range(-30, 31)]
    (tmp_path / f"{name}.py").write_text("\n".join(f"C{i} = {v!r}" for i, v in enumerate(values)) + "\n")
    sys.path.insert(0, str(tmp_path))
    try:
        importlib.import_module(name)     # left in sys.modules: hypothesis looks there (it notices a new length)
    finally:
        sys.path.remove(str(tmp_path))


def test_generated_operators_and_problems_do_not_move_with_an_unrelated_import(tmp_path):
    profile = get_profile("ci")
    ops = _generated_operators(profile, 0)
    problems = generated_problems(0, 6)
    _import_constants(tmp_path, "vm_user_constants_ops")
    again_ops = _generated_operators(profile, 0)
    again_problems = generated_problems(0, 6)
    assert [label for label, _ in ops] == [label for label, _ in again_ops]
    assert _fingerprint(op for _, op in ops) == _fingerprint(op for _, op in again_ops)
    assert _fingerprint(p.operator for p in problems) == _fingerprint(p.operator for p in again_problems)
    assert [repr(p) for p in problems] == [repr(p) for p in again_problems]
    # not vacuous: six operators in dimensions 1-3, not all alike
    assert len(ops) == profile.generated_subjects == 6 and len(set(_fingerprint(op for _, op in ops))) == 6
    assert sorted({op.dim for _, op in ops}) == [1, 2, 3]


def test_generated_operators_depend_on_the_seed():
    profile = get_profile("ci")
    assert _fingerprint(op for _, op in _generated_operators(profile, 0)) != \
        _fingerprint(op for _, op in _generated_operators(profile, 1))


_LOCATED = r'''
import hashlib, json, sys
import numpy as np
import verimono
from reference import catalog
from verimono.checks.operator_battery import check_operator
from verimono.execution.profiles import get_profile
from verimono.run.stages.builtin import _generated_operators
''' + inspect.getsource(_fingerprint) + r'''
profile = get_profile("ci")
H = [p.operator for p in catalog() if "Example" in p.name and "\u2212t" in p.name][0]
rep = check_operator(H, seed=0, examples=profile.law_examples)
print(json.dumps({"file": verimono.__file__,
                  "operators": _fingerprint(op for _, op in _generated_operators(profile, 0)),
                  "records": [[r.check, r.status, repr(r.worst), r.details.get("evaluations"), r.counterexample]
                              for r in rep.results]}))
'''


def _located_run(root) -> dict:
    import json
    import os
    import subprocess

    env = {**os.environ, "PYTHONPATH": str(root), "PYTHONHASHSEED": "random"}
    out = subprocess.run([sys.executable, "-c", _LOCATED], cwd=root, env=env, capture_output=True, text=True,
                         timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert got["file"].startswith(str(root)), got["file"]      # the copy ran, not the installed package
    return got


@pytest.mark.slow
def test_the_same_code_at_another_path_gives_the_same_records(tmp_path):
    """A run is a function of (code, seed, profile): the package copied to two folders — one under a folder
    named ``tests``, which hypothesis excludes when it collects local constants (``is_local_module_file``) —
    draws the same six operators and gives the paper Example's ``H`` the same operator-law records
    (evaluations, worst ratios to the bit), hash randomisation on.  Seen failing on 747bfae: the copy under
    ``tests/`` drew other operators #2 and #3 (verimono's own literals no longer in hypothesis' pool)."""
    import shutil

    import verimono

    src = Path(verimono.__file__).resolve().parent.parent
    runs = []
    for root in (tmp_path / "a", tmp_path / "tests" / "elsewhere_longer_name"):
        for pkg in ("verimono", "reference"):
            shutil.copytree(src / pkg, root / pkg, ignore=shutil.ignore_patterns("__pycache__"))
        runs.append(_located_run(root))
    a, b = runs
    assert a["operators"] == b["operators"] and len(set(a["operators"])) == 6
    assert a["records"] == b["records"]
    assert sum(r[1] == "passed" for r in a["records"]) >= 10 and all(r[3] for r in a["records"][:15])
