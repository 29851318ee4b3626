"""A convergence study fits the scheme (issue 35): it chooses its grids from the claimed order and the floor, honours
claims, and says undecided — never failed — when no asymptotic range lies above the floor within its budget.

The subjects are classical integrators, one step per cell (tests/zoo_classical.py): SciPy's RK45 (order 5) and
DOP853 (order 8), Butcher's order-5 scheme written from its tableau, and explicit Euler (order 1) — each claimed at
its order on the smooth references and a smooth manufactured problem.  Before, a correct order-5 or order-8
scheme was failed there ("too few points above round-off to estimate an order": its errors were round-off on the
grids sized for the proximal scheme), and an order-1 scheme claimed as order 5 passed on a smooth manufactured
problem (regularity 1 stated) and in any ``convergence_study`` (the claim ignored)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

import verimono as vm
import zoo_classical as zi
from verimono.checks import check_convergence_order
from verimono.core.convergence import convergence_study
from verimono.core.grid_design import MIN_GRIDS, ladder, ladder_ratio
from verimono.reference import catalog, get

SMOOTH = ["linear x' = -Mx", "Lipschitz field and input", "Example ex, v = (−t, 0)", "static ball, x0 inside"]
def _problem(name, request):
    return request.getfixturevalue("manufactured") if name == "manufactured" else get(name)


def test_the_smooth_references_are_the_catalogs_smooth_problems():
    smooth = {p.name for p in catalog() if p.order.regularity == math.inf and not p.initial_jump}
    assert smooth == set(SMOOTH)


SCHEMES = {"RK45": (zi.rk45, 5), "DOP853": (zi.dop853, 8), "butcher5": (zi.butcher5, 5)}
#: DOP853 on the manufactured problem (2 s: its input by finite differences at every stage) is in the slow tier
CASES = [pytest.param(k, name, marks=[pytest.mark.slow] if (k, name) == ("DOP853", "manufactured") else [],
                      id=f"{k}-{name}") for k in SCHEMES for name in SMOOTH + ["manufactured"]]


@pytest.mark.parametrize("scheme, name", CASES)
def test_high_order_schemes_pass_at_their_orders(scheme, name, request):
    """Each reaches its order on at least four grids above the floor (the study coarsened for it), or is exact to
    round-off where the solution is a polynomial of low degree (Example ex: x0 + t²/2; the static ball)."""
    fn, order = SCHEMES[scheme]
    p = _problem(name, request)
    rec = check_convergence_order(vm.Stepper(fn, scheme="any", order=order), p)
    assert rec.status == "passed", rec.message
    study = rec.details["study"]
    assert study.expected.value == order and study.claimed == order
    d = study.decision()
    if "round-off" in d.message:
        assert name in ("Example ex, v = (−t, 0)", "static ball, x0 inside")
        assert min(study.steps) <= 3           # exact down to the coarsest grid the ladder holds
        return
    assert len(d.window) >= MIN_GRIDS and all(study.errors["sup"][i] > study.grid_floors[i] for i in d.window)
    assert study.order.reaches(order) and study.order.slope < order + 1.0, str(study.order)
    finest = study.order.local_slopes[0]          # fine to coarse: the asymptotic end
    assert abs(finest - order) < 0.5, study.order.local_slopes
    assert study.added, "the study chose coarser grids than the problem's"


def _variants():
    """Smooth problems the grids were not tuned on: other matrices, starts, horizons, inputs."""
    from verimono.reference import linear

    yield linear.linear(M=[[2.0, -1.0], [1.0, 0.3]], x0=(0.3, -1.0), T=1.0)
    yield linear.linear(M=[[0.5, 4.0], [-4.0, 0.5]], x0=(2.0, 1.0), T=3.5)
    yield linear.lipschitz_input(m=2.0, a=0.3, b=-0.4, omega=5.0, x0=-0.5, T=1.7)
    yield linear.lipschitz_input(m=0.2, a=1.0, b=0.0, omega=0.5, x0=3.0, T=6.0)


@pytest.mark.parametrize("k", range(4))
def test_a_correct_order_8_scheme_is_never_failed(k):
    """DOP853 claimed at 8, in float64 and in float32 (where round-off leaves one or two grids above it): passed
    or undecided, never failed."""
    p = list(_variants())[k]
    rec = check_convergence_order(vm.Stepper(zi.dop853, scheme="any", order=8), p)
    assert rec.status == "passed", rec.message
    rec = check_convergence_order(vm.Stepper(_float32(zi.dop853), scheme="any", order=8), p)
    assert rec.status in ("passed", "undecided"), rec.message


def _float32(fn):
    def step(problem, t):
        return fn(problem, t).astype(np.float32)
    step.__name__ = f"{fn.__name__} in float32"
    return step


MEASURED = re.compile(r"order (\d+\.\d\d) measured, 5 claimed")


@pytest.mark.parametrize("name", ["linear x' = -Mx", "Lipschitz field and input", "Example ex, v = (−t, 0)",
                                  "manufactured"])
def test_an_order_1_scheme_claimed_as_order_5_fails_naming_its_order(name, request):
    """Explicit Euler claimed as order 5: failed, "order 1.0x measured, 5 claimed" — not "a stall", not a pass
    (on the smooth manufactured problem it passed: its regularity was stated as 1, capping the claim)."""
    p = _problem(name, request)
    rec = check_convergence_order(vm.Stepper(zi.euler, scheme="any", order=5), p)
    assert rec.status == "failed", rec.message
    m = MEASURED.search(rec.message)
    assert m and 0.9 <= float(m.group(1)) < 2.0, rec.message
    assert "stall" not in rec.message.split("measured")[0]
    assert rec.worst > 1.0


def test_a_study_honours_the_claim():
    """``convergence_study`` of a claimed stepper judges the claimed order (it judged the problem's before: the
    proximal scheme claimed as order 5 "reached the expected order" 1)."""
    p = get("linear x' = -Mx")
    s = convergence_study(vm.Stepper(vm.solve, scheme="any", order=5), p)
    assert s.expected.value == 5 and s.claimed == 5
    assert s.decision().status == "failed" and MEASURED.search(s.decision().message)
    assert convergence_study(vm.solve, p).decision().ok          # unclaimed: the reference's order 1


def test_the_ladder_is_spaced_for_the_order():
    assert ladder_ratio(1) == ladder_ratio(3) == 2.0 and ladder_ratio(8) == pytest.approx(8 ** 0.125)
    for p in (1.0, 5.0, 8.0):
        counts = ladder(2, 200, ladder_ratio(p))
        assert counts[0] <= 3 and counts[-1] == 200
        assert all(b / a >= ladder_ratio(p) * (1 - 1e-12) for a, b in zip(counts[:-1], counts[1:]))
        assert all(set(_factors(k)) <= {2, 3} for k in counts[:-1])      # 3-smooth below the given grid


def _factors(k):
    out, d = [], 2
    while k > 1:
        while k % d == 0:
            out.append(d)
            k //= d
        d += 1
    return out


# -- a step range, for users who know better -----------------------------------------------------------------------

def test_a_step_range_confines_the_study():
    p = get("linear x' = -Mx")
    dop = vm.Stepper(zi.dop853, scheme="any", order=8)
    s = convergence_study(dop, p, step_range=(p.T / 16, p.T / 3))
    assert all(p.T / 16 * (1 - 1e-12) <= h <= p.T / 3 * (1 + 1e-12) for h in s.mesh)
    assert len(s.steps) >= MIN_GRIDS and s.added == [] and s.refined == 0
    assert s.decision().ok, s.decision().message
    rec = check_convergence_order(dop, p, step_range=(p.T / 16, p.T / 3))
    assert rec.status == "passed" and rec.details["study"].steps == s.steps
    # a range where every error is round-off: nothing outside it is tried, and the verdict says so
    exact = convergence_study(dop, p, step_range=(p.T / 240, p.T / 100))
    assert min(exact.steps) >= 100 and "round-off" in exact.decision().message
    with pytest.raises(vm.InvalidProblem):
        convergence_study(dop, p, step_range=(p.T / 10, p.T / 10.5))


def test_check_stepper_takes_a_step_range():
    p = get("Lipschitz field and input")
    rep = vm.check_stepper(zi.dop853, problems=[p], scheme="any", order=8, laws=False,
                           step_range=(p.T / 30, p.T / 3))
    (rec,) = rep.results
    assert rec.status == "passed" and max(rec.details["study"].steps) <= 30


# -- what the study cannot decide ---------------------------------------------------------------------------------

def test_a_stepper_refusing_coarse_steps_is_judged_on_the_rest():
    """The coarse grids the study added itself, where a stepper refuses a step (or diverges), are left out with
    what it raised, never held against it; the grids the study was given still count."""
    def refuses(problem, t):
        if len(t) - 1 < 20:
            raise ValueError("steps larger than T/20 are refused")
        return zi.rk45(problem, t)

    p = get("linear x' = -Mx")
    rec = check_convergence_order(vm.Stepper(refuses, scheme="any", order=5), p)
    assert rec.status == "passed", rec.message
    assert "left out" in rec.message and "refused" in rec.message
    study = rec.details["study"]
    assert any(not math.isfinite(study.errors["sup"][i]) for i in study.added)
    # on a grid it was given, the same refusal is the stepper's failure
    with pytest.raises(ValueError):
        convergence_study(vm.Stepper(refuses, scheme="any", order=5), p, [p.T / 10, p.T / 40])


def test_no_asymptotic_range_above_the_floor_is_undecided_with_what_was_tried():
    """DOP853 in float32 within a range where only two grids lie above float32's round-off: undecided, listing the
    grids tried — a limit of the study, not a failure of the scheme."""
    p = get("linear x' = -Mx")
    s = convergence_study(vm.Stepper(_float32(zi.dop853), scheme="any", order=8), p, step_range=(p.T / 8, p.T / 2))
    d = s.decision()
    assert d.status == "undecided", d.message
    assert "too few points above round-off" in d.message and "K=2:" in d.message and "K=8:" in d.message
