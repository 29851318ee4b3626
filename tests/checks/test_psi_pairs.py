"""lem:bndEquiCont on long partitions: beyond ``ALL_PAIRS`` times the ψ-interpolation law judges the consecutive
pairs (which bound every other pair through the triangle inequality, ψ nondecreasing) and every pair of a
subsample — all pairs of 40 000 times (solve_adaptive's own partition at tol = 1e-4) took the process's memory."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.checks.bounds import ALL_PAIRS, _pairs, check_psi_interpolation
from verimono.reference import subdifferential


def test_pairs_are_all_pairs_up_to_the_limit_then_consecutive_and_a_subsample():
    i, j = _pairs(7)
    assert len(i) == 21 and np.all(i < j)
    n = 3 * ALL_PAIRS + 17
    i, j = _pairs(n)
    assert np.all(i < j) and np.all(j < n)
    consecutive = set(zip(i.tolist(), j.tolist()))
    assert all((k, k + 1) in consecutive for k in range(n - 1))
    assert (0, n - 1) in consecutive                 # the subsample holds both ends
    assert len(i) < n + ALL_PAIRS ** 2


def kicked(at):
    """The scheme with one iterate kicked by 0.3 at the fraction ``at`` of the partition: one cell's increment
    exceeds ψ's, a violation only a pair across that cell sees."""
    def stepper(problem, t):
        x = vm.solve(problem, t).x.copy()
        x[int(at * (len(t) - 1))] += 0.3
        return x
    return stepper


@pytest.mark.parametrize("cells, at", [(2000, 0.5), (5000, 0.8137), (5000, 0.0911)])
def test_long_partitions_pass_the_scheme_and_fail_a_kicked_iterate(cells, at):
    p = subdifferential.t_norm((0.6, -0.8))
    t = vm.uniform_grid(p.T, steps=cells)
    good = check_psi_interpolation(vm.solve, p, grids=[t])
    assert good.status == "passed" and good.details["times"] > ALL_PAIRS, good
    bad = check_psi_interpolation(kicked(at), p, grids=[t])
    assert bad.status == "failed", bad


def test_in_a_large_dimension_the_pairs_hold_a_bounded_number_of_coordinates():
    """Every pair is a difference of two states: at n = 10^6 the 3 000 pairs of 80 times were 3e9 numbers (24 GB)
    and the battery had no verdict after 120 s.  The all-pairs subsample now shrinks with the dimension (the
    consecutive pairs, which bound the others, always stay), so the work per time is linear in n."""
    from verimono.checks.bounds import PAIR_ELEMENTS

    for dim in (10**4, 10**6):
        i, j = _pairs(80, dim)
        consecutive = set(zip(i.tolist(), j.tolist()))
        assert all((k, k + 1) in consecutive for k in range(79)) and (0, 79) in consecutive
        assert (len(i) - 79) * dim <= PAIR_ELEMENTS
    assert len(_pairs(80, 3)[0]) == 80 * 79 // 2       # a small dimension keeps every pair, as before


@pytest.mark.parametrize("at", [0.5, 0.2])
def test_a_kicked_iterate_fails_in_a_large_dimension_and_the_scheme_passes(at):
    n = 5_000                          # the subsample is cut here: 82 of the 121 times
    box = vm.sets.Box(-np.ones(n), np.ones(n))
    p = vm.Problem(vm.NormalCone(box), np.linspace(-0.9, 0.9, n), 1.0, u=lambda t: np.full(n, 0.5), name="box")
    t = vm.uniform_grid(p.T, steps=40)
    good = check_psi_interpolation(vm.solve, p, grids=[t])
    assert good.status == "passed" and good.details["pairs"] < good.details["times"] ** 2 / 2, good
    bad = check_psi_interpolation(kicked(at), p, grids=[t])
    assert bad.status == "failed", bad
