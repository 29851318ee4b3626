"""Bad input of every kind gets its typed error with a message saying what was expected."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.core.sets import Ball, Box, Polyhedron


def ok_problem(**kw):
    return vm.Problem(vm.NormSubdifferential(1.0, dim=2), kw.pop("x0", [1.0, 0.0]), kw.pop("T", 1.0), **kw)


def test_every_error_is_a_verimono_error():
    for cls in (vm.InvalidProblem, vm.InvalidGrid, vm.OutsideDomain, vm.NotMonotone, vm.InfeasibleStep,
                vm.SolverFailure):
        assert issubclass(cls, vm.VerimonoError)


@pytest.mark.parametrize("x0, match", [
    ([1.0, 2.0, 3.0], r"shape \(2,\)"),
    ([[1.0], [2.0]], r"shape \(2,\)"),
    ([np.nan, 0.0], "finite"),
    ([np.inf, 0.0], "finite"),
    (["a", "b"], "numeric"),
])
def test_bad_initial_points(x0, match):
    with pytest.raises(vm.InvalidProblem, match=match):
        ok_problem(x0=x0)


@pytest.mark.parametrize("T", [0.0, -1.0, np.inf, np.nan, "x"])
def test_bad_final_time(T):
    with pytest.raises(vm.InvalidProblem, match="T must"):
        ok_problem(T=T)


def test_bad_callables_and_their_shapes():
    with pytest.raises(vm.InvalidProblem, match="f must be callable"):
        ok_problem(f=3.0)
    with pytest.raises(vm.InvalidProblem, match=r"f\(x0\) must have the shape"):
        ok_problem(f=lambda x: np.zeros(3))
    with pytest.raises(vm.InvalidProblem, match=r"u\(0\) must have shape"):
        ok_problem(u=lambda t: np.zeros(5))
    with pytest.raises(vm.InvalidProblem, match="finite"):
        ok_problem(u=lambda t: np.array([np.nan, 0.0]))
    with pytest.raises(vm.InvalidProblem, match="verimono.Operator"):
        vm.Problem(object(), [0.0], 1.0)


def test_initial_point_outside_the_domain():
    S = vm.NormalCone(Ball([0.0, 0.0], 1.0))
    with pytest.raises(vm.OutsideDomain, match="outside cl dom"):
        vm.Problem(S, [2.0, 0.0], 1.0)
    vm.Problem(S, [2.0, 0.0], 1.0, initial_jump=True)  # explicitly allowed catching-up jump
    with pytest.raises(vm.OutsideDomain):
        vm.Problem(vm.LogBarrier(1.0), [-0.5], 1.0)


@pytest.mark.parametrize("grid, match", [
    ([0.0, 0.5, 0.5, 1.0], "strictly increasing"),
    ([0.0, 0.7, 0.4, 1.0], "strictly increasing"),
    ([0.1, 0.5, 1.0], "start at t_0 = 0"),
    ([0.0, 0.5, 0.9], "end at T"),
    ([0.0, np.nan, 1.0], "non-finite"),
    ([[0.0, 1.0]], "1-D"),
    ([0.0], "at least 2"),
])
def test_bad_grids(grid, match):
    with pytest.raises(vm.InvalidGrid, match=match):
        vm.solve(ok_problem(), grid)


@pytest.mark.parametrize("args, match", [
    ((1.0, 0.0), "positive"), ((1.0, -0.1), "positive"), ((1.0, 0.3), "does not divide"),
    ((0.0, 0.1), "T must be positive"), ((1.0, np.nan), "positive and finite"),
])
def test_bad_uniform_grids(args, match):
    with pytest.raises(vm.InvalidGrid, match=match):
        vm.uniform_grid(*args)


def test_not_monotone_operators_and_sets():
    with pytest.raises(vm.NotMonotone):
        vm.Linear([[0.0, 1.0], [0.0, -1.0]])
    with pytest.raises(vm.NotMonotone, match="nonnegative"):
        vm.NormSubdifferential(-1.0)
    with pytest.raises(vm.NotMonotone):
        vm.L1Subdifferential([1.0, -1.0], dim=2)
    with pytest.raises(vm.InvalidProblem, match="empty"):
        Box([1.0], [0.0])
    with pytest.raises(vm.InvalidProblem, match="square"):
        vm.Linear(np.ones((2, 3)))


def test_infeasible_polyhedron_projection():
    S = Polyhedron([[1.0], [-1.0]], [-1.0, -1.0])  # x <= -1 and x >= 1: empty
    with pytest.raises(vm.VerimonoError):
        S.project(np.array([0.0]))


def test_non_finite_resolvent_output_is_reported_with_its_step():
    def resolvent(x, lam, t):
        return x if t < 0.5 else x * np.nan
    op = vm.operator_from_resolvent(resolvent, 1)
    with pytest.raises(vm.SolverFailure, match=r"non-finite state at step 5"):
        vm.solve(vm.Problem(op, [1.0], 1.0), vm.uniform_grid(1.0, 0.1))


def test_resolvent_of_wrong_shape_is_reported():
    op = vm.operator_from_resolvent(lambda x, lam, t: np.zeros(3), 2)
    with pytest.raises(vm.SolverFailure, match="returned shape"):
        vm.solve(vm.Problem(op, [1.0, 0.0], 1.0), vm.uniform_grid(1.0, 0.5))


def test_every_public_exception_class_lives_in_errors():
    """Every public exception class of the package is defined in verimono/errors.py and still importable
    from where it was before (``verimono.run.stages.StageUnavailable``, ``verimono.records.schema.SchemaError``, ...)."""
    import importlib
    import pkgutil

    from verimono import errors

    modules = [importlib.import_module(m.name) for m in pkgutil.walk_packages(vm.__path__, "verimono.")
               if m.name.split(".")[1] not in ("reference", "properties")]
    defined = {(obj.__module__, name) for mod in modules for name, obj in vars(mod).items()
               if isinstance(obj, type) and issubclass(obj, BaseException) and not name.startswith("_")
               and obj.__module__.startswith("verimono")}
    assert {m for m, _ in defined} == {"verimono.core.errors"}, sorted(defined)
    old_homes = {"verimono.run.stages": ("StageUnavailable", "UnknownStage"), "verimono.cli": ("BadTarget",),
                 "verimono.execution.profiles": ("UnknownProfile",), "verimono.records.schema": ("SchemaError",),
                 "verimono.run.gate": ("IncompatibleBaseline",), "verimono.lcs.passivity": ("MissingOptionalDependency",)}
    for module, names in old_homes.items():
        for name in names:
            assert getattr(importlib.import_module(module), name) is getattr(errors, name)
            assert issubclass(getattr(errors, name), vm.VerimonoError)


def test_problem_is_frozen_and_replace_revalidates():
    import dataclasses

    p = ok_problem(name="p", order=1)
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.T = 2.0
    q = p.replace(T=2.0, x0=[0.5, 0.5])
    assert (q.T, q.name, q.order, q.operator) == (2.0, "p", p.order, p.operator) and p.T == 1.0
    assert np.array_equal(q.x0, [0.5, 0.5]) and dataclasses.replace(p, T=3.0).T == 3.0
    with pytest.raises(vm.InvalidProblem, match="T must"):
        p.replace(T=-1.0)
    with pytest.raises(vm.InvalidProblem, match="no field"):
        p.replace(horizon=2.0)
