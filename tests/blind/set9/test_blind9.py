"""Blind set 9 (tests/blind/set9/subjects.py): each plant's witness violates its law at its smallest input and each
control's obeys it (fast, plain NumPy); and, in the slow tier, verimono's verdict on each entry at the ``ci``
profile: every plant has a failed record, every control none failed and none undecided.  The plants verimono
misses are strict xfails whose reason is the measured miss (tests/blind/set9/README.md tables every run)."""

import importlib.util
import pathlib
import subprocess
import sys

import pytest

_DIR = pathlib.Path(__file__).resolve().parent
_RSPEC = importlib.util.spec_from_file_location("verimono_blind_set9_runner", _DIR / "run_blind9.py")
runner = importlib.util.module_from_spec(_RSPEC)
_RSPEC.loader.exec_module(runner)
S = runner.subjects()

PLANTS = [e for e in S.ENTRIES if not e.lawful]
CONTROLS = [e for e in S.ENTRIES if e.lawful]

#: plants verimono's ci battery (seed 0) misses: name -> the measured reason (tests/blind/set9/README.md)
#: box_returns_shared_buffer, missed on 0288656 (no operator law held a value J_λx1 across a later call J_λx2), is caught
#: since resolvent_single_valued keeps the first value over a call at x2 (operator_laws._value_kept)
MISSED: dict[str, str] = {
    "box_value_strict_bounds": "missed at ci seeds 0-2, dev and thorough seed 0 (main 0288656): prox_inequality, prox_optimal, "
                               "prox_minimiser, moreau_envelope passed with 50, 50, 38, 52 samples inconclusive -- the "
                               "prox lands exactly on a face where the declared g is +inf, which is judged as rounding "
                               "at an open domain's boundary, not as a failure. Kept a miss (scale2, on a2671ac): in "
                               "floating point {|x_i| < 1} is the closed box of half-width 1 - 2^-53 and clip its "
                               "projection within one ulp; at p = (1, 0, 0) the plant shows exactly what correct code "
                               "shows (PyProximal's EuclideanBall at 1e6·(1, 1, 1): its own projection, a fixed point of "
                               "its prox, rejected by its membership, accepted one ulp inward) -- tests/checks/"
                               "test_judged_at_precision.py::test_a_strict_box_indicator_shows_at_its_face_what_correct_"
                               "code_shows",
}


def test_set_shape():
    assert len(PLANTS) >= 25 and len(CONTROLS) >= 12
    assert len(S.BY_NAME) == len(S.ENTRIES)
    for e in S.ENTRIES:
        if e.twin is not None:
            assert S.BY_NAME[e.twin].lawful != e.lawful and S.BY_NAME[e.twin].kind == e.kind, e.name


@pytest.mark.parametrize("entry", PLANTS, ids=lambda e: e.name)
def test_plant_witness_violates_its_law(entry):
    assert entry.witness() > 1.0, f"{entry.name}: {entry.label} holds at {entry.smallest}"


@pytest.mark.parametrize("entry", CONTROLS, ids=lambda e: e.name)
def test_control_witness_obeys_its_law(entry):
    assert entry.witness() <= 1.0, f"{entry.name}: {entry.label} violated at {entry.smallest}"


#: entries whose verdict is taken in a subprocess of their own: their bug writes into the problems verimono shares
#: within a process, and every stepper checked after them there fails (README.md, "A plant that poisons the process")
ISOLATED = {"resume_into_problem_x0"}


def _marks(e):
    if e.name in MISSED:
        return [pytest.mark.xfail(strict=True, reason=MISSED[e.name])]
    return []


@pytest.mark.slow
@pytest.mark.parametrize("entry", [pytest.param(e, marks=_marks(e), id=e.name) for e in S.ENTRIES])
def test_verimono_verdict_at_ci(entry):
    if entry.name in ISOLATED:
        res = runner.common.child(runner.BLIND, entry.name, 0, "ci", 900.0)
    else:
        res = runner.run_one(entry.name, 0, "ci")
    good, text = runner.verdict(entry, res)
    assert good, f"{entry.name} ({'control' if entry.lawful else 'plant'}, {entry.label}): {text}"


_POISON = """
import sys
sys.path.insert(0, sys.argv[1])
import subjects as S
import verimono as vm
vm.check_stepper(S.BY_NAME["resume_into_problem_x0"].build()[0], seed=0, profile="ci")
report = vm.check_stepper(vm.solve, seed=0, profile="ci")
print("POISON-RESULT", report.ok, sorted({r.check + "[" + r.subject + "]" for r in report.failures})[:3])
"""


@pytest.mark.slow
# measured on main 0288656 (blind9): after check_stepper on resume_into_problem_x0 the same process's
# check_stepper(vm.solve, seed=0, profile='ci') failed in_domain, trajectory_immutable and bounds_lg on generated #0 and
# #2 -- the generated problems are shared and kept the overwritten x0.  Since a Problem's x0 is read-only
# (verimono/core/problem.py) the plant fails where it writes, and the process stays clean
def test_a_stepper_writing_into_x0_does_not_poison_later_checks():
    cp = subprocess.run([sys.executable, "-c", _POISON, str(_DIR)], capture_output=True, text=True, timeout=1200)
    line = [ln for ln in cp.stdout.splitlines() if ln.startswith("POISON-RESULT")]
    assert line, cp.stderr[-2000:]
    assert line[-1].startswith("POISON-RESULT True"), line[-1]
