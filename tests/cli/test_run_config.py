"""One run configuration: the profile chosen at the entry point decides the whole run's effort.

``verimono check --profile P`` runs P's unit budget (its ``unit_budget`` calibration units, the budget every
call of the subject runs under), P's examples per law and P's scale sweep, whatever ``$CI`` and
``$HYPOTHESIS_PROFILE`` say; without ``--profile`` the environment names the profile.  ``verimono check
--profile thorough`` ran dev's budget (800 units instead of 8000) and dev's sweep (33 samples instead of 132)
before: the budget and the sweep read the environment, not the command line.
"""

from __future__ import annotations

import json
import sys
import textwrap
from pathlib import Path

import pytest

from verimono.checks.engine.sweep import sweep_count
from verimono.cli import main
from verimono.execution.profiles import PROFILES, get_profile

TARGET = '''
import numpy as np
import verimono as vm
from verimono.execution import timeouts

#: the unit budget each call of the resolvent ran under (seconds)
BUDGETS = set()


def shrink(x, lam, t):
    BUDGETS.add(timeouts.current_budget())
    return np.asarray(x, dtype=float) / (1.0 + lam)


op = vm.operator_from_resolvent(shrink, 1, name="shrink")
'''


@pytest.fixture
def target(tmp_path):
    path = tmp_path / "shrinking.py"
    path.write_text(textwrap.dedent(TARGET))
    return path


def checked(target: Path, out: Path, args: list[str], monkeypatch, env: dict[str, str]) -> tuple[dict, set]:
    """``verimono check target:op`` in this process (serially, so the subject's calls are seen here) with the
    environment ``env`` (``$CI`` and ``$HYPOTHESIS_PROFILE`` removed first); the results and the budgets seen."""
    for name in ("CI", "HYPOTHESIS_PROFILE"):
        monkeypatch.delenv(name, raising=False)
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    code = main(["check", f"{target}:op", "--executor", "serial", "--seed", "1", "--out", str(out), *args])
    assert code == 0, code
    module = next(m for m in list(sys.modules.values()) if getattr(m, "__file__", None) == str(target))
    budgets = set(module.BUDGETS)
    module.BUDGETS.clear()
    return json.loads((out / "results.json").read_text()), budgets


def assert_ran_at(doc: dict, budgets: set, profile: str) -> None:
    """The records, the run's configuration and the subject's calls all show ``profile``'s effort."""
    effort = get_profile(profile)
    assert doc["meta"]["profile"] == profile
    laws = [r for r in doc["results"] if "examples" in r["details"]]
    assert len(laws) >= 10, [r["check"] for r in doc["results"]]
    assert {r["details"]["examples"] for r in laws} == {effort.law_examples}
    swept = [r for r in laws if r["details"].get("sweep")]
    assert len(swept) >= 5
    for r in swept:
        assert r["details"]["sweep"] == sweep_count(profile, r["check"]), (profile, r["check"], r["details"])
    # every call of the subject ran under the profile's budget: its units x the run's calibration
    seconds = effort.unit_budget * doc["meta"]["calibrations"][0]
    assert budgets and all(b == pytest.approx(seconds, rel=1e-12) for b in budgets), (profile, seconds, budgets)
    assert doc["meta"]["config"]["profile"] == profile
    assert doc["meta"]["config"]["unit_budget"]["seconds"] == pytest.approx(seconds, rel=1e-12)


def other(profile: str) -> str:
    return {"dev": "thorough", "ci": "dev", "thorough": "ci"}[profile]


def test_profile_ci_runs_cis_effort_under_another_hypothesis_profile(target, tmp_path, monkeypatch):
    """The fast case of the matrix below: ci's budget (1600 units, dev's is 800) and examples (20, dev's 10)
    with ``$HYPOTHESIS_PROFILE=dev``."""
    doc, budgets = checked(target, tmp_path, ["--profile", "ci"], monkeypatch, {"HYPOTHESIS_PROFILE": "dev"})
    assert_ran_at(doc, budgets, "ci")
    assert doc["meta"]["config"]["source"] == "--profile"


@pytest.mark.slow
@pytest.mark.parametrize("env", ["unset", "CI", "HYPOTHESIS_PROFILE"])
@pytest.mark.parametrize("profile", PROFILES)
def test_each_profile_through_verimono_check(profile, env, target, tmp_path, monkeypatch):
    """``--profile P`` with ``$CI`` and ``$HYPOTHESIS_PROFILE`` unset, ``$CI=1``, and ``$HYPOTHESIS_PROFILE``
    naming another profile: P's budget, examples and sweep every time."""
    environment = {"unset": {}, "CI": {"CI": "1"}, "HYPOTHESIS_PROFILE": {"HYPOTHESIS_PROFILE": other(profile)}}[env]
    doc, budgets = checked(target, tmp_path, ["--profile", profile], monkeypatch, environment)
    assert_ran_at(doc, budgets, profile)


@pytest.mark.slow
@pytest.mark.parametrize("profile", PROFILES)
def test_without_profile_the_environment_names_it(profile, target, tmp_path, monkeypatch):
    doc, budgets = checked(target, tmp_path / "named", [], monkeypatch, {"HYPOTHESIS_PROFILE": profile, "CI": "1"})
    assert_ran_at(doc, budgets, profile)
    assert doc["meta"]["config"]["source"] == "$HYPOTHESIS_PROFILE"
    if profile == "ci":
        doc, budgets = checked(target, tmp_path / "ci", [], monkeypatch, {"CI": "true"})
        assert_ran_at(doc, budgets, "ci")
        assert doc["meta"]["config"]["source"] == "$CI"
