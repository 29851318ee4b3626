"""Issue 43 (branch units10): ``L1Subdifferential``'s one-point paths — ``value`` reading a constant weight's array
and a float64 point as they are, ``resolvent`` with one ``λ`` without ``_steps`` — give the numbers of the general
paths bit for bit: ``value`` against ``np.sum``'s definition on every input type, ``resolvent`` against the same
rows through a block of step sizes (``_steps``' path) and against soft thresholding's formula."""

from __future__ import annotations

import numpy as np
import pytest

from verimono.core.errors import InvalidProblem
from verimono.core.operators import L1Subdifferential


def _ops():
    return [L1Subdifferential(0.7, dim=3), L1Subdifferential([1.6023, 0.5318, 4.9881], dim=3),
            L1Subdifferential(lambda t: np.array([1.0 + t, 2.0 * t + 0.5, 0.3]), dim=3)]


def _points():
    rng = np.random.default_rng(3)
    pts = [rng.normal(size=3) * s for s in (1e-300, 1e-3, 1.0, 1e3, 1e200)]
    pts += [np.array([0.0, -0.0, 5e-324]), np.array([1, -2, 3]), [0.5, -1.5, 2.5],
            rng.normal(size=3).astype(np.float32), rng.normal(size=6)[::2]]
    return pts


@pytest.mark.parametrize("k", range(3))
def test_l1_value_is_the_sum_of_its_definition(k):
    op = _ops()[k]
    for x in _points():
        for t in (0.0, 0.25, 1.0):
            want = float(np.sum(np.asarray(op._c(t), dtype=float) * np.abs(np.asarray(x, dtype=float))))
            got = op.value(x, t)
            assert type(got) is float and np.float64(got).tobytes() == np.float64(want).tobytes()


@pytest.mark.parametrize("k", range(3))
def test_l1_resolvent_with_one_step_is_the_block_and_the_formula(k):
    op = _ops()[k]
    rng = np.random.default_rng(4)
    X = rng.normal(size=(16, 3)) * 3.0
    lams = np.exp(rng.uniform(-5.0, 3.0, 16))
    for t in (0.0, 0.5):
        block = op.resolvent(X, lams, t)
        one = np.array([op.resolvent(x, lam, t) for x, lam in zip(X, lams.tolist())])
        c = np.asarray(op._c(t), dtype=float)
        formula = np.array([np.sign(x) * np.maximum(np.abs(x) - lam * c, 0.0) for x, lam in zip(X, lams.tolist())])
        assert one.tobytes() == block.tobytes() == formula.tobytes()
    for bad in (0.0, -1.0, np.inf, np.nan):
        with pytest.raises(InvalidProblem):
            op.resolvent(X[0], bad)
