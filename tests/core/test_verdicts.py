"""The verdict rules of a convergence study on synthetic errors (``verimono.core.verdicts.decide``): power laws with
the shapes that matter — a pause, a stall, erratic constants, round-off, an inner solve's level — so each rule is
seen deciding both ways, independently of any stepper."""

from __future__ import annotations

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
