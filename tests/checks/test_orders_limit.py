"""convergence_order on a problem without an exact solution: self-convergence plus the limit of
verimono.solve (the proximal scheme converges to the solution, thm:main); reproduction lines; --problem."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

import verimono as vm
from verimono.checks.orders import check_convergence_order, reproduction_script
from verimono.core.problem import Order, with_origin
from verimono.reference import get

PROBLEM_FILE = '''
import numpy as np
import verimono as vm
from verimono.core.problem import Order
from verimono.core.sets import Ball

disc = vm.NormalCone(Ball(lambda t: 0.3 * np.array([np.cos(t), np.sin(t)]), 1.0))
inexact = vm.Problem(disc, np.array([1.2, 0.0]), 2.0, f=lambda x: -0.5 * x, lipschitz=0.5,
                     u=lambda t: np.array([np.cos(3 * t), 0.0]), name="moving disc, no exact solution",
                     steps=[0.04, 0.02, 0.01, 0.005], order=Order(1.0, "stated by the test"))


def drops_u(problem, t):
    """Converges at order 1 — to the solution of the problem without its input."""
    return vm.solve(problem.replace(u=None, U=None), t).x
'''


@pytest.fixture(scope="module")
def user(tmp_path_factory):
    path = tmp_path_factory.mktemp("user") / "user_problem.py"
    path.write_text(textwrap.dedent(PROBLEM_FILE))
    from verimono.run.targets import load_target

    return path, load_target(f"{path}:inexact"), load_target(f"{path}:drops_u")


def _twice(problem, t):
    """Another correct scheme: the proximal scheme on the grid with every cell halved, read at the nodes."""
    fine = np.sort(np.concatenate([t, (t[1:] + t[:-1]) / 2]))
    return vm.solve(problem, fine).x[::2]


def test_a_scheme_converging_to_a_wrong_limit_fails_without_an_exact_solution(user):
    _, problem, drops_u = user
    assert problem.exact is None
    rec = check_convergence_order(drops_u, problem)
    assert rec.status == "failed", rec.message
    assert "not to the solution" in rec.message and rec.details["limit"]["distance"] > rec.details["limit"]["bound"]
    assert rec.worst > 1


def test_correct_schemes_agree_with_the_limit_of_solve(user):
    _, problem, _ = user
    other = check_convergence_order(vm.Stepper(_twice, scheme="any", order=1), problem)
    assert other.status == "passed", other.message
    assert other.details["limit"]["distance"] <= other.details["limit"]["bound"]
    own = check_convergence_order(vm.solve, problem)
    assert own.status == "passed" and "limit" not in own.details       # solve is the reference itself


def test_reproduction_lines_name_where_the_problem_comes_from(user):
    path, problem, _ = user
    assert "problem = get('t|x| (n=1)')" in reproduction_script(get("t|x| (n=1)"))
    assert f"load_target('{path}:inexact')" not in reproduction_script(problem)   # loaded, but not declared
    assert f"load_target('{path}:inexact')" in reproduction_script(with_origin(problem, f"{path}:inexact"))
    own = vm.Problem(vm.Linear([[1.0]]), np.array([1.0]), 1.0, name="mine", order=Order(1.0, "t"), steps=[0.1, 0.05])
    script = reproduction_script(own)
    assert "problem = ..." in script and "'mine'" in script and "check_convergence_order(stepper, problem)" in script


def test_check_takes_a_problem_from_the_command_line(user, tmp_path, capsys):
    from verimono.cli import main

    path, _, _ = user
    out = tmp_path / "out"
    code = main(["check", f"{path}:drops_u", "--problem", f"{path}:inexact", "--out", str(out)])
    text = capsys.readouterr().out
    assert code == 1 and "moving disc, no exact solution" in text and "FAILED" in text
    from verimono.records.results import load

    rec = next(r for r in load(out / "results.json").results
               if r.check == "convergence_order" and "no exact" in r.subject)
    assert rec.status == "failed" and f"load_target('{path}:inexact')" in rec.details["reproduce_python"]
    assert main(["check", f"{path}:drops_u", "--problem", f"{path}:disc", "--out", str(out)]) == 2
    assert "expected a verimono.Problem" in capsys.readouterr().err
