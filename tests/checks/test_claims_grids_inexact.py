"""Issue 40, items 1 and 3: a stepper states the grids it runs on (``grids="uniform"``) and the tolerance of its
resolvent (``inexact=(C, q)``), and the battery judges it by that claim — on steppers written the way public
sweeping-process codes are (``tests/zoo_steppers.py``: uniform-only catching-up with approximate projections by
dual projected gradient, on the translating ball over ``[0, 2π]``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import verimono as vm
from verimono.core.claims import Inexact, InvalidClaim, Stepper, claim_of, with_claim
from verimono.core.convergence import expected_order
from verimono.checks.trajectory_laws import check_in_domain, check_selections
from verimono.checks.limits import check_unique_limit

import zoo_steppers as zoo

STEP_LAWS = ("contraction", "in_domain", "selections", "bounds_lg", "psi_interpolation")


@pytest.fixture(scope="module")
def problem():
    return zoo.sweeping_2pi()


def uniform_only(fn, **kw):
    return Stepper(fn, grids="uniform", **kw)


# -- item 1: the grids a stepper runs on -----------------------------------------------------------------

def test_a_uniform_only_stepper_refusing_other_grids_fails_every_step_law_without_the_claim(problem):
    """What the issue measured: the correct code, raising ValueError on nonuniform grids, fails the step laws
    when it cannot say that it runs on uniform grids only (the false failures the claim removes)."""
    bare = Stepper(zoo.ball_catching_up(), inexact=(1, 2))
    rec = check_selections(bare, problem)
    assert rec.status == "failed" and "uniform grids only" in rec.message


def test_the_correct_uniform_only_inexact_catching_up_stepper_passes_the_battery(problem):
    s = uniform_only(zoo.ball_catching_up(1.0, 2.0), inexact=(1.0, 2.0))
    report = vm.check_stepper(s, problems=[problem])
    assert report.ok, "\n".join(str(r) for r in report.failures)
    ran = {r.check for r in report if r.status == "passed"}
    assert {"convergence_order", "unique_limit", *STEP_LAWS} <= ran
    for r in report:
        assert r.status in ("passed", "skipped"), r
        if r.status == "skipped":      # bounds_yb: the problem states no θ of (YB) — never a grid
            assert r.check == "bounds_yb" and "θ" in r.message, r


@pytest.mark.parametrize("law", [check_selections, check_in_domain])
def test_step_laws_run_on_uniform_partitions_only_and_say_so(problem, law):
    s = uniform_only(zoo.ball_catching_up(1.0, 2.0), inexact=(1.0, 2.0))
    rec = law(s, problem)
    assert rec.status == "passed", rec
    judged = rec.details["worst_by_grid"]
    assert judged and all(k.startswith(("uniform", "study")) for k in judged), judged
    assert rec.details["grids"]["claimed"] == "uniform"
    assert set(rec.details["grids"]["left_out"]) >= {"random", "graded"}
    assert "uniform partitions only" in rec.message


def test_the_set_taken_at_the_wrong_time_fails_on_a_uniform_only_stepper(problem):
    """The planted bug that was missed (the set's centre at t_{n-1}) when the stepper could only skip every
    step law: judged on its uniform grids it fails."""
    lagged = uniform_only(zoo.ball_catching_up(1.0, 2.0, lag=True), inexact=(1.0, 2.0))
    for law in (check_selections, check_in_domain):
        rec = law(lagged, problem)
        assert rec.status == "failed", rec
        assert rec.counterexample["grid_kind"].startswith("uniform")


def test_a_stepper_stopping_short_of_T_fails(problem):
    """floor(T/h) steps stop one short of T = 2π on the grids of the convergence study (K = 50 ... 800; the
    battery's uniform partitions are np.linspace(0, T, K + 1), t_K = T exactly): padded with its last state, the
    last node is not the state at T; unpadded, the trajectory is too short."""
    t = vm.uniform_grid(problem.T, steps=50)
    assert math.floor(problem.T / (t[1] - t[0])) == 49 and t[-1] == problem.T
    padded = uniform_only(zoo.ball_catching_up(1.0, 2.0, floor_steps=True), inexact=(1.0, 2.0))
    rec = check_in_domain(padded, problem, grids=[t])
    assert rec.status == "failed" and rec.counterexample["k"] == 50, rec
    assert check_in_domain(uniform_only(zoo.ball_catching_up(1.0, 2.0), inexact=(1.0, 2.0)), problem,
                           grids=[t]).status == "passed"
    short = uniform_only(lambda p, tg: zoo.ball_catching_up(1.0, 2.0, floor_steps=True)(p, tg)[:-1],
                         inexact=(1.0, 2.0))
    rec = check_selections(short, problem, grids=[t])
    assert rec.status == "failed" and "returned shape" in rec.message, rec


def test_unique_limit_of_a_uniform_only_stepper_is_judged_on_uniform_refinements(problem):
    s = uniform_only(zoo.ball_catching_up(1.0, 2.0), inexact=(1.0, 2.0))
    rec = check_unique_limit(s, problem)
    assert rec.status == "passed", rec
    assert set(rec.details["ratios"]) == {"uniform"} and rec.details["grids"]["claimed"] == "uniform"
    # an offset 0.3 (-2)^m on the m-th 4-fold refinement of K = 10 cells: differences that grow, no limit
    wobbly = uniform_only(lambda p, tg: zoo.ball_catching_up()(p, tg)
                          + 0.3 * (-2.0) ** round(math.log((len(tg) - 1) / 10, 4)), inexact=(1, 2))
    rec = check_unique_limit(wobbly, problem)
    assert rec.status == "failed" and "no limit" in rec.message, rec


def test_grids_claim_keeps_the_existing_api():
    assert claim_of(zoo.wrong_time).grids == "any" and not claim_of(zoo.wrong_time).uniform
    s = Stepper(zoo.wrong_time, scheme="any", order=1, grids="uniform")
    assert s.claim.uniform and "grids='uniform'" in repr(s)
    assert with_claim(s, order=2).claim.uniform            # what is not given is kept
    with pytest.raises(InvalidClaim, match="grids"):
        Stepper(zoo.wrong_time, grids="nonuniform")


# -- item 3: inexact resolvents ------------------------------------------------------------------------------

def test_a_scheme_violating_its_stated_tolerance_fails(problem):
    """Projections to tolerance h while claiming h²: the resolvent distance exceeds ε(h); the same stepper
    claiming what it does (h) passes selections."""
    loose = zoo.ball_catching_up(1.0, 1.0)
    rec = check_selections(uniform_only(loose, inexact=(1.0, 2.0)), problem)
    assert rec.status == "failed" and "exceeds the stated resolvent tolerance" in rec.message, rec
    assert check_selections(uniform_only(loose, inexact=(1.0, 1.0)), problem).status == "passed"


def test_the_exact_laws_need_the_stated_tolerance(problem):
    """Claimed exact, the h² projections fail selections; claimed inexact they pass.  (in_domain holds either
    way: the dual iterates overshoot into the ball.)"""
    s = zoo.ball_catching_up(1.0, 2.0)
    assert check_selections(uniform_only(s), problem).status == "failed"
    rec = check_selections(uniform_only(s, inexact=(1.0, 2.0)), problem)
    assert rec.status == "passed" and rec.details["inexact"]["max_ratio"] <= 1.0 < 4 * rec.details["inexact"]["max_ratio"]


def test_a_tolerance_of_order_at_most_one_makes_convergence_impossible(problem):
    """ε = 10 h^0.5: K = T/h steps accumulate 10 T h^-0.5 — no convergence follows from the claim, and the
    stepper projecting to it does not converge: convergence_order fails, naming the claim."""
    s = uniform_only(zoo.ball_catching_up(10.0, 0.5), inexact=(10.0, 0.5))
    rep = vm.check_stepper(s, problems=[problem], laws=False)
    (rec,) = list(rep)
    assert rec.status == "failed" and "q = 0.5" in rec.message, rec
    assert check_selections(s, problem).status == "passed"       # its results are within what it states


def test_the_expected_order_follows_from_the_tolerance(problem):
    base = Stepper(zoo.ball_catching_up(), grids="uniform")
    assert expected_order(base, problem).value == 1.0
    assert expected_order(Stepper(base, inexact=(1.0, 1.5)), problem).value == pytest.approx(0.5)
    assert expected_order(Stepper(base, inexact=(1.0, 3.0)), problem).value == 1.0
    assert "h^(q-1)" in expected_order(Stepper(base, inexact=(1.0, 1.5)), problem).source
    eps = Inexact(fn=lambda h: 0.5 * h ** 2.5)
    assert eps.exponent(2 * np.pi) == pytest.approx(2.5) and eps(0.1) == pytest.approx(0.5 * 0.1 ** 2.5)


@pytest.mark.parametrize("kw", [dict(inexact=(0.0, 2.0)), dict(inexact=(1.0, -1.0)), dict(inexact="tight"),
                                dict(inexact=(1.0, 2.0), scheme="any")])
def test_inexact_claims_that_cannot_be_stated_are_typed_errors(kw):
    with pytest.raises(InvalidClaim):
        Stepper(zoo.wrong_time, **kw)


def test_the_command_line_states_both_claims(tmp_path, monkeypatch):
    """``verimono check --grids uniform --inexact C:Q`` makes the same claim as the Python API."""
    from verimono.cli import build_parser

    args = build_parser().parse_args(["check", "m:s", "--grids", "uniform", "--inexact", "1:2"])
    assert (args.grids, args.inexact) == ("uniform", (1.0, 2.0))
    claim = with_claim(zoo.wrong_time, grids=args.grids, inexact=args.inexact).claim
    assert claim.uniform and claim.inexact == Inexact(1.0, 2.0)
    with pytest.raises(SystemExit):
        build_parser().parse_args(["check", "m:s", "--inexact", "0:2"])
