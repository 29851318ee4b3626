"""Issue 6, target 2: ensembles — one vectorized solve of B trajectories.

``solve(problem, t)`` with ``problem.x0`` of shape ``(B, n)`` returns ``(len(t), B, n)`` values that are
bit-identical to ``B`` separate solves, for every catalog operator and set (checked here, untimed), and for
``B = 1000`` runs at least ``ENSEMBLE_TARGET`` × faster than the ``B`` separate ``solve`` calls (timed
by :func:`verimono.run.performance.check_ensemble`, which also asserts the identical results; the problems
are built outside the timing).  Batches of operators: ``NormSubdifferential(c)`` with ``c`` of shape ``(B,)``,
``Ball`` with centers ``(B, n)`` and radii ``(B,)``, ``Box`` with bounds ``(B, n)``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import verimono as vm
from verimono.run.performance import check_ensemble
from verimono.core.sets import Ball, Box, HalfSpace, Polyhedron, Translated

RNG = np.random.default_rng(6)


def catalog_cases():
    box = Box(-0.5 * np.ones(3), 0.5 * np.ones(3))
    return {
        "NormSubdifferential": (vm.NormSubdifferential(0.7, dim=3), {}),
        "NormSubdifferential(t)": (vm.NormSubdifferential(lambda t: t, dim=3), {}),
        "L1Subdifferential": (vm.L1Subdifferential([0.1, 0.2, 0.3], dim=3), {}),
        "Linear": (vm.Linear([[1.0, 2.0, 0.0], [-2.0, 0.5, 0.0], [0.0, 0.0, 1.0]]), {}),
        "Linear(t)": (vm.Linear(lambda t: np.array([[t, 1.0, 0.0], [-1.0, t, 0.0], [0.0, 0.0, 1.0]])), {}),
        "Ball": (vm.NormalCone(Ball(np.zeros(3), 0.8)), {"initial_jump": True}),
        "Ball(t)": (vm.NormalCone(Ball(lambda t: np.array([t, 0.0, 0.0]), 0.8)), {"initial_jump": True}),
        "Box": (vm.NormalCone(box), {"initial_jump": True}),
        "Box(t)": (vm.NormalCone(Box(lambda t: np.array([t - 1, -1.0, -1.0]), lambda t: np.array([t, 1.0, 1.0]))),
                   {"initial_jump": True}),
        "HalfSpace(t)": (vm.NormalCone(HalfSpace([1.0, 2.0, -1.0], math.cos)), {"initial_jump": True}),
        "Polyhedron": (vm.NormalCone(Polyhedron(np.vstack([np.eye(3), -np.eye(3), [[1.0, 1.0, 1.0]]]),
                                                np.r_[np.ones(6) * 0.6, 0.5])), {"initial_jump": True}),
        "Translated(t)": (vm.NormalCone(Translated(Ball(np.zeros(3), 0.5), lambda t: np.array([t, 0.0, 0.0]))),
                          {"initial_jump": True}),
        "Shifted(t)": (vm.Shifted(vm.NormSubdifferential(1.0, dim=3), lambda t: np.array([math.sin(t), 0.0, 0.0])), {}),
        "LogBarrier": (vm.LogBarrier(1.0, dim=3), {"initial_jump": True}),
        "f and u": (vm.NormSubdifferential(0.3, dim=3),
                    {"f": lambda x: -0.5 * x, "u": lambda t: np.array([math.cos(t), 0.0, 0.0])}),
    }


def separate(op, X0, t, **kw):
    return np.stack([vm.solve(vm.Problem(op, x, t[-1], **kw), t).x for x in X0], axis=1)


@pytest.mark.parametrize("name", list(catalog_cases()))
def test_batched_solve_is_bit_identical_to_separate_solves(name):
    op, kw = catalog_cases()[name]
    X0 = RNG.normal(size=(40, 3))
    if name == "LogBarrier":
        X0 = np.abs(X0)
    t = vm.random_grid(1.0, 25, seed=1)
    xb = vm.solve(vm.Problem(op, X0, 1.0, **kw), t).x
    assert xb.shape == (26, 40, 3)
    assert np.array_equal(xb, separate(op, X0, t, **kw))


def test_operator_batches_match_separate_operators():
    B, n = 30, 3
    X0 = RNG.normal(size=(B, n))
    t = vm.uniform_grid(1.0, steps=20)
    c = RNG.uniform(0.1, 2.0, B)
    xb = vm.solve(vm.Problem(vm.NormSubdifferential(c, dim=n), X0, 1.0), t).x
    xs = np.stack([vm.solve(vm.Problem(vm.NormSubdifferential(ci, dim=n), x, 1.0), t).x for ci, x in zip(c, X0)], 1)
    assert np.array_equal(xb, xs)
    centers, radii = RNG.normal(size=(B, n)), RNG.uniform(0.2, 1.0, B)
    xb = vm.solve(vm.Problem(vm.NormalCone(Ball(centers, radii)), X0, 1.0, initial_jump=True), t).x
    xs = np.stack([vm.solve(vm.Problem(vm.NormalCone(Ball(ci, ri)), x, 1.0, initial_jump=True), t).x
                   for ci, ri, x in zip(centers, radii, X0)], 1)
    assert np.array_equal(xb, xs)
    lo = RNG.uniform(-1.0, 0.0, (B, n))
    hi = lo + RNG.uniform(0.1, 1.0, (B, n))
    xb = vm.solve(vm.Problem(vm.NormalCone(Box(lo, hi)), X0, 1.0, initial_jump=True), t).x
    xs = np.stack([vm.solve(vm.Problem(vm.NormalCone(Box(a, b)), x, 1.0, initial_jump=True), t).x
                   for a, b, x in zip(lo, hi, X0)], 1)
    assert np.array_equal(xb, xs)


SPEED_CASES = ["NormSubdifferential(t)", "Box", "Ball", "Linear", "HalfSpace(t)"]


@pytest.mark.parametrize("name", SPEED_CASES)
def test_batch_of_1000_vs_1000_separate_solves(gate, name):
    op, kw = catalog_cases()[name]
    gate.check(check_ensemble(op, name, batch=gate.size(1000, 200), steps=gate.size(200, 50),
                              rounds=gate.rounds(3, 2), problem_kw=kw, runner=gate.runner))
