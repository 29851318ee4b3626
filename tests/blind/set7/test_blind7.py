"""Blind set 7 (tests/blind/set7/subjects.py): each plant's witness violates its law at its smallest input and each
control's obeys it (fast, plain NumPy); and, in the slow tier, verimono's verdict on each entry at the ``ci``
profile: every plant has a failed record, every control none failed and none undecided.  The plants verimono
misses are strict xfails whose reason is the measured miss (tests/blind/set7/README.md tables every run)."""

import importlib.util
import pathlib

import pytest

_DIR = pathlib.Path(__file__).resolve().parent
_RSPEC = importlib.util.spec_from_file_location("verimono_blind_set7_runner", _DIR / "run_blind7.py")
runner = importlib.util.module_from_spec(_RSPEC)
_RSPEC.loader.exec_module(runner)
S = runner.subjects()

PLANTS = [e for e in S.ENTRIES if not e.lawful]
CONTROLS = [e for e in S.ENTRIES if e.lawful]

#: plants verimono's ci battery (seed 0) misses, measured on main 9e58e7d: name -> reason
MISSED: dict[str, str] = {
    "soft_threshold_decade_1e-9":
        "a Yosida error of 50% at λ in [1e-9, 1e-8): evaluated there (λ = 1e-9, |x| ≈ 9) but judged at the slack "
        "RTOL(1 + |x|)/λ of Y_λ = (x - J_λx)/λ, which exceeds the error; missed at ci, dev and thorough",
    "halfspace_lag_in_t_window":
        "a lag confined to t in [0.61, 0.62): ci's t resolution is 0.019 (disclosed in the record); thorough catches it",
    "soft_threshold_skips_tiny_steps":
        "J_λx = x for λ < 1e-12: Y_λx = 0 ∉ F(J_λx), 10^3 times the rounding of (x - J)/λ at λ = 1e-13, |x| = 1, but "
        "below the slack RTOL(1 + |x|)/λ; missed at ci, dev and thorough",
}


def test_set_shape():
    assert len(PLANTS) >= 25 and len(CONTROLS) >= 10
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


def _marks(e):
    if e.name in MISSED:
        return [pytest.mark.xfail(strict=True, reason=MISSED[e.name])]
    return []


@pytest.mark.slow
@pytest.mark.parametrize("entry", [pytest.param(e, marks=_marks(e), id=e.name) for e in S.ENTRIES])
def test_verimono_verdict_at_ci(entry):
    res = runner.run_one(entry.name, 0, "ci")
    good, text = runner.verdict(entry, res)
    assert good, f"{entry.name} ({'control' if entry.lawful else 'plant'}, {entry.label}): {text}"
