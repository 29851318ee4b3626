"""Issue 42 items 1–2: time searched by count (:mod:`verimono.checks.engine.times`) and (A3)'s domain motion
searched over the boundary points exposed in every direction (:mod:`verimono.checks.engine.sphere`).

Every subject here passed the code before (seen in the commit that added this file, at ``ci``'s budget): a
monotonicity lost on a window of ``T/600`` or ``T/2000`` between the old coverage grid's points, a violation
periodic with that grid's spacing, a domain motion periodic with the old ``T/16`` windows, a stated φ too
small by 2–6% for a ball translating in ``R^5``, ``R^10``, ``R^20`` (the sample points meet the worst
boundary point at an angle, ratio 0.911 in ``R^10``) and a half-space moving far from ``x0``.  Each stands
beside a lawful control within 1–2% that passes.  ``ci``'s budget (``budgets(time=512)``: 3072 strata)
resolves ``t`` to ``T/2048``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import verimono as vm
from verimono import Problem, operator_from_resolvent
from verimono.checks.assumption_bounds import check_assumption_A3
from verimono.checks.assumptions import check_assumption_A1
from verimono.checks.engine.supremum import budget, budgets
from verimono.checks.engine.times import promised_resolution, strata, time_design
from verimono.records.results import FAILED, PASSED

CI = budget("time", "ci")
#: the (A3) subjects violate φ on every window (or on a quarter of every period): a short design finds one,
#: and the sphere's search at it is what they test (96 strata)
FEW = 16


def gain(c, dim=3, **stated):
    """``F(t, x) = c(t) x`` through its resolvent and minimal section (one call per row)."""
    op = operator_from_resolvent(lambda x, lam, t: x / (1.0 + lam * c(t)), dim, min_norm=lambda x, t: c(t) * x,
                                 name="gain")
    return Problem(op, np.ones(dim), 1.0, **stated)


def dip(windows, width, depth):
    """``c = 1`` except on each window ``(τ, τ + width)``, where it falls continuously to ``depth`` on the
    middle ~90% (``depth < 0``: ``F(t) = c(t) x`` not monotone there)."""
    def c(t):
        for tau in windows:
            if tau < t < tau + width:
                h = min(1.0, 8.0 * math.sin(math.pi * (t - tau) / width))
                return 1.0 - (1.0 - depth) * h
        return 1.0
    return c


def test_the_time_design_is_stratified_has_both_ends_and_resolves_T_over_2000_at_ci():
    with budgets(time=CI):
        n = strata()
    ts = time_design(0.0, 1.0, n, seed=3)
    assert ts[0] == 0.0 and ts[-1] == 1.0 and np.all(np.diff(ts) > 0)
    gaps = np.diff(ts)
    assert gaps.max() <= promised_resolution(n) <= 1 / 2000
    assert np.unique(np.round(gaps, 12)).size > n // 2            # not equally spaced: no aliasing
    assert np.array_equal(ts, time_design(0.0, 1.0, n, seed=3))   # the same points on every machine
    assert strata("dev") < strata("ci") and strata("thorough") >= 10 * strata("ci")


#: between two points of the old ci coverage grid ((i + 0.5)/377, i = 120, 300, 15, 250)
BETWEEN = [(120.5 / 377 + 2e-4, 1 / 600), (300.5 / 377 + 5e-4, 1 / 600), (15.5 / 377 + 1e-3, 1 / 2000),
           (250.5 / 377 + 3e-4, 1 / 2000)]


@pytest.mark.slow
@pytest.mark.parametrize("tau,width", BETWEEN)
def test_monotonicity_lost_on_a_narrow_window_fails_A1_and_a_monotone_control_passes(tau, width):
    with budgets(time=CI):
        bad = check_assumption_A1(gain(dip([tau], width, -0.01)), seed=0)
        good = check_assumption_A1(gain(dip([tau], width, 0.01)), seed=0)
    assert bad.status == FAILED and tau < bad.counterexample["t"] < tau + width, str(bad)
    assert good.status == PASSED, str(good)
    t = good.details["searched"]["t"]
    assert t["resolution"] <= t["promised_resolution"] <= 1 / 2000 and t["strata"] == 6 * CI


def test_a_window_of_T_over_600_fails_A1_at_dev_budget():
    # dev's 1536 strata resolve T/1024: the dip of T/600 between two points of the old ci grid is seen
    tau, width = BETWEEN[1]
    with budgets(time=budget("time", "dev")):
        bad = check_assumption_A1(gain(dip([tau], width, -0.01), dim=2), seed=1)
        good = check_assumption_A1(gain(dip([tau], width, 0.01), dim=2), seed=1)
    assert bad.status == FAILED and tau < bad.counterexample["t"] < tau + width, str(bad)
    assert good.status == PASSED, str(good)
    assert good.details["searched"]["t"]["resolution"] <= 1 / 1024


@pytest.mark.slow
def test_a_violation_periodic_with_the_old_grid_spacing_fails_A1():
    # the old ci coverage: 377 points (i + 0.5)/377 (384 less the 7 sample times; the offset of seed 0 is ½);
    # a dip of width T/20000 midway between every two of them (narrower than the new resolution too: each
    # window is met with probability ~0.15), except near the centres of DIRECT's first thirds
    width = 1 / 20000
    thirds = [(2 * k + 1) / (2 * 3 ** j) for j in range(6) for k in range(3 ** j)]
    windows = [(i + 1) / 377 - width / 2 for i in range(376)]
    windows = [w for w in windows if not any(w - 2 * width < x < w + 3 * width for x in thirds)]
    with budgets(time=CI):
        bad = check_assumption_A1(gain(dip(windows, width, -0.01)), seed=0)
        good = check_assumption_A1(gain(dip(windows, width, 0.01)), seed=0)
    assert bad.status == FAILED, str(bad)
    assert good.status == PASSED, str(good)


def ball_moving(direction, speed, x0, phi_factor, period=None):
    """A unit ball whose centre moves along ``direction`` at ``speed`` (or ``0.3 sin(2π t/period)``), and the
    stated ``φ = phi_factor · (its largest speed) · t``."""
    u = np.asarray(direction, float) / np.linalg.norm(direction)
    if period is None:
        centre, top = (lambda t: speed * t * u), speed
    else:
        centre, top = (lambda t: 0.3 * math.sin(2 * math.pi * t / period) * u), 0.3 * 2 * math.pi / period
    return Problem(vm.NormalCone(vm.sets.Ball(centre, 1.0)), x0, 1.0, phi=lambda t: phi_factor * top * t)


@pytest.mark.parametrize("dim,short", [pytest.param(5, 0.98, marks=pytest.mark.slow), (10, 0.94), (20, 0.94),
                                       pytest.param(10, 0.98, marks=pytest.mark.slow)])
def test_phi_understated_on_every_window_of_a_translating_ball_fails_A3(dim, short):
    u = np.random.default_rng(dim).standard_normal(dim)
    x0 = np.zeros(dim)
    with budgets(time=FEW):
        bad = check_assumption_A3(ball_moving(u, 0.5, x0, short), seed=0)
        good = check_assumption_A3(ball_moving(u, 0.5, x0, 1.01), seed=0)
    assert bad.status == FAILED and bad.worst > 1.0 / (short + 0.005), str(bad)
    assert good.status == PASSED and good.worst > 0.98, str(good)       # the worst boundary point was met
    assert good.details["searched"]["boundary"]["sphere"] == f"S^{dim - 1}"


def test_a_motion_periodic_with_the_old_windows_fails_A3():
    # the centre returns every T/16: every window [s, s + T/16] of the old search saw no motion
    u = np.array([1.0, 2.0])
    with budgets(time=FEW):
        bad = check_assumption_A3(ball_moving(u, None, np.zeros(2), 0.98, period=1 / 16), seed=0)
        good = check_assumption_A3(ball_moving(u, None, np.zeros(2), 1.02, period=1 / 16), seed=0)
    assert bad.status == FAILED, str(bad)
    assert good.status == PASSED, str(good)


@pytest.mark.parametrize("dim", [pytest.param(3, marks=pytest.mark.slow), 12])
def test_a_half_space_receding_far_from_x0_fails_a_short_phi(dim):
    # {a·x ≤ 8 − t}: its boundary 8/|a| from x0 = 0, beyond every point sampled around x0 (at 1 and 3)
    a = np.random.default_rng(dim).standard_normal(dim)
    a /= np.linalg.norm(a)

    def problem(k):
        return Problem(vm.NormalCone(vm.sets.HalfSpace(a, lambda t: 8.0 - t)), np.zeros(dim), 1.0,
                       phi=lambda t: k * t)
    with budgets(time=FEW):
        bad = check_assumption_A3(problem(0.98), seed=0)
        good = check_assumption_A3(problem(1.01), seed=0)
    assert bad.status == FAILED, str(bad)
    assert good.status == PASSED, str(good)


@pytest.mark.slow
def test_thorough_searches_ten_times_ci_and_dev_less_in_the_records():
    problem = gain(lambda t: 1.0 + 0.5 * math.sin(7 * t), dim=1, sigma=lambda t: 1.6)
    counts = {}
    for name in ("dev", "ci", "thorough"):
        with budgets(time=budget("time", name)):
            rec = check_assumption_A1(problem, seed=0)
        assert rec.status == PASSED, str(rec)
        counts[name] = rec.details["searched"]["t"]["points"]      # times searched (the family values at the
        # law's 7 design times, 544 here, are the same at every profile)
        assert rec.details["searched"]["t"]["resolution"] <= rec.details["searched"]["t"]["promised_resolution"]
    assert counts["dev"] < counts["ci"] and counts["thorough"] >= 10 * counts["ci"], counts


def test_a_time_search_the_unit_budget_stops_is_undecided_with_the_resolution_reached():
    """A time search slow at every evaluation (1 ms), stopped by a unit budget of 0.3 s: undecided, with the times
    evaluated and the resolution reached against the promised one (``details["searched"]["t"]``).  And (A1) on a
    correct subject slow at every call (0.2 ms a resolvent) under a unit budget of 0.5 s: undecided — it was FAILED,
    the law having stated no progress to the unit, so the whole of it counted as one call that never returned."""
    import time

    from verimono.checks.engine.times import search_time
    from verimono.execution import timeouts
    from verimono.execution.timeouts import run_unit
    from verimono.records.results import UNDECIDED

    def values(t, which):
        time.sleep(1e-3)
        return np.array([-1.0])

    with timeouts.budget(0.3), budgets(time=CI):
        cut = run_unit(lambda: search_time(values, 0.0, 2.0, seed=0), check="a time search", subject="slow values")
    assert cut.status == UNDECIDED and cut.details["undecided_reason"] == "time budget", cut
    t = cut.details["searched"]["t"]
    assert 0 < t["points"] < 6 * CI and t["range"] == [0.0, 2.0], t
    assert t["resolution_reached"] > t["promised_resolution"] == promised_resolution(6 * CI) * 2.0, t

    def resolvent(x, lam, t):
        time.sleep(2e-4)
        return x / (1.0 + lam)

    op = operator_from_resolvent(resolvent, 2, min_norm=lambda x, t: x, name="slow identity")
    with timeouts.budget(0.5):
        rec = run_unit(lambda: check_assumption_A1(Problem(op, np.ones(2), 1.0), seed=0), check="assumption_A1",
                       subject="slow identity")
    assert rec.status == UNDECIDED and rec.details["undecided_reason"] == "time budget", rec
