"""Steppers that choose their own steps: the protocol (verimono.Adaptive), the tolerance study, the laws on the
stepper's own partition, and the switching times of an event-driven scheme — each law seen failing on a
planted bug beside a lawful control."""

from __future__ import annotations

import math

import numpy as np
import pytest

import verimono as vm
import zoo_integrators as zoo
from verimono.checks.orders import check_convergence_order
from verimono.checks.own_steps import check_switching_times, check_tolerance_rate, own_partition_laws
from verimono.core.adaptive import own_run, tolerance_study
from verimono.reference import lcs_example, linear, subdifferential
from verimono.reference.events import switching_times


def synthetic(rate, order, dim=1, C=0.3):
    """An adaptive stepper whose error at every node is exactly ``C tol^rate`` and whose step count is
    ``N = ceil(4 tol^(-rate/order))``: the study must recover both exponents."""
    def fn(problem, T, tol):
        N = int(math.ceil(4 * tol ** (-rate / order)))
        t = np.linspace(0.0, T, N + 1)
        x = np.array([problem.exact(s) for s in t]) + C * tol ** rate / math.sqrt(dim)
        return t, x
    return fn


@pytest.mark.parametrize("rate, order, dim", [(1.0, 2.0, 1), (0.5, 1.0, 3), (5 / 6, 5.0, 3)])
def test_study_recovers_the_rate_and_the_order(rate, order, dim):
    p = subdifferential.t_norm(tuple(np.linspace(0.4, 1.0, dim)))
    tols = [10.0 ** -k for k in (2, 2.5, 3, 3.5, 4)]
    s = tolerance_study(vm.Adaptive(synthetic(rate, order, dim), rate=rate, order=order, name="synthetic"), p, tols)
    assert s.fits["sup"].contains(rate, 0.02) and s.step_fits["sup"].contains(order, 0.15)
    assert s.verdict()[0]
    over = tolerance_study(vm.Adaptive(synthetic(rate, order, dim), rate=rate + 0.5, name="claims more"), p, tols)
    ok, msg = over.verdict()
    assert not ok and f"claimed {rate + 0.5:g}" in msg


def test_bad_returns_are_typed_errors():
    p = subdifferential.t_norm()
    cases = [(lambda pr, T, tol: (np.array([0.0, 1.0, 0.5, T]), np.zeros((4, 1))), vm.InvalidGrid),
             (lambda pr, T, tol: (np.array([0.0, 1.0]), np.zeros((2, 1))), vm.InvalidGrid),          # ends before T
             (lambda pr, T, tol: (np.array([0.0, T]), np.zeros((3, 1))), vm.InvalidProblem),
             (lambda pr, T, tol: np.zeros((3, 1)), vm.InvalidProblem)]
    for fn, err in cases:
        with pytest.raises(err):
            own_run(vm.Adaptive(fn), p, 1e-3)
    for kw in ({"rate": 0}, {"rate": float("nan")}, {"order": -1}, {"control": "dt"}, {"tolerances": [1e-3]}):
        with pytest.raises(vm.InvalidClaim):
            vm.Adaptive(lambda pr, T, tol: None, **kw)


@pytest.mark.parametrize("problem", [linear.lipschitz_input(),
                                     linear.lipschitz_input(m=2.0, a=0.3, omega=3.0, x0=-0.5, T=2.0)],
                         ids=["default", "other-data"])
def test_planted_wrapper_bugs_fail_beside_their_lawful_controls(problem):
    steps = [problem.T / k for k in (20, 40, 80, 160, 320)]
    order = check_convergence_order.law.check
    assert order(zoo.heun, problem, steps=steps).status == "passed"
    for broken in (zoo.heun_stage_half, zoo.heun_input_time):
        rec = order(broken, problem, steps=steps)
        assert rec.status == "failed" and "measured, 2 claimed" in rec.message, rec
    assert check_tolerance_rate(zoo.heun_pid, problem).status == "passed"
    ignores = check_tolerance_rate(zoo.heun_pid_ignores, problem)
    assert ignores.status == "failed" and "does not respond to the tolerance" in ignores.message
    shifted = check_tolerance_rate(zoo.heun_pid_input_shift, problem)
    assert shifted.status == "failed" and "stall" in shifted.message


def test_solve_adaptive_obeys_the_local_laws_on_its_own_partition():
    p = subdifferential.t_norm((0.6, -0.8))
    rate = check_tolerance_rate(vm.solve_adaptive, p)
    assert rate.status == "passed", rate
    recs = own_partition_laws(vm.solve_adaptive, p, controls=[1e-2, 1e-3])
    assert {r.check: r.status for r in recs} == dict.fromkeys(
        ("in_domain", "selections", "bounds_lg", "bounds_yb", "psi_interpolation"), "passed")
    assert all("(own steps)" in r.subject for r in recs)


def explicit_adaptive(problem, T, tol):
    """A broken 'proximal' scheme: the controller of solve_adaptive's partition, but an explicit step
    x_{k+1} = x_k - h F⁰(t_k, x_k) (not the resolvent)."""
    traj = vm.solve_adaptive.fn(problem, T, tol)
    t = traj.t
    x = [np.array(problem.x0, dtype=float)]
    for k in range(len(t) - 1):
        x.append(x[-1] - (t[k + 1] - t[k]) * problem.operator.min_norm(x[-1], t[k]))
    return t, np.array(x)


def test_an_explicit_step_fails_selections_on_its_own_partition():
    p = subdifferential.t_norm((0.6, -0.8))
    broken = vm.Adaptive(explicit_adaptive, scheme="proximal", order=1, name="explicit")
    recs = {r.check: r for r in own_partition_laws(broken, p, controls=[1e-2, 1e-3], laws=["selections"])}
    assert recs["selections"].status == "failed"
    any_claim = own_partition_laws(vm.Adaptive(explicit_adaptive, name="explicit any"), p, controls=[1e-2, 1e-3])
    assert {r.status for r in any_claim} == {"skipped"}


@pytest.mark.parametrize("x0, T", [(0.0, 3 * np.pi), (0.7, 7.0)])
def test_event_driven_locates_the_switching_times(x0, T):
    from verimono.lcs.event_driven import event_driven

    p = lcs_example.sine_problem(x0=x0, T=T)
    times = switching_times(p)
    assert times == [k * np.pi for k in range(1, 3)]
    tols = [1e-4, 1e-6, 1e-8]
    good = check_switching_times(event_driven(), p, times=times, controls=tols)
    assert good.status == "passed" and good.worst < 1e-2, good
    assert check_tolerance_rate(event_driven(), p, controls=tols).status == "passed"
    bad = check_switching_times(event_driven(locate=False), p, times=times, controls=tols)
    assert bad.status == "failed" and bad.worst > 100, bad
    assert check_tolerance_rate(event_driven(locate=False), p, controls=tols).status == "failed"


def test_no_events_reported_is_a_skip_not_a_pass():
    p = subdifferential.t_norm()
    rec = check_switching_times(vm.solve_adaptive, p, times=switching_times(p), controls=[1e-2, 1e-3])
    assert rec.status == "skipped" and "reports no located events" in rec.message


@pytest.mark.parametrize("name", ["play operator, piecewise-linear u", "x' = c/x from 0 (order 1/2)"])
def test_solve_adaptive_converges_where_its_estimate_is_blind_or_its_rule_unattainable(name):
    """Two references failed solve_adaptive before its step cap and per-step rule: a piecewise-linear input
    between breakpoints, where one step and two half steps agree while both are wrong (18 steps at every
    tolerance, error 0.364), and x = √(2ct) from 0, where an error-per-unit-step rule asks h ≤ tol t^{3/2} (more
    than 200 000 steps at tol = 0.01)."""
    from verimono.reference import get

    rec = check_tolerance_rate(vm.solve_adaptive, get(name))
    assert rec.status == "passed", rec


def test_too_few_errors_above_round_off_is_undecided_not_failed():
    """solve_adaptive on moving box is second-order accurate: its errors fall below round-off after two
    tolerances, so no rate can be fitted — that refutes nothing (it was failed, worst = inf)."""
    from verimono.reference import get

    rec = check_tolerance_rate(vm.solve_adaptive, get("moving box"))
    assert rec.status == "undecided" and "too few errors above the round-off floor" in rec.message, rec
    assert "looser tolerances" in rec.message


def test_check_stepper_gives_an_adaptive_stepper_its_own_battery():
    """A verimono.Adaptive takes a tolerance, not a grid: check_stepper called it with a grid (failed,
    TypeError: missing 'tol'); it now runs check_adaptive."""
    p = subdifferential.t_norm((0.6, -0.8))
    report = vm.check_stepper(vm.solve_adaptive, [p])
    checks = {r.check: r.status for r in report.results}
    assert checks["tolerance_rate"] == "passed" and checks["selections"] == "passed", checks
    assert "convergence_order" not in checks


@pytest.mark.slow
def test_verimono_check_of_an_adaptive_stepper_runs_the_adaptive_stage(tmp_path):
    import json
    import subprocess
    import sys
    from pathlib import Path

    (tmp_path / "myadaptive.py").write_text("import verimono as vm\nadaptive = vm.solve_adaptive\n")
    out = subprocess.run([sys.executable, "-m", "verimono.cli", "check", "myadaptive:adaptive", "--reference",
                          "t|x| (n=1)", "--reference", "linear x' = -Mx", "--out", str(tmp_path / "out")],
                         cwd=tmp_path, capture_output=True, text=True, timeout=600,
                         env={**__import__("os").environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])})
    assert out.returncode == 0, out.stderr
    assert "as an adaptive stepper" in out.stderr
    data = json.loads((tmp_path / "out" / "results.json").read_text())
    statuses = {(r["check"], r["subject"]): r["status"] for r in data["results"]}
    assert ("tolerance_rate", "solve_adaptive on linear x' = -Mx") in statuses, sorted(statuses)
    assert set(statuses.values()) <= {"passed", "skipped"}, statuses
    assert [s["name"] for s in data["meta"]["stages"]] == ["adaptive"]
