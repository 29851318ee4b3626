"""The user's problems alone (issue 40, item 4): ``Problem(data=...)`` carried to every copy, ``check_stepper`` /
``parametrize_with_checks`` with ``problems=`` and ``verimono check --problem ... --only`` running exactly those
problems, and a stepper declining a problem it does not handle (``verimono.NotApplicable``): counted skips with
its reason, never failures."""

from __future__ import annotations

import json
import pickle
from pathlib import Path

import cloudpickle
import numpy as np
import pytest

import verimono as vm
from verimono.reference import linear, subdifferential
from verimono.run.targets import load_target

TARGETS = str(Path(__file__).with_name("only_targets.py"))


def targets(*names):
    return [load_target(f"{TARGETS}:{n}") for n in names]


def test_problem_data_is_carried_to_every_copy_and_checked():
    (problems,) = targets("problems")
    p = problems[0]
    assert p.data == {"radius": 0.5}
    assert p.replace(T=0.5).data == {"radius": 0.5}                       # replace, the shrinking of a failure
    assert p.replace(x0=np.zeros((2, 2))).data == {"radius": 0.5}         # a batch
    assert cloudpickle.loads(cloudpickle.dumps(p)).data == {"radius": 0.5}  # to the workers
    assert pickle.loads(pickle.dumps({"a": 1})) == vm.Problem(linear.linear().operator, [1.0, 0.0], 1.0,
                                                              data={"a": 1}).data
    given = {"radius": 1.0}
    q = p.replace(data=given)
    given["radius"] = 3.0                                                 # the problem keeps its own copy
    assert q.data == {"radius": 1.0} and linear.linear().data == {}
    with pytest.raises(vm.InvalidProblem, match="mapping"):
        p.replace(data=[("radius", 1.0)])
    with pytest.raises(vm.InvalidProblem, match="strings"):
        p.replace(data={1: 2.0})


def test_a_problem_specific_stepper_on_its_own_problems_only():
    catching_up, problems = targets("catching_up", "problems")
    report = vm.check_stepper(catching_up, problems, profile="dev")
    subjects = {r.subject for r in report}
    assert subjects == {"catching_up on small ball", "catching_up on large ball"}
    assert not report.failures and not any("KeyError" in r.message for r in report)
    assert len(report) == 2 * (1 + len(vm.checks.stepper_battery.CHECKS))   # every law, on exactly those
    # the same stepper on the catalog cannot find its parameters: what --only spares it
    rec = vm.check_stepper(catching_up, [linear.linear()], laws=["in_domain"], orders=False).results[0]
    assert rec.status == "failed" and "KeyError" in rec.message


def test_parametrize_with_checks_on_the_given_problems_only():
    from verimono.testing import checks_for

    catching_up, problems = targets("catching_up", "problems")
    names = [n for n, _ in checks_for(catching_up, problems=problems)]
    assert {n.partition("[")[2][:-1] for n in names} == {"small ball", "large ball"}
    assert len(names) == 2 * (1 + len(vm.checks.stepper_battery.CHECKS))


def test_an_ode_integrator_declines_set_valued_problems_with_a_counted_skip():
    ode_euler, euler = targets("ode_euler", "euler")      # euler: the declining integrator, unwrapped
    tnorm, lin = subdifferential.t_norm(), linear.linear()
    report = vm.check_stepper(ode_euler, [tnorm, lin], profile="dev")
    on_tnorm = [r for r in report if r.subject.endswith("t|x| (n=1)")]
    assert on_tnorm and all(r.status == "skipped" for r in on_tnorm)
    assert all("single-valued" in r.message or "needs" in r.message for r in on_tnorm)
    assert sum("set-valued F" in r.message for r in on_tnorm) >= 3      # convergence_order, in_domain, unique_limit
    on_linear = {r.check: r.status for r in report if r.subject.endswith("-Mx")}
    assert on_linear["convergence_order"] == "passed" and on_linear["unique_limit"] == "passed"
    assert not report.failures
    # the diffrax stepper refused them with its own error: failures, the symptom the skip replaces
    def refuses(problem, t_grid):
        if not isinstance(problem.operator, vm.Linear):
            raise ValueError("not a constant linear operator")
        return euler(problem, t_grid)

    failed = vm.check_stepper(vm.Stepper(refuses, scheme="any", order=1), [tnorm], profile="dev").failures
    assert failed and all("not a constant linear operator" in r.message for r in failed)


@pytest.mark.slow
def test_verimono_check_only_runs_exactly_the_given_problems(tmp_path):
    from verimono.cli import main

    code = main(["check", f"{TARGETS}:catching_up", "--problem", f"{TARGETS}:problems", "--only",
                 "--executor", "serial", "--profile", "dev", "--out", str(tmp_path)])
    text = (tmp_path / "results.json").read_text()
    doc = json.loads(text)
    subjects = {r["subject"] for r in doc["results"]}
    assert subjects == {"catching_up on small ball", "catching_up on large ball"}, subjects
    assert not any("KeyError" in r["message"] for r in doc["results"])
    assert code == 0 and doc["meta"]["selection"]["problems"] == ["small ball", "large ball"]
    assert "radius" not in text                         # the user's data is never written into the records
    # --only with no problem named is misuse: exit 2 before any work
    assert main(["check", f"{TARGETS}:catching_up", "--only", "--out", str(tmp_path / "none")]) == 2
