"""Issue 24: the proximal scheme's step-by-step laws (``selections``, ``in_domain``) are judged on every
partition the battery builds, so the verdict on a stepper that deviates on some steps only does not depend
on which random partition a seed drew.  The planted stepper (``zoo_steppers.residual_stop``) accepts its
Newton predictor when the residual is below 1e-4 — off on the small steps only."""

from __future__ import annotations

import pytest

import verimono as vm
from verimono.checks.partitions import EVERY_GRID, default_grids, every_battery_grid
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
