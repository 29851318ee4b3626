"""Run verimono on blind set 10 (tests/blind/set10/subjects.py) and tabulate what it catches.

    python tests/blind/set10/run_blind10.py [--profile ci] [--seeds 0] [--cap SECONDS] [--only NAME ...] [--json OUT]

Operators go to ``vm.check_operator(op, seed=s, profile=p)``, steppers to ``vm.check_stepper(stepper, seed=s,
profile=p)`` (the reference catalog plus the profile's generated problems), each (entry, seed) in its own
subprocess under a time cap, one at a time.  A plant is caught when a record failed (the table names the check,
the subject of its worst failed record and its worst ratio); a control passes when no record failed and none is
undecided (any failed or undecided record of a control is a false alarm, printed with its record).
"""

from __future__ import annotations

import importlib.util
import pathlib
import sys

HERE = pathlib.Path(__file__).resolve().parent
_spec = importlib.util.spec_from_file_location("verimono_blind_runner", HERE.parent / "blind_runner.py")
common = sys.modules.get("verimono_blind_runner")
if common is None:
    common = importlib.util.module_from_spec(_spec)
    sys.modules["verimono_blind_runner"] = common
    _spec.loader.exec_module(common)

BLIND = common.BlindSet(10, HERE / "run_blind10.py", __doc__)


def subjects():
    return BLIND.subjects()


def run_one(name: str, seed: int, profile: str) -> dict:
    return common.run_one(BLIND, name, seed, profile)


verdict = common.verdict


if __name__ == "__main__":
    sys.exit(common.main(BLIND))
