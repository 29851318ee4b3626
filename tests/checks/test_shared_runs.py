"""One run of a stepper per (problem, partition) within a battery (:mod:`verimono.checks.shared_runs`)."""

from __future__ import annotations

import collections

import numpy as np
import pytest

import verimono
from verimono.checks.partitions import run_stepper
from verimono.checks.shared_runs import shared_runs
from verimono.core.grids import uniform_grid
from verimono.reference import catalog
from verimono.core.tolerances import judged_precision


def _problem(name: str = "static ball, x0 outside (jump)"):
    return next(p for p in catalog() if p.name == name)


def _counting(stepper):
    calls = collections.Counter()

    def counted(problem, t_grid):
        calls[(problem.name, len(t_grid), np.asarray(t_grid).tobytes(), np.asarray(problem.x0).tobytes())] += 1
        return stepper(problem, t_grid)

    return counted, calls


def test_a_battery_runs_the_stepper_once_per_problem_and_partition():
    stepper, calls = _counting(verimono.solve)
    p = _problem()
    report = verimono.check_stepper(stepper, [p], orders=False)
    assert not report.failures
    assert calls and max(calls.values()) == 1          # every partition the laws share: one run each
    outside, calls_outside = _counting(verimono.solve)
    t = uniform_grid(p.T, steps=40)
    run_stepper(outside, p, t), run_stepper(outside, p, t)
    assert max(calls_outside.values()) == 2           # outside a battery nothing is kept


def test_a_repeat_is_the_first_run_read_only():
    """A law cannot change the run another law judges: the kept run is read-only (a law that writes into it gets
    NumPy's error), and a repeat is the same array, not a copy (a copy per reuse cost a second per 161-node run at
    n = 10^6).  Outside a battery the run is the caller's own, writable."""
    from verimono.checks.shared_runs import run_serial

    p, t = _problem(), uniform_grid(1.0, steps=10)
    with shared_runs():
        first = run_stepper(verimono.solve, p, t)
        with pytest.raises(ValueError, match="read-only"):
            first[:] = np.nan                          # a law that writes into its array
        again = run_stepper(verimono.solve, p, t)
        assert again is first and run_serial(again) is not None
        assert run_serial(np.array(first)) is None     # a copy is no kept run
    assert np.all(np.isfinite(again))
    np.testing.assert_array_equal(again, verimono.solve(p, t))
    own = run_stepper(verimono.solve, p, t)
    own[0] = 0.0                                       # outside a block: the caller's own array
    assert run_serial(own) is None


def test_a_repeat_reports_the_precision_the_stepper_computed_in():
    """A float32 stepper's reused states are judged as float32 by the second law too."""
    def single(problem, t_grid):
        return np.asarray(verimono.solve(problem, t_grid), dtype=np.float32)

    p, t = _problem(), uniform_grid(1.0, steps=10)
    with shared_runs():
        with judged_precision() as first:
            run_stepper(single, p, t)
        with judged_precision() as second:
            run_stepper(single, p, t)
    assert first.name == second.name == "float32"


def test_a_stepper_that_fails_is_not_remembered():
    calls = []

    def flaky(problem, t_grid):
        calls.append(1)
        return np.full((len(t_grid), problem.dim), np.nan)

    p, t = _problem(), uniform_grid(1.0, steps=10)
    with shared_runs():
        for _ in range(2):
            with pytest.raises(ValueError, match="non-finite"):
                run_stepper(flaky, p, t)
    assert len(calls) == 2


def test_different_initial_points_and_horizons_are_different_runs():
    stepper, calls = _counting(verimono.solve)
    p, t = _problem(), uniform_grid(1.0, steps=10)
    with shared_runs():
        a = run_stepper(stepper, p, t)
        b = run_stepper(stepper, p.replace(x0=p.x0 * 0.5), t)
    assert sum(calls.values()) == 2 and not np.array_equal(a, b)


def test_a_remembered_value_is_computed_once_and_reports_its_precision_on_every_reuse():
    from verimono.checks.shared_runs import remembered_value
    from verimono.core.tolerances import observe

    calls = []

    def compute():
        calls.append(1)
        observe(np.float32)                 # what the operator computed in, seen while computing
        return (np.arange(3.0),)

    with shared_runs():
        for _ in range(3):
            with judged_precision() as seen:
                (a,) = remembered_value(("k",), (), compute)
                a[0] = 99.0                 # a copy: the next reuse is not changed
            assert seen.name == "float32"
        (b,) = remembered_value(("k",), (), compute)
    assert len(calls) == 1 and b[0] == 0.0
    with judged_precision() as seen:        # outside any block: computed every time
        remembered_value(("k",), (), compute)
    assert len(calls) == 2 and seen.name == "float32"


def test_witnesses_shared_by_in_domain_and_selections_are_computed_once():
    from verimono.checks.trajectory_laws import check_in_domain
    from verimono.checks.stepper_battery import CHECKS

    p = _problem("translating ball")
    resolvents = collections.Counter()
    op = p.operator
    original = op.resolvent

    def counted(x, lam, t=0.0):
        resolvents[(np.asarray(x).tobytes(), float(lam), float(t))] += 1
        return original(x, lam, t)

    op.resolvent = counted
    t = uniform_grid(p.T, steps=40)
    with shared_runs():
        assert check_in_domain(verimono.solve, p, grids=[t]).status == "passed"
        assert CHECKS["selections"](verimono.solve, p, grids=[t]).status == "passed"
    assert resolvents and max(resolvents.values()) == 1
