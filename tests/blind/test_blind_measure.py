"""The blind set's own evidence: every plant's independent NumPy measure exceeds 1, every control's is at most 1.

No verimono check runs here (``tests/blind/run_blind.py`` does that); the measures take well under a second.
"""

import importlib.util
import pathlib
import sys

import pytest

_PATH = pathlib.Path(__file__).with_name("plants.py")
_NAME = "verimono_blind_plants"
if _NAME not in sys.modules:
    _spec = importlib.util.spec_from_file_location(_NAME, _PATH)
    _mod = importlib.util.module_from_spec(_spec)
    sys.modules[_NAME] = _mod
    _spec.loader.exec_module(_mod)
plants = sys.modules[_NAME]


def test_blind_set_is_large_enough():
    bad = [e for e in plants.PLANTS if not e.lawful]
    good = [e for e in plants.PLANTS if e.lawful]
    assert len(bad) >= 24 and len(good) >= 8
    assert len({e.name for e in plants.PLANTS}) == len(plants.PLANTS)
    assert {e.kind for e in plants.PLANTS} <= {"operator", "stepper"}


@pytest.mark.parametrize("entry", [e for e in plants.PLANTS if not e.lawful], ids=lambda e: e.name)
def test_plant_violates_its_law(entry):
    ratio = entry.measure()
    assert ratio > 1.0, f"{entry.name}: measured ratio {ratio!r} does not violate {entry.label}"


@pytest.mark.parametrize("entry", [e for e in plants.PLANTS if e.lawful], ids=lambda e: e.name)
def test_control_obeys_its_law(entry):
    ratio = entry.measure()
    assert ratio <= 1.0, f"{entry.name}: measured ratio {ratio!r} violates {entry.label}"
