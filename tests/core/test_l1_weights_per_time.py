"""L1Subdifferential with a constant weight per coordinate (``c`` of shape ``(n,)``) on a block of rows with a time per
row: the resolvent and ``min_norm`` are the calls per row.  The constant weight was made a column ``(n, 1)`` — weight
``c_i`` for every coordinate of row ``i`` — so a block of ``n`` rows got wrong values (and other sizes a broadcast
error, then the engine's calls per row); generated operator #5 of the operator_laws stage is such an operator."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm


@pytest.mark.parametrize("B", [1, 2, 3, 5])
@pytest.mark.parametrize("c", [np.array([1.6, 0.53, 4.99]), 0.7, lambda t: np.array([1.0 + t, 0.5, 2.0 * t])])
def test_a_block_of_times_is_the_calls_per_row(c, B):
    op = vm.L1Subdifferential(c, 3)
    X = np.linspace(-4.0, 4.0, 3 * B).reshape(B, 3)
    ts = np.linspace(0.1, 0.9, B)
    lam = np.linspace(0.5, 2.0, B)
    assert op._accepts_times()
    assert np.array_equal(op.resolvent(X, 1.0, ts), np.array([op.resolvent(x, 1.0, t) for x, t in zip(X, ts)]))
    assert np.array_equal(op.resolvent(X, lam, ts), np.array([op.resolvent(x, l, t) for x, l, t in zip(X, lam, ts)]))
    assert np.array_equal(op.min_norm(X, ts), np.array([op.min_norm(x, t) for x, t in zip(X, ts)]))
