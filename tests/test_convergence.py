"""Order estimation: synthetic data with known orders, round-off floors, fine-grid references."""

from __future__ import annotations

import math

import numpy as np
import pytest

import verimono as vm
from verimono.convergence import ORDER_SLACK, convergence_study, fit_order, grid_errors


@pytest.mark.parametrize("p", [0.5, 1.0, 2.0])
@pytest.mark.parametrize("ratio", [2.0, 3.0, 1.7])
def test_fit_recovers_exact_power_laws_for_any_step_ratio(p, ratio):
    h = 0.1 / ratio ** np.arange(5)
    fit = fit_order(h, 3.0 * h ** p)
    assert fit.slope == pytest.approx(p, abs=1e-12)
    assert fit.contains(p, slack=1e-9)  # exact data: a zero-width interval at p
    assert not fit.pre_asymptotic


def test_fit_interval_covers_noisy_data_and_flags_curvature():
    rng = np.random.default_rng(0)
    h = 0.2 / 2 ** np.arange(6)
    fit = fit_order(h, h * np.exp(rng.normal(0, 0.05, h.size)))
    assert fit.low <= 1.0 <= fit.high
    curved = fit_order(h, h ** 2 + 1e-3 * h ** 0.5)  # order 2 at large h, order 1/2 at small h
    assert curved.pre_asymptotic


def test_points_at_round_off_are_dropped_and_all_dropped_means_exact():
    h = 0.1 / 2 ** np.arange(5)
    e = np.array([1e-2, 2.5e-3, 6.25e-4, 1e-17, 3e-17])
    fit = fit_order(h, e, floor=1e-12)
    assert fit.dropped == [3, 4] and fit.slope == pytest.approx(2.0)
    assert fit_order(h, np.full(5, 1e-16), floor=1e-12).exact


def test_grid_errors_norms():
    t = np.array([0.0, 0.5, 1.0])
    x = np.array([[0.0], [1.0], [2.0]])
    errs = grid_errors(t, x, np.zeros_like(x))
    assert errs == {"sup": 2.0, "l2": pytest.approx(math.sqrt(0.5 * 1 + 0.5 * 4)), "final": 2.0}


def test_study_without_exact_solution_uses_fine_grid_and_says_so():
    p = vm.Problem(vm.Linear([[2.0, 1.0], [-1.0, 0.5]]), [1.0, 1.0], 1.0)
    s = convergence_study(vm.solve, p, [0.1, 0.05, 0.025, 0.0125])
    assert "fine-grid" in s.reference
    assert s.order.slope == pytest.approx(1.0, abs=0.15)


def test_study_accepts_nonuniform_grids_and_rejects_wrong_shapes():
    from verimono.reference import get

    p = get("t|x| (n=1)")
    grids = [vm.random_grid(p.T, k, seed=k) for k in (40, 80, 160, 320)]
    s = convergence_study(vm.solve, p, grids)
    assert s.order.reaches(1.0)
    with pytest.raises(vm.InvalidProblem, match="returned shape"):
        convergence_study(lambda prob, t: np.zeros((len(t), 5)), p, [0.1, 0.05])
    with pytest.raises(vm.InvalidProblem, match="at least two"):
        convergence_study(vm.solve, p, [0.1])


def test_study_round_trips_through_dict():
    from verimono.convergence import ConvergenceStudy
    from verimono.reference import get

    s = convergence_study(vm.solve, get("moving box"))
    back = ConvergenceStudy.from_dict(s.to_dict())
    assert back.errors == s.errors and back.order.slope == s.order.slope and back.expected == s.expected


def test_slack_is_small_enough_to_separate_half_from_one():
    assert 0.5 + 2 * ORDER_SLACK < 1.0
