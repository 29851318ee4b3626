"""The operator's own scale in the stepper and problem laws (verimono.core.tolerances, "the operator's own scale";
verimono.checks.core.run; verimono.checks.engine.data_scale).

A sweeping process in a ball of radius R centred at (R − 1 + t)·e_1 — the boundary x_1 = t − 1 sweeps the state from
the origin at t = 1 — is computed by a correct projection that rounds at |c| + R ≈ 2R whatever the state.  Judged at
the states' magnitude alone (measured on 2c160ea, profile ci, seeds 0–2): float32 at R = 10^6 failed ``unique_limit``
(the refinements' differences stay at the rounding, 0.047) for ``solve`` and a textbook loop, and (A1) by 2·10^6 to
1.5·10^7 times its slack, (A3) 80 times; float64 at R = 10^12 failed (A1), (A2), (A3) by 10^4 to 10^6 times.  Now: the
problem laws judge at the stated ``data_scale`` (passed), or are undecided within the rounding of the scale inferred
from the domain; a planted step error beyond ``rtol·S`` still fails, one within it is undecided, never passed."""

import numpy as np
import pytest

import verimono as vm
from verimono.checks.assumptions import check_assumption_A1
from verimono.checks.partitions import run_stepper
from verimono.checks.shared_runs import shared_runs
from verimono.core.tolerances import judged_precision

N = 3


def sweeping_ball(dtype, R, stated=None):
    """The normal cone of the ball B((R − 1 + t)·e_1, R), computed in ``dtype``; x0 = 0 (on the boundary at t = 1)."""
    def J(x, lam, t):
        x = np.asarray(x, dtype=dtype)
        c = np.zeros(N, dtype=dtype)
        c[0] = dtype(R - 1 + t)
        d = x - c
        nd = np.linalg.norm(d)
        return (c + d * min(dtype(1), dtype(R) / nd)) if nd > 0 else x

    op = vm.operator_from_resolvent(J, N, project_domain=lambda x, t: J(x, 1.0, t), data_scale=stated,
                                    name=f"ball {np.dtype(dtype).name} R={R:g}")
    return vm.Problem(op, x0=np.zeros(N), T=2.0, name=f"sweeping ball {np.dtype(dtype).name} R={R:g}")


def textbook(problem, t_grid):              # README.md's my_stepper: x_{k+1} = J_{hF(t_{k+1})}(x_k)
    x = [problem.x0]
    for k in range(1, len(t_grid)):
        x.append(problem.operator.resolvent(x[-1], t_grid[k] - t_grid[k - 1], t_grid[k]))
    return np.array(x)


def off_by(delta):
    """The textbook loop with every state moved by ``delta`` outward through the sweeping boundary x_1 = t − 1:
    outside the domain by ``delta`` once the boundary pushes the state (t ≥ 1)."""
    def stepper(problem, t_grid):
        x = textbook(problem, t_grid)
        x[1:, 0] -= delta
        return x
    stepper.__name__ = f"off_by_{delta:g}"
    return stepper


def by_status(report):
    out = {}
    for r in report:
        out.setdefault(r.status, []).append(r)
    return out


@pytest.mark.heavy       # a ci stepper battery each (1-2 s)
@pytest.mark.parametrize("stepper", [vm.solve, textbook], ids=["solve", "textbook"])
def test_a_correct_stepper_at_its_operators_scale_is_never_failed(stepper):
    rep = by_status(vm.check_stepper(stepper, problems=[sweeping_ball(np.float32, 1e6)], profile="ci", seed=0))
    assert "failed" not in rep, {r.check: r.message for r in rep["failed"]}
    undecided = {r.check: r for r in rep.get("undecided", [])}
    assert "unique_limit" in undecided, "the points' scale alone fails this correct code: the fallback must be exercised"
    r = undecided["unique_limit"]
    assert r.details["data_scale"]["inferred"] == pytest.approx(2e6, rel=1e-5)
    assert r.details["data_scale"]["there"] == "passed" and r.details["dtype"] == "float32"
    assert "data_scale" in r.message and r.counterexample


@pytest.mark.heavy       # a ci stepper battery (1 s)
def test_a_stated_scale_decides_the_stepper_laws():
    rep = vm.check_stepper(textbook, problems=[sweeping_ball(np.float32, 1e6, stated=2e6)], profile="ci", seed=0)
    assert {r.status for r in rep} <= {"passed", "skipped"}
    passed = [r for r in rep if r.status == "passed"]
    assert passed and all(r.details["data_scale"] == {"stated": 2e6} for r in passed)


@pytest.mark.heavy       # the assumption laws twice (1-2 s)
def test_the_assumption_laws_at_the_operators_scale():
    rep = by_status(vm.check_assumptions(sweeping_ball(np.float64, 1e12), seed=0))
    assert "failed" not in rep, {r.check: r.message for r in rep["failed"]}
    laws = {r.check for r in rep["undecided"]}
    assert {"assumption_A1", "assumption_A3", "assumptions_thm_main"} <= laws
    for r in rep["undecided"]:
        if r.check != "assumptions_thm_main":         # the composite is undecided because they are
            assert r.details["data_scale"]["inferred"] == pytest.approx(2e12, rel=1e-9)
    stated = vm.check_assumptions(sweeping_ball(np.float64, 1e12, stated=2e12), seed=0)
    assert {r.status for r in stated} == {"passed"}
    assert all(r.details["data_scale"] == {"stated": 2e12} for r in stated if r.check != "assumptions_thm_main")


@pytest.mark.heavy       # three stepper laws, four times (2 s)
def test_a_step_error_beyond_the_scale_still_fails_and_one_within_is_never_passed():
    # float64, R = 10^6: the domain's extent 2·10^6, rtol·(1 + 2·10^6) = 0.02.  A state 1 outside the ball
    # fails in_domain at the inferred scale too (and when the scale is stated); 10^-3 outside is undecided
    laws = ["in_domain"]
    big = vm.check_stepper(off_by(1.0), problems=[sweeping_ball(np.float64, 1e6)], laws=laws, orders=False,
                           profile="ci", seed=0)
    (r,) = big.results
    assert r.status == "failed" and r.details["data_scale"]["fails_there_too"]
    stated = vm.check_stepper(off_by(1.0), problems=[sweeping_ball(np.float64, 1e6, stated=2e6)], laws=laws,
                              orders=False, profile="ci", seed=0)
    assert [r.status for r in stated] == ["failed"]
    small = vm.check_stepper(off_by(1e-3), problems=[sweeping_ball(np.float64, 1e6)], laws=laws, orders=False,
                             profile="ci", seed=0)
    assert [r.status for r in small] == ["undecided"]
    # the same 10^-3 on the unit-scale ball (R = 1: extent 2, rtol·3) fails
    unit = vm.check_stepper(off_by(1e-3), problems=[sweeping_ball(np.float64, 1.0)], laws=laws, orders=False,
                            profile="ci", seed=0)
    assert [r.status for r in unit] == ["failed"]


def box32():
    J = lambda x, lam, t: np.clip(np.asarray(x, dtype=np.float32), np.float32(-1e9), np.float32(1e9))  # noqa: E731
    op = vm.operator_from_resolvent(J, N, project_domain=lambda x, t: J(x, 1.0, t), name="box float32")
    return vm.Problem(op, x0=np.full(N, 0.3), T=2.0, f=lambda x: -x, lipschitz=1.0, name="box float32")


@pytest.mark.heavy       # (A1) twice (0.75 s)
def test_a1_judges_a_float32_operator_at_float32_precision():
    # (A1) was judged at float64's RTOL whatever the subject's precision: an exact float32 clip failed by 7–10 times
    rec = check_assumption_A1(box32(), seed=0)
    assert rec.status == "passed" and rec.details["dtype"] == "float32"
    # F = −I (J_λ x = x/(1 − λ)) is not monotone: its pairs violate (A1) at unit size, far beyond float32's slack
    J = lambda x, lam, t: (np.asarray(x, dtype=np.float32) / np.float32(1.0 - lam))  # noqa: E731
    bad = vm.Problem(vm.operator_from_resolvent(J, N, name="minus identity float32"), x0=np.zeros(N), T=0.5,
                     name="minus identity float32")
    rec = check_assumption_A1(bad, seed=0)
    assert rec.status == "failed" and rec.worst > 100


def test_a_kept_run_keeps_the_precision_the_operator_computed_in():
    # a stepper returning float64 states of a float32 operator computes in float32: a law reading its kept run later
    # (without calling the operator) is judged at float32, as the law that ran it
    p = sweeping_ball(np.float32, 1.0)
    grid = np.linspace(0.0, 2.0, 11)
    with shared_runs():
        with judged_precision() as first:
            x1 = run_stepper(textbook, p, grid)
        with judged_precision() as again:
            x2 = run_stepper(textbook, p, grid)
    assert x1 is x2 and x1.dtype == np.float64
    assert first.name == again.name == "float32"


@pytest.mark.parametrize("stated", [None, 2e6])
def test_an_initial_point_within_the_rounding_of_the_stated_scale_is_in_the_domain(stated):
    # x0 = 10^-3·e_1 lies 10^-3 inside the float32 ball B(10^6·e_1, 10^6), whose projection moves it by its rounding at
    # 10^6 (to the origin): refused at x0's own scale (the message says how to decide), accepted at the stated one
    def J(x, lam, t):
        x = np.asarray(x, dtype=np.float32)
        c = np.array([1e6, 0.0, 0.0], dtype=np.float32)
        d = x - c
        return c + d * min(np.float32(1), np.float32(1e6) / np.linalg.norm(d))

    op = vm.operator_from_resolvent(J, N, project_domain=lambda x, t: J(x, 1.0, t), data_scale=stated)
    x0 = np.array([1e-3, 0.0, 0.0])
    if stated is None:
        with pytest.raises(vm.OutsideDomain, match="data_scale"):
            vm.Problem(op, x0=x0, T=1.0)
    else:
        assert vm.Problem(op, x0=x0, T=1.0).x0[0] == 1e-3
    # a point 10^3 outside is refused at the stated scale 10^6 too: float32 rtol·(1 + 10^6) = 230 < 10^3
    op = vm.operator_from_resolvent(J, N, project_domain=lambda x, t: J(x, 1.0, t), data_scale=1e6)
    with pytest.raises(vm.OutsideDomain):
        vm.Problem(op, x0=np.array([-1e3, 0.0, 0.0]), T=1.0)
