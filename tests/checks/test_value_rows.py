"""``value`` of a block of rows in one call (``_value_rows`` of the catalog's NormSubdifferential and L1Subdifferential,
used by ``prox_optimal`` for a sample's 42 perturbations): bit-identical to the calls per row — zero rows, signed
zeros, tiny and huge scales, constant and moving weights, dimensions across BLAS's and NumPy's summation blocks —
declined where ``value`` (or the norm's weight read) is not the class's own, and the law's outcome bit for bit the one
of its calls per row, on lawful subjects and on wrong ones.  Seen failing: with the block's rows built in another
order than the loop's (the worst perturbation moved), and with the L1 rows summed in reverse order."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import verimono as vm
from verimono.checks import prox_laws
from verimono.checks.engine.samples import Sample

_OPS = {
    "norm": lambda n: vm.NormSubdifferential(2.222, dim=n),
    "norm_moving": lambda n: vm.NormSubdifferential(lambda t: 0.5 + t, dim=n),
    "l1": lambda n: vm.L1Subdifferential(1.7, n),
    "l1_weights": lambda n: vm.L1Subdifferential(np.linspace(0.1, 5.0, n), n),
    "l1_moving": lambda n: vm.L1Subdifferential(lambda t: 1.0 + np.arange(n) * t, n),
}


@pytest.mark.parametrize("name", sorted(_OPS))
def test_the_block_is_the_calls_per_row(name):
    rng = np.random.default_rng(5)
    for n in (1, 2, 3, 7, 9, 17, 33, 130):
        op = _OPS[name](n)
        for scale in (1e-300, 1e-3, 1.0, 1e150):
            Z = rng.standard_normal((42, n)) * scale * np.exp(rng.uniform(-5, 5, (42, 1)))
            Z[3], Z[4] = 0.0, -0.0
            t = float(rng.uniform())
            with np.errstate(all="ignore"):
                block = op._value_rows(Z, t)
                one = np.array([op.value(z.copy(), t) for z in Z])
            assert block.dtype == np.float64 and block.tobytes() == one.tobytes(), (n, scale)


def test_declined_where_value_is_not_the_class_own():
    class Mine(vm.NormSubdifferential):
        def value(self, x, t=0.0):
            return 2.0 * super().value(x, t)

    class MyL1(vm.L1Subdifferential):
        def value(self, x, t=0.0):
            return 0.0

    Z = np.ones((4, 2))
    assert Mine(1.0, 2)._value_rows(Z, 0.0) is None and MyL1(1.0, 2)._value_rows(Z, 0.0) is None
    op = vm.NormSubdifferential(1.0, 2)
    op.value = lambda x, t=0.0: 0.0                         # replaced on the object
    assert op._value_rows(Z, 0.0) is None
    op = vm.NormSubdifferential(1.0, 2)
    op._c_at = lambda t: 3.0                                # the weight read through the object's own _c_at
    assert op._value_rows(Z, 0.0) is None
    assert vm.NormSubdifferential(1.0, 2)._value_rows(Z, 0.0).tolist() == [2 ** 0.5] * 4


class _PerRow:
    """The same operator seen through a wrapper class without ``_value_rows``: the law's calls per row."""

    def __init__(self, op):
        self._op = op

    def __getattr__(self, name):
        if name == "_value_rows":
            raise AttributeError(name)
        return getattr(self._op, name)


def _wrong_norm(n):
    """A resolvent of ``t|x|`` with the value of ``2t|x|``: the prox of another function (the law fails it)."""
    op = vm.NormSubdifferential(lambda t: t, dim=n)
    return vm.operator_from_resolvent(op.resolvent, n, value=lambda x, t=0.0: 2.0 * op.value(x, t))


@pytest.mark.parametrize("name", ["norm_moving", "l1_weights", "l1_moving"])
def test_the_outcome_is_the_calls_per_row(name):
    rng = np.random.default_rng(2)
    evaluate = prox_laws.check_prox_optimal.law.evaluate
    worst = []
    for n in (1, 3, 5):
        op = _OPS[name](n)
        for _ in range(25):
            s = Sample(rng.standard_normal(n) * 10.0 ** rng.integers(-4, 4), rng.standard_normal(n),
                       float(10 ** rng.uniform(-4, 1)), 0.5, 0.25, float(rng.uniform()))
            block, one = evaluate(op, s), evaluate(_PerRow(op), s)
            assert repr(dataclasses.asdict(block)) == repr(dataclasses.asdict(one))
            worst.append(block.worst)
    assert max(worst) < 1.0


def test_a_wrong_value_still_fails():
    rng = np.random.default_rng(3)
    evaluate = prox_laws.check_prox_optimal.law.evaluate
    op = _wrong_norm(3)
    assert getattr(type(op), "_value_rows", None) is None     # a user's operator: the calls per row
    bad = vm.NormSubdifferential(lambda t: 2.0 * t, dim=3)
    bad.resolvent = vm.NormSubdifferential(lambda t: t, dim=3).resolvent   # the prox of t|x| stated as 2t|x|'s
    fails = 0
    for _ in range(20):
        s = Sample(rng.standard_normal(3) * 3.0, rng.standard_normal(3), 1.0, 0.5, 0.25, 0.5 + 0.5 * rng.uniform())
        a, b, c = evaluate(op, s), evaluate(bad, s), evaluate(_PerRow(bad), s)
        assert repr(dataclasses.asdict(b)) == repr(dataclasses.asdict(c))
        fails += a.worst > 1.0 and b.worst > 1.0
    assert fails >= 10


@pytest.mark.parametrize("name", sorted(_OPS))
def test_the_value_at_one_time_is_value(name):
    """``_value_at(t)``: the minimiser's ``g`` at one time, the same float as ``value`` at every point."""
    rng = np.random.default_rng(7)
    for n in (1, 3, 17):
        op = _OPS[name](n)
        t = float(rng.uniform())
        g = op._value_at(t)
        Z = rng.standard_normal((30, n)) * 10.0 ** rng.integers(-200, 150, (30, 1))
        with np.errstate(all="ignore"):
            assert [g(z.copy()) for z in Z] == [op.value(z.copy(), t) for z in Z]
            assert all(type(g(z.copy())) is float for z in Z)


def test_the_minimiser_outcome_is_the_calls_per_point():
    rng = np.random.default_rng(4)
    evaluate = prox_laws.check_prox_minimiser.law.evaluate
    bad = vm.NormSubdifferential(lambda t: 2.0 * t, dim=2)
    bad.resolvent = vm.NormSubdifferential(lambda t: t, dim=2).resolvent   # the prox of t|x| stated as 2t|x|'s
    fails = 0
    for op in (_OPS["norm_moving"](2), _OPS["l1_weights"](3), _OPS["l1"](1), bad):
        for _ in range(4):
            s = Sample(rng.standard_normal(op.dim) * 3.0, rng.standard_normal(op.dim), float(10 ** rng.uniform(-2, 0.5)),
                       0.5, 0.25, 0.5 + 0.5 * float(rng.uniform()))
            a, b = evaluate(op, s), evaluate(_PerRow(op), s)
            assert repr(dataclasses.asdict(a)) == repr(dataclasses.asdict(b))
            fails += op is bad and a.worst > 1.0
    assert fails >= 3


@pytest.mark.parametrize("name", sorted(_OPS))
def test_a_time_per_row_is_the_calls_per_row(name):
    """``_value_rows(Z, ts)`` with a time per row (the prox inequality's vectorised form, through ``row_values``):
    the calls per row at each row's time, and the same rows marked not ok."""
    rng = np.random.default_rng(9)
    for n in (1, 3, 8):
        op = _OPS[name](n)
        Z = rng.standard_normal((50, n)) * 10.0 ** rng.integers(-5, 5, (50, 1))
        Z[7] = np.inf
        ts = rng.uniform(0.0, 1.0, 50)
        ts[10:20] = ts[9]                       # runs of one time, as the search's rows have them
        one = np.array([op.value(z.copy(), float(tt)) for z, tt in zip(Z, ts)])
        assert op._value_rows(Z, ts).tobytes() == one.tobytes()
        ok = np.ones(50, dtype=bool)
        ok[3] = False
        per = ok & np.isfinite(one)                     # the calls per row: a non-finite value marks its row
        want = np.where(per, one, 0.0)
        from verimono.checks.engine.batches import row_values
        assert row_values(op, Z, ts, ok).tobytes() == want.tobytes()
        assert (ok == per).all() and not ok[7]
