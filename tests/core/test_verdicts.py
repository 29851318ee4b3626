"""The verdict rules of a convergence study on synthetic errors (``verimono.core.verdicts.decide``): power laws with
the shapes that matter — a pause, a stall, erratic constants, round-off, an inner solve's level — so each rule is
seen deciding both ways, independently of any stepper."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from verimono.core.problem import Order
from verimono.core.verdicts import FAILED, PASSED, UNDECIDED, StudyData, decide

FLOOR = 2.2e-12


def data(e, p=1.0, *, ratio=2.0, K0=40, refined=0, can_refine=False, can_coarsen=False, added=(), claimed=None,
         solve_tol=None, scale=1.0):
    e = np.asarray(e, float)
    K = [int(K0 * ratio ** i) for i in range(len(e))]
    return StudyData([1.0 / k for k in K], K, e.tolist(), [FLOOR] * len(e), Order(p, "test"), scale, solve_tol,
                     claimed, list(added), refined, can_coarsen, can_refine)


def power(p, n=5, C=0.3, ratio=2.0, K0=40, noise=None):
    h = np.array([1.0 / (K0 * ratio ** i) for i in range(n)])
    e = C * h ** p
    return e if noise is None else e * noise


@pytest.mark.parametrize("p", [0.5, 1.0, 2.0, 5.0])
def test_a_clean_power_law_passes_and_a_lower_one_fails_naming_both(p):
    assert decide(data(power(p), p)).status == PASSED
    low = decide(data(power(p / 2 if p > 1 else p / 3), p, claimed=p))
    assert low.status == FAILED and "measured" in low.message and f"{p:g} claimed" in low.message
    assert low.worst > 1.0


def test_the_issue_case_a_finest_slope_near_zero_never_reaches():
    """4.69e-3 -> 4.69e-3 at the finest refinement after slopes 0.95, 1.00, 0.90 (issue #32): it passed as
    pre-asymptotic.  Adaptive: refine first; fixed grids: undecided; refined and still flat: failed."""
    e = [3.4e-2, 1.75e-2, 8.75e-3, 4.69e-3, 4.69e-3]
    assert decide(data(e, can_refine=True)).action == "refine"
    fixed = decide(data(e))
    assert fixed.status == UNDECIDED and "no finer grid could be tried" in fixed.message
    persisted = decide(data(e + [4.69e-3, 4.68e-3], refined=2))
    assert persisted.status == FAILED and "stall persists" in persisted.message
    resumed = decide(data(e + [2.35e-3, 1.17e-3], refined=2))
    assert resumed.status == PASSED and "paused at 0.00469" in resumed.message


def test_a_stall_from_the_coarsest_grid_is_refined_then_failed():
    flat = [1e-3 * (1 + 0.01 * k) for k in range(5)]
    assert decide(data(flat, can_refine=True)).action == "refine"
    d = decide(data(flat + [1.05e-3, 1.06e-3], refined=2))
    assert d.status == FAILED and "stall" in d.message


def test_three_grids_with_a_stalled_finest_never_pass():
    """A 3-point fit has a wide interval that "reaches" almost anything: with its finest slope at 0 it must not."""
    d = decide(data([1e-2, 5.2e-3, 5.2e-3]))
    assert d.status != PASSED


def test_erratic_constants_are_judged_on_the_fits_interval():
    """Slopes 0.42, 0.58, 0.50, 0.22, 1.16, 0.06 (random substeps on x' = c/x, order 1/2): a finest dip after a
    resumption is noise, not a stall."""
    h = np.array([1.0 / (100 * 2 ** i) for i in range(7)])
    slopes = [0.42, 0.58, 0.50, 0.22, 1.16, 0.06]
    e = [2.6e-2]
    for s in slopes:
        e.append(e[-1] * 2.0 ** -s)
    d = decide(data(e, 0.5, K0=100, refined=2))
    assert d.status == PASSED and "erratic" in d.message
    assert np.allclose(h, 1.0 / np.array(data(e, K0=100).steps))


def test_errors_at_the_floor_down_to_the_coarsest_grid_are_exact():
    d = decide(data([1e-15] * 5, 5.0))
    assert d.status == PASSED and "exceeds every order" in d.message
    assert decide(data([1e-15] * 5, 5.0, can_coarsen=True)).action == "coarsen"


def test_too_few_grids_above_the_floor_is_undecided_with_what_was_tried():
    e = [1e-6, 1e-9, 1e-13, 1e-14, 1e-15]
    d = decide(data(e, 8.0, ratio=1.5, K0=4, added=range(5)))
    assert d.status == UNDECIDED and "K=4: 1.00e-06" in d.message


def test_an_unstated_inner_solve_floor_is_undecided_and_a_real_stall_fails():
    grows = [3.4e-9 * 2 ** k for k in range(5)]            # K·τ with τ = 1e-10: the errors grow with K
    d = decide(data(grows, claimed=1.0))
    assert d.status == UNDECIDED and "solve_tol" in d.message
    stated = decide(data(grows, claimed=1.0, solve_tol=1e-10))      # stated (its floor is not in these data)
    assert stated.status == FAILED and "State the accuracy" not in stated.message
    stall = decide(data([1e-3] * 5, claimed=1.0))
    assert stall.status == FAILED and "stall" in stall.message and "solve_tol" not in stall.message
    # the level is relative to the solution's scale: 2e-4 errors on a solution of size 1e3 are a solve's level
    # (2e-7 of it); on one of size 1e7 (2e-11 of it), flat on every grid, they are a floor: exact to it (issue 42)
    assert decide(data([2e-4] * 5, scale=1e3)).status == UNDECIDED
    assert decide(data([2e-4] * 5, scale=1e7)).status == PASSED


def test_a_non_finite_error_fails_on_a_given_grid_and_is_left_out_on_an_added_one():
    e = list(power(5.0, n=6, ratio=1.5, K0=2, C=3.0))
    e[0] = float("nan")
    assert decide(data(e, 5.0, ratio=1.5, K0=2)).status == FAILED
    kept = decide(data(e, 5.0, ratio=1.5, K0=2, added=[0]))
    assert kept.status == PASSED, kept.message


def _from_slopes(slopes, e0=1e-2, ratio=2.0):
    """Errors on grids refined by ``ratio`` whose local slopes are ``slopes``, coarse to fine."""
    e = [e0]
    for s in slopes:
        e.append(e[-1] * ratio ** -s)
    return e


def test_the_users_slopes_meet_only_the_order_they_sit_at():
    """Local slopes 3.50, 2.14, 2.03 (Heun, issue 42): the fit over them is 2.46 with an interval up to 3.46, and it
    passed a claim of 3.  The finest slopes sit at 2: claimed 3 fails, naming 2.03; claimed 2 passes."""
    e = _from_slopes([3.50, 2.14, 2.03])
    three = decide(data(e, 3.0, claimed=3.0))
    assert three.status == FAILED and "order 2.03 measured, 3 claimed" in three.message, three.message
    assert three.worst > 1.0 and three.fit.reaches(3.0)          # the fit alone would have passed it
    assert decide(data(e, 3.0, claimed=3.0, can_refine=True)).status == FAILED     # settled: nothing to refine
    two = decide(data(e, 2.0, claimed=2.0))
    assert two.status == PASSED and two.worst <= 1.0, two.message


def test_slopes_still_moving_are_refined_then_undecided():
    """Slopes 4.0, 3.4, 2.9 claimed 3: falling by half an order per refinement, nobody can say where they stop.
    The study refines; without a finer grid it is undecided.  Refined: settled at 2.95 passes, at 2.0 fails."""
    e = _from_slopes([4.0, 3.4, 2.9])
    assert decide(data(e, 3.0, claimed=3.0, can_refine=True)).action == "refine"
    fixed = decide(data(e, 3.0, claimed=3.0))
    assert fixed.status == UNDECIDED and "still move" in fixed.message, fixed.message
    assert decide(data(_from_slopes([4.0, 3.4, 2.9, 2.95]), 3.0, claimed=3.0, refined=1)).status == PASSED
    assert decide(data(_from_slopes([4.0, 3.4, 2.9, 2.1, 2.02]), 3.0, claimed=3.0, refined=2)).status == FAILED


@pytest.mark.parametrize("q", [0.5, 1.0, 2.0, 3.0, 4.0])
def test_a_claim_one_order_up_never_passes_on_pre_asymptotic_power_laws(q):
    """Errors ``0.3 h^q (1 + D (h/h_0)^m)`` on 3 to 6 grids refined by 2 or 1.5, the leading term dominant at the
    finest grid (``|D| (h_n/h_0)^m ≤ 1/2``), fixed grids: claimed ``q + 1`` never passes (43 of these 185 passed
    before), claimed ``q`` never fails."""
    seen = {True: set(), False: set()}
    for ratio, n, D, m in itertools.product([2.0, 1.5], [3, 4, 6], [-0.3, 0.3, 2.0, 20.0], [1, 2]):
        h = np.array([1.0 / (4 * ratio ** i) for i in range(n)])
        if abs(D) * (h[-1] / h[0]) ** m > 0.5:
            continue
        e = 0.3 * h ** q * (1.0 + D * (h / h[0]) ** m)
        for claim in (q, q + 1):
            d = decide(StudyData(h.tolist(), [round(1 / x) for x in h], e.tolist(), [FLOOR] * n, Order(claim, "t"),
                                 claimed=claim, refined=2))
            seen[claim == q].add(d.status)
            assert d.status != (FAILED if claim == q else PASSED), (ratio, n, D, m, claim, d.message)
    assert PASSED in seen[True] and FAILED in seen[False]


def test_errors_flat_at_a_floor_on_every_grid_are_exact_to_it_and_a_constant_error_fails():
    """The user's case (issue 42): an integrator exact at the nodes up to a Newton solve's floor, errors 7.9e-11 ->
    3.2e-11 across the grids, failed as "order 0.31 measured".  Flat errors at no more than 1e-8 of the solution's
    scale are a floor: exact to it.  The same shape at 1e-3 (a wrong limit) fails; the study coarsens first."""
    user = np.geomspace(7.9e-11, 3.2e-11, 5)
    d = decide(data(user, 2.0, claimed=2.0))
    assert d.status == PASSED and "exact to the floor" in d.message and d.worst == 0.0, d.message
    noise = 1e-10 * (1.0 + 0.3 * np.random.default_rng(42).random(6))
    assert decide(data(noise, 2.0, claimed=2.0)).status == PASSED
    assert decide(data(noise, 2.0, claimed=2.0, can_coarsen=True)).action == "coarsen"
    for wrong in (user * 1e7 / 7.9, noise * 1e7):       # the same shapes at 1e-3
        bad = decide(data(wrong, 2.0, claimed=2.0))
        assert bad.status == FAILED, bad.message
    # at 1e-7 of the scale a flat error is no floor of round-off or of a tight solve: undecided with the advice
    assert decide(data(noise * 1e3, 2.0, claimed=2.0)).status == UNDECIDED
    # falling at the order it claims, tiny errors are no floor: a scheme of order 1 claimed 2 at 1e-10 fails
    tiny = 1e-9 * np.array([1.0 / 2 ** k for k in range(5)])
    assert decide(data(tiny, 2.0, claimed=2.0)).status == FAILED


def test_a_newton_solves_noise_below_1e_8_is_exact_to_the_floor_not_a_slope():
    """probe8: solve_nivp's trapezoidal rule (ERC-INJECT/solve_nivp c82f2bc) on t|x| is exact for the quadratic
    solution up to its semismooth Newton solve: errors 1e-16 on K = 2, 4 and 8e-12 ... 9.5e-11 after, spread 1e5,
    not flat.  Read as slopes the noise "measured 0.769 [0.170, 1.369]" and passed a claim of 1; from x0 = -0.7 it
    was undecided.  Both are exact to the floor; the same errors times 1e7 (1e-3: a wrong limit) still fail, and
    tiny errors falling at order 1 are still errors (claimed 2: failed)."""
    K = [2, 4, 9, 18, 40, 80, 160, 320, 640, 1280, 2560]
    runs = [[1.04e-16, 2.05e-16, 6.31e-11, 7.37e-11, 9.48e-11, 3.51e-11, 9.37e-11, 5.84e-11, 3.17e-11, 3.70e-11,
             8.19e-12],
            [4.98e-17, 4.49e-17, 2.19e-11, 3.99e-16, 9.18e-11, 1.22e-11, 9.28e-11, 9.62e-11, 6.17e-11, 2.14e-11,
             2.70e-12]]
    for e in runs:
        floors = [FLOOR] * len(K)                # the study's round-off floor, 10^4 eps x scale
        d = decide(StudyData([2.0 / k for k in K], K, e, floors, Order(1.0, "t"), 1.0, None, 1.0, [], 2, False,
                             False))
        assert d.status == PASSED and "exact to the floor" in d.message and "without falling" in d.message, d.message
        wrong = decide(StudyData([2.0 / k for k in K], K, [x * 1e7 + 1e-3 for x in e], floors, Order(1.0, "t"), 1.0,
                                 None, 1.0, [], 2, False, False))
        assert wrong.status == FAILED, wrong.message
    tiny = 1e-9 * np.array([1.0 / 2 ** k for k in range(5)])
    assert decide(data(tiny, 2.0, claimed=2.0)).status == FAILED
