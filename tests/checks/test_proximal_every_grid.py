"""Issue 24: the proximal scheme's step-by-step laws (``selections``, ``in_domain``) are judged on every
partition the battery builds, so the verdict on a stepper that deviates on some steps only does not depend
on which random partition a seed drew.  The planted stepper (``zoo_steppers.residual_stop``) accepts its
Newton predictor when the residual is below 1e-4 — off on the small steps only."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.checks.partitions import EVERY_GRID, default_grids, every_battery_grid, limit_grids
from verimono.checks.trajectory_laws import check_selections
from verimono.reference import get
from zoo_steppers import residual_stop


def test_the_proximal_laws_are_declared_on_every_grid():
    assert EVERY_GRID >= {"selections", "in_domain"}
    kinds = every_battery_grid(get("t|x| (n=1)"), seed=0)
    assert {"uniform", "random", "graded", "uniform K=160", "random K=160", "graded K=160"} <= set(kinds)


@pytest.mark.parametrize("name", ["t|x| (n=1)", "t|x| (n=3)"])
def test_a_stepper_off_on_small_steps_fails_selections_at_every_seed(name):
    p = get(name)
    seen_default = []
    for seed in range(3):
        rec = check_selections(residual_stop, p, seed=seed)
        assert rec.status == "failed", str(rec)
        seen_default.append(check_selections(residual_stop, p, grids=default_grids(p, seed), seed=seed).status)
    # the two default partitions alone miss it (the planted violation is real only off them)
    assert "passed" in seen_default
    # the correct scheme passes on every grid
    assert check_selections(vm.solve, p, seed=0).status == "passed"


def test_the_battery_partitions_are_built_once_and_handed_out_as_copies():
    """The partitions are cached per (T, seed): each call gets its own arrays, so a law (or a stepper) that
    writes into one cannot change what the next law is judged on; they are the partitions the grid
    functions build (uniform: ``linspace``; random and graded: :mod:`verimono.core.grids`)."""
    p = get("t|x| (n=1)")
    first = every_battery_grid(p, seed=3)
    assert np.array_equal(first["uniform"], np.linspace(0.0, p.T, 41))
    assert np.array_equal(first["random"], vm.random_grid(p.T, 40, seed=3, spread=0.6))
    assert np.array_equal(first["graded K=160"], vm.graded_grid(p.T, 160, 2.0))
    for g in first.values():
        g[1:-1] = -1.0                      # a careless writer
    again = every_battery_grid(p, seed=3)
    assert set(again) == set(first)
    assert all(np.all(np.diff(g) > 0) and g[0] == 0.0 and g[-1] == p.T for g in again.values())
    assert np.array_equal(again["uniform"], np.linspace(0.0, p.T, 41))
    other = every_battery_grid(p, seed=4)
    assert not np.array_equal(other["random"], again["random"])   # the seed is part of the key
    for build in (lambda: default_grids(p, 3), lambda: limit_grids(p.T, 160, 3)):   # the other cached builders
        for g in build().values():
            g[1:-1] = -1.0
        assert all(np.all(np.diff(g) > 0) for g in build().values())
