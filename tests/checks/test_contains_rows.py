"""``contains`` of a block of rows in one call (``_contains_rows`` of the catalog's NormalCone and Linear, used by the
engine's ``row_contains``): bit-identical to the calls per row — on graph points (``(J_λx, Y_λx)``, at the
boundary of the set, where the test is decided by rounding), on pairs moved off the graph by a few tolerances, at
every time — and declined where a member is not the class's own (a subclass, a member replaced on the object)."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.checks.engine.batches import row_contains
from verimono.core.sets import Ball, Box, HalfSpace


def _moving_ball():
    return vm.NormalCone(Ball(lambda t: np.array([np.sin(t), 0.5 * t, -1.0]), lambda t: 1.0 + 0.5 * t))


_OPS = {
    "ball": lambda: vm.NormalCone(Ball(np.zeros(3), 1.0)),
    "moving_ball": _moving_ball,
    "box": lambda: vm.NormalCone(Box([-1.0, 0.0], [1.0, 2.0])),
    "moving_box": lambda: vm.NormalCone(Box(lambda t: np.array([-1.0, t]), lambda t: np.array([1.0 + t, 2.0]))),
    "halfspace": lambda: vm.NormalCone(HalfSpace(lambda t: np.array([2.7, -2.2]), lambda t: -1.1 + 0.3 * t)),
    "linear": lambda: vm.Linear(np.array([[2.0, 1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 0.5]])),
    "moving_linear": lambda: vm.Linear(lambda t: np.array([[1.0 + t, t], [-t, 2.0]])),
    "norm": lambda: vm.NormSubdifferential(lambda t: 0.5 + t, dim=3),
    "norm_1": lambda: vm.NormSubdifferential(2.222, dim=1),
    "l1": lambda: vm.L1Subdifferential(np.array([1.6, 0.53, 4.99]), 3),
    "l1_moving": lambda: vm.L1Subdifferential(lambda t: 1e-3 + np.sin(0.7 * t), 1),
    "log_barrier": lambda: vm.LogBarrier(lambda t: 1.0 + t, dim=2),
    "shifted_box": lambda: vm.Shifted(vm.NormalCone(Box([2.3, 0.0], [2.3, 1.7])),
                                      lambda t: np.array([np.sin(3 * t), -1.2 * t * t])),
    "shifted_linear": lambda: vm.Shifted(vm.Linear(np.zeros((3, 3))), lambda t: np.array([1.98 * t, -t, 0.78])),
}


def _rows(op, rng, B=400):
    n = op.dim
    x0 = rng.standard_normal((B, n)) * 10.0 ** rng.integers(-3, 4, size=(B, 1))
    lam = 10.0 ** rng.uniform(-6, 3, size=B)
    ts = rng.uniform(0.0, 1.0, size=B)
    J = np.array([op.resolvent(x0[i].copy(), lam[i], ts[i]) for i in range(B)])
    Y = (x0 - J) / lam[:, None]
    tols = 1e-8 * (1.0 + np.maximum(np.abs(J).max(axis=1), np.abs(Y).max(axis=1))) * rng.choice([0.5, 1.0, 2.0, 8.0], B)
    kick = rng.standard_normal((B, n)) * tols[:, None] * rng.choice([0.0, 0.3, 1.0, 3.0, 1e3], (B, 1))
    X = J + (rng.random((B, 1)) < 0.3) * kick
    Y = Y + (rng.random((B, 1)) < 0.5) * kick[:, ::-1]
    # and moves of one coordinate by a hair below or above the tolerance: the test's boundary
    edge = np.zeros((B, n))
    edge[np.arange(B), rng.integers(0, n, B)] = tols * rng.choice([-1.0, 1.0], B) * rng.choice([0.99, 1.005, 1.02], B)
    which = rng.integers(0, 3, B)
    X = np.where((which == 1)[:, None], J + edge, X)
    Y = np.where((which == 2)[:, None], (x0 - J) / lam[:, None] + edge, Y)
    return X, Y, ts, tols


@pytest.mark.parametrize("name", sorted(_OPS))
def test_the_block_is_the_calls_per_row(name):
    op = _OPS[name]()
    rng = np.random.default_rng(11)
    X, Y, ts, tols = _rows(op, rng)
    block = op._contains_rows(X, Y, ts, tols)
    assert block is not None and block.dtype == bool
    one = np.array([op.contains(X[i].copy(), Y[i].copy(), float(ts[i]), float(tols[i])) for i in range(len(ts))])
    assert (block == one).all(), np.flatnonzero(block != one)
    assert 0.1 < one.mean() < 0.95          # both answers are met, many at the rounding boundary
    ok = np.ones(len(ts), dtype=bool)
    assert (row_contains(op, X, Y, ts, tols, ok) == one).all() and ok.all()


def test_declined_where_a_member_is_not_the_class_own():
    class Mine(vm.NormalCone):
        def contains(self, x, y, t=0.0, tol=None):
            return True
    op = Mine(Ball(np.zeros(2), 1.0))
    X = np.full((3, 2), 5.0)
    assert op._contains_rows(X, X, np.zeros(3), np.ones(3)) is None
    ok = np.ones(3, dtype=bool)
    assert row_contains(op, X, X, np.zeros(3), np.full(3, 1e-8), ok).all()       # its own answer, per row
    lin = vm.Linear(np.eye(2))
    lin.contains = lambda x, y, t=0.0, tol=None: False
    assert lin._contains_rows(X, X, np.zeros(3), np.ones(3)) is None
    assert not row_contains(lin, X, X @ np.eye(2), np.zeros(3), np.full(3, 1e-8), ok).any()


def test_declined_where_contains_is_replaced_on_the_class(monkeypatch):
    """A wrapper set on the class itself (an instrumented contains, as the engine-overhead benchmark times members)
    is called per row: the block would answer for the class's own test, not for it."""
    seen = []
    own = vm.NormalCone.contains

    def counted(self, x, y, t=0.0, tol=None):
        seen.append(1)
        return own(self, x, y, t, tol)
    monkeypatch.setattr(vm.NormalCone, "contains", counted)
    op = vm.NormalCone(Ball(np.zeros(2), 1.0))
    assert op._contains_rows(np.zeros((3, 2)), np.zeros((3, 2)), np.zeros(3), np.ones(3)) is None
    ok = np.ones(3, dtype=bool)
    assert row_contains(op, np.zeros((3, 2)), np.zeros((3, 2)), np.zeros(3), np.full(3, 1e-8), ok).all()
    assert len(seen) == 3
