"""A study's exact solution on a grid (:func:`verimono.core.study_runs.exact_on`): one call of the reference's
vectorized twin ``exact.on_times`` when it has one, with the values of the per-node calls bit for bit."""

from __future__ import annotations

import numpy as np

from verimono.core.problem import Problem
from verimono.core.study_runs import exact_on
from verimono.reference import subdifferential


def test_t_norm_on_times_is_the_per_node_exact_solution_bit_for_bit():
    """Before and after the extinction time sqrt(2|x0|) (the clamp at 0), in dimensions 1, 3 and 10."""
    for x0, T in [((1.0,), 2.0), ((0.3, -0.2, 0.5), 1.5), (tuple(np.linspace(0.1, 1.0, 10) * 0.05), 1.0)]:
        p = subdifferential.t_norm(x0, T=T)
        t = np.linspace(0.0, T, 2001)
        per_node = np.array([np.asarray(p.exact(s), dtype=float) for s in t.tolist()])
        got = exact_on(p, t)
        assert got.shape == per_node.shape and np.array_equal(got.view(np.int64), per_node.view(np.int64))
        assert np.all(got[-1] == 0.0) and np.any(got[0] != 0.0)       # extinct at T, not at 0


def test_exact_on_calls_the_twin_once_and_without_one_every_node():
    calls = []

    def exact(t):
        calls.append(t)
        return np.array([1.0 - t])

    p = Problem(subdifferential.t_norm((1.0,)).operator, [1.0], 1.0, exact=exact)
    t = np.linspace(0.0, 1.0, 11)
    assert np.array_equal(exact_on(p, t)[:, 0], 1.0 - t) and len(calls) == 11
    exact.on_times = lambda ts: (calls.append("batch"), (1.0 - ts)[:, None])[1]
    assert np.array_equal(exact_on(p, t)[:, 0], 1.0 - t) and calls[11:] == ["batch"]
