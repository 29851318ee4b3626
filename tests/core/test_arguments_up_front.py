"""What the harness is given is checked before any work, with a typed error (issue 41, item 4).

Before, each case below was accepted and then charged to the subject (``Problem(..., lipschitz=-1)`` made a
correct stepper fail ``contraction``; ``check_stepper(executor=object())`` recorded a failed
``convergence_order``; ``step_range=(0, 0.1)`` an undecided one), accepted as something else (``orders='no'``
ran the orders), or ended in a raw ``TypeError``/``AttributeError`` (``laws=None``, a single ``Problem``, a
non-callable to ``convergence_study``).  Each must now raise the stated :class:`verimono.VerimonoError` subclass
naming the argument, and the subject must never have been called.
"""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.core.errors import InvalidCheckArgument, InvalidClaim, InvalidProblem
from verimono.reference import get

P = get("t|x| (n=1)")


class Counting:
    """A correct stepper (the library's own) that counts its calls: none may happen on bad arguments."""

    def __init__(self):
        self.calls = 0
        self.__name__ = "counting"

    def __call__(self, problem, t_grid):
        self.calls += 1
        return vm.solve(problem, t_grid).x


def _problem(**kw):
    return lambda s: vm.Problem(P.operator, P.x0, P.T, **kw)


def _check(**kw):
    kw.setdefault("laws", False)
    problems = kw.pop("problems", [P])
    return lambda s: vm.check_stepper(s, problems, **kw)


def _study(*args, **kw):
    return lambda s: vm.convergence_study(s, *(args or (P,)), **kw)


NAN, INF = float("nan"), float("inf")
CASES = [
    # -- Problem: every keyword it keeps is checked ---------------------------------------------------------------
    ("Problem lipschitz=-1", _problem(lipschitz=-1), InvalidProblem, "lipschitz"),
    ("Problem lipschitz=nan", _problem(lipschitz=NAN), InvalidProblem, "lipschitz"),
    ("Problem lipschitz=inf", _problem(lipschitz=INF), InvalidProblem, "lipschitz"),
    ("Problem lipschitz='1'", _problem(lipschitz="1"), InvalidProblem, "lipschitz"),
    ("Problem lipschitz=True", _problem(lipschitz=True), InvalidProblem, "lipschitz"),
    ("Problem steps=[0.1, -0.1]", _problem(steps=[0.1, -0.1]), InvalidProblem, "steps"),
    ("Problem steps=['a']", _problem(steps=["a"]), InvalidProblem, "steps"),
    ("Problem steps=0.1", _problem(steps=0.1), InvalidProblem, "steps"),
    ("Problem phi=3", _problem(phi=3), InvalidProblem, "phi"),
    ("Problem sigma='x'", _problem(sigma="x"), InvalidProblem, "sigma"),
    ("Problem name=3", _problem(name=3), InvalidProblem, "name"),
    ("Problem notes=None", _problem(notes=None), InvalidProblem, "notes"),
    ("Problem initial_jump='no'", _problem(initial_jump="no"), InvalidProblem, "initial_jump"),
    # -- check_stepper ----------------------------------------------------------------------------------------------
    ("check_stepper executor=object()", _check(executor=object()), InvalidCheckArgument, "executor"),
    ("check_stepper executor='threads'", _check(executor="threads"), InvalidCheckArgument, "executor"),
    ("check_stepper executor='process:0'", _check(executor="process:0"), InvalidCheckArgument, "executor"),
    ("check_stepper step_range=(0, 0.1)", _check(step_range=(0, 0.1)), InvalidCheckArgument, "step_range"),
    ("check_stepper step_range=(nan, 0.1)", _check(step_range=(NAN, 0.1)), InvalidCheckArgument, "step_range"),
    ("check_stepper step_range=(0.1, inf)", _check(step_range=(0.1, INF)), InvalidCheckArgument, "step_range"),
    ("check_stepper step_range=0.1", _check(step_range=0.1), InvalidCheckArgument, "step_range"),
    ("check_stepper step_range=(1, 2, 3)", _check(step_range=(0.1, 0.2, 0.3)), InvalidCheckArgument, "step_range"),
    ("check_stepper orders='no'", _check(orders="no", laws=["contraction"]), InvalidCheckArgument, "orders"),
    ("check_stepper orders=None", _check(orders=None, laws=["contraction"]), InvalidCheckArgument, "orders"),
    ("check_stepper laws=None", _check(laws=None), InvalidCheckArgument, "laws"),
    ("check_stepper laws='contraction'", _check(laws="contraction"), InvalidCheckArgument, "laws"),
    ("check_stepper laws=[3]", _check(laws=[3]), InvalidCheckArgument, "laws"),
    ("check_stepper a single Problem", _check(problems=P), InvalidCheckArgument, "list"),
    ("check_stepper problems=[P, 3]", _check(problems=[P, 3]), InvalidCheckArgument, "Problem"),
    ("check_stepper problems='abc'", _check(problems="abc"), InvalidCheckArgument, "list"),
    ("check_stepper generated=1.5", _check(generated=1.5), InvalidCheckArgument, "generated"),
    # -- convergence_study -------------------------------------------------------------------------------------------
    ("convergence_study reference_refinement=1.5", _study(reference_refinement=1.5), InvalidProblem,
     "reference_refinement"),
    ("convergence_study reference_refinement=1", _study(reference_refinement=1), InvalidProblem,
     "reference_refinement"),
    ("convergence_study reference_refinement='8'", _study(reference_refinement="8"), InvalidProblem,
     "reference_refinement"),
    ("convergence_study executor=object()", _study(executor=object()), InvalidProblem, "executor"),
    ("convergence_study step_range=(nan, 0.1)", _study(step_range=(NAN, 0.1)), InvalidProblem, "step_range"),
    ("convergence_study a problem that is not one", _study(3), InvalidProblem, "Problem"),
    ("convergence_study steps=0.1", _study(steps=0.1), InvalidProblem, "steps"),
    ("convergence_study solve_tol=-1", _study(solve_tol=-1.0), InvalidClaim, "solve_tol"),
    ("convergence_study expected=2", _study(expected=2), InvalidProblem, "expected"),
]


@pytest.mark.parametrize("build, error, words", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_a_bad_argument_is_refused_before_any_work(build, error, words):
    s = Counting()
    with pytest.raises(error) as info:
        build(s)
    assert isinstance(info.value, vm.VerimonoError)
    assert words in str(info.value), str(info.value)
    assert s.calls == 0, "the stepper was called: the harness's input was charged to the subject"


@pytest.mark.parametrize("stepper", [3, "solve", None, vm.Problem], ids=["int", "str", "None", "a class"])
def test_convergence_study_of_what_is_not_a_stepper_is_a_typed_error(stepper):
    with pytest.raises(InvalidClaim, match="stepper"):
        vm.convergence_study(stepper, P)


def test_the_accepted_forms_still_run():
    """The forms the checks take keep working (the controls of the cases above): a lipschitz of 0 or an integer,
    ``numpy`` numbers, a tuple of steps, a tuple of laws, ``orders=0``/``1`` as the integers Python's bools are,
    a study of a :class:`verimono.Stepper`."""
    assert vm.Problem(P.operator, P.x0, P.T, lipschitz=0).lipschitz == 0
    assert vm.Problem(P.operator, P.x0, P.T, lipschitz=np.float32(2.5), steps=(0.1, np.float64(0.05))).steps == \
        [0.1, 0.05]
    s = Counting()
    rep = vm.check_stepper(s, (P,), laws=("contraction",), orders=False)
    assert [r.check for r in rep.results] == ["contraction"] and rep.results[0].status == "passed" and s.calls > 0
    study = vm.convergence_study(vm.Stepper(s), P, reference_refinement=np.int64(4), executor="serial")
    assert study.decision().ok


def test_a_correct_stepper_never_fails_contraction_for_the_problems_lipschitz():
    """The case that was charged: ``lipschitz=-1`` made the contraction factor ``e^{-h}`` and the library's own
    stepper 'failed'.  Now the problem cannot be built, and the honest constant passes."""
    with pytest.raises(InvalidProblem):
        vm.Problem(P.operator, P.x0, P.T, lipschitz=-1)
    rep = vm.check_stepper(vm.solve, [vm.Problem(P.operator, P.x0, P.T, lipschitz=0.0, name="L = 0")],
                           laws=["contraction"], orders=False)
    assert rep.results[0].status == "passed"


@pytest.mark.parametrize("call, words", [
    (lambda: vm.work_precision(3, P), "list of steppers"),
    (lambda: vm.work_precision([vm.solve, 3], P), "callable"),
    (lambda: vm.work_precision([vm.solve, vm.Stepper(vm.solve, name="b")], "P"), "Problem"),
    (lambda: vm.work_precision([vm.solve, vm.Stepper(vm.solve, name="b")], P, rounds=2.5), "rounds"),
    (lambda: vm.work_precision([vm.solve, vm.Stepper(vm.solve, name="b")], P, alpha=1.5), "alpha"),
    (lambda: vm.work_precision([vm.solve, vm.Stepper(vm.solve, name="b")], P, controls=0.1), "controls"),
], ids=["steppers=3", "a stepper 3", "problem a string", "rounds=2.5", "alpha=1.5", "controls=0.1"])
def test_work_precision_refuses_bad_arguments_before_timing_anything(call, words):
    with pytest.raises(InvalidCheckArgument, match=words):
        call()


@pytest.mark.parametrize("rounds", ["0", "-2", "1.5"])
def test_cli_rounds_is_checked_before_anything_is_written(rounds, tmp_path, capsys):
    """``verimono compare --rounds 0`` reached the timing (after marking the folder in progress) before."""
    from verimono.cli import main

    out = tmp_path / "out"
    with pytest.raises(SystemExit) as info:
        main(["compare", "verimono:solve", "verimono:solve", "--reference", "t|x| (n=1)", "--rounds", rounds,
              "--out", str(out)])
    assert info.value.code == 2 and "--rounds" in capsys.readouterr().err
    assert not out.exists()
