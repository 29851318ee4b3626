"""One name per subject whatever the entry point, ``--problem`` adding to the references, and messages that
do not contradict themselves (issue 33, item 5)."""

from __future__ import annotations

import argparse
import textwrap

import numpy as np
import pytest

import verimono as vm
from verimono.cli import _context, build_parser, main
from verimono.execution.profiles import get_profile
from verimono.records.results import Report, load
from verimono.reference import catalog, get
from verimono.run.stages import RunContext
from verimono.run.stages.builtin import trajectory_laws_stage

MODULE = textwrap.dedent('''
    import numpy as np
    import verimono as vm

    def swap_prox(x, lam, t):                     # the elastic net's prox on swapped coordinates, a correct one
        x = np.asarray(x, dtype=float)
        return np.sign(x) * np.maximum(np.abs(x) - lam, 0.0) / (1.0 + lam)

    enet_swapped = vm.operator_from_resolvent(swap_prox, 2, name="elastic net swapped")

    def my_stepper(problem, t):
        return vm.solve(problem, t)

    extra = vm.Problem(vm.operator_from_resolvent(swap_prox, 2, name="soft"), np.array([1.0, -2.0]), 1.0,
                       name="my own problem")
''')


@pytest.fixture
def mysolver(tmp_path, monkeypatch):
    (tmp_path / "mysolver_names.py").write_text(MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.chdir(tmp_path)
    import importlib

    return importlib.import_module("mysolver_names")


@pytest.mark.slow
def test_an_operator_has_the_same_record_keys_from_the_cli_and_the_api(mysolver, capsys):
    """The CLI named the subject of every record by the target spec (``mysolver:enet_swapped``), the API and
    pytest by the operator's name (``elastic net swapped``): a baseline from one never gated the other."""
    assert main(["check", "mysolver_names:enet_swapped", "--profile", "dev", "--executor", "serial", "--seed", "0",
                 "--out", "out"]) in (0, 2)
    cli = load("out/results.json")
    api = vm.check_operator(mysolver.enet_swapped, seed=0)
    assert {r.subject for r in cli if r.check != "stage"} == {"elastic net swapped"}
    assert {r.key for r in cli} == {r.key for r in api}
    assert "as an operator" in capsys.readouterr().err


def test_problem_adds_to_the_catalog_and_to_the_chosen_references(mysolver):
    """``--problem`` replaced the catalog (154 records became 8) where the README and --help say it adds."""
    args = argparse.Namespace(problem=["mysolver_names:extra"], reference=None, data=None, seed=None)
    ctx = _context(args)
    names = [p.name for p in ctx.catalog()]
    assert names == [p.name for p in catalog()] + ["my own problem"]
    args.reference = ["moving box"]
    assert [p.name for p in _context(args).catalog()] == ["moving box", "my own problem"]


def test_the_trajectory_laws_keep_the_sampled_problems_beside_a_given_problem(mysolver, monkeypatch):
    seen = []

    def run_units(self, profile, units, costs=None):
        seen.extend(u.label for u in units)
        return [Report() for _ in units]

    monkeypatch.setattr(RunContext, "run_units", run_units)
    profile = get_profile("ci")
    trajectory_laws_stage(profile, RunContext(stepper=mysolver.my_stepper, extra_problems=[mysolver.extra]))
    with_problem = list(seen)
    seen.clear()
    trajectory_laws_stage(profile, RunContext(stepper=mysolver.my_stepper))
    assert with_problem == seen + ["my own problem"] and len(seen) > len(catalog())


def test_the_timeout_help_says_what_the_readme_says():
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    text = " ".join(sub.choices["check"].format_help().split())
    assert "recorded as failed" not in text
    assert "undecided when all it evaluated held" in text


def test_selections_does_not_report_a_membership_the_operator_cannot_test():
    """For an operator without ``contains`` the message said "(contains: True, ...)" beside "y is not in F":
    membership was never asked."""
    box = get("moving box")
    op = vm.operator_from_resolvent(lambda x, lam, t: box.operator.resolvent(x, lam, t), box.dim, name="resolvent only")
    problem = box.replace(operator=op)

    def skewed(p, t):                       # the proximal scheme, every state pushed by a fixed offset
        return np.asarray(vm.solve(p, t).x) + 0.05

    rep = vm.check_stepper(skewed, [problem], laws=["selections"], orders=False)
    (rec,) = rep.results
    assert rec.status == "failed", rec
    assert "contains: True" not in rec.message and "contains: False" not in rec.message
    assert "the operator has no contains" in rec.message
    assert rec.counterexample["contains"] is None


def test_selections_states_the_membership_where_the_operator_tests_it():
    box = get("moving box")

    def skewed(p, t):
        return np.asarray(vm.solve(p, t).x) + 0.05

    (rec,) = vm.check_stepper(skewed, [box], laws=["selections"], orders=False).results
    assert rec.status == "failed" and "contains: False" in rec.message
    assert isinstance(rec.counterexample["contains"], bool) and np.isfinite(rec.worst)
