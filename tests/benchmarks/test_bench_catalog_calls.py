"""Issue 43 item 1/3: the catalog's own cost per one-point call (what a law pays per sample on ∂|·|, the ball, the
half-space), timed by pytest-benchmark: ``pytest -m timing --benchmark-enable tests/benchmarks/test_bench_catalog_calls.py``.

Each call's result is checked against its closed form (block soft thresholding, the ball's radial projection, the
half-space's projection along its normal), so a fast wrong member fails here too.  Compare branches with
``--benchmark-compare``; docs/speed.md (branch ``catfast``) has the interleaved figures against b19eba1.
"""

from __future__ import annotations

import numpy as np
import pytest

from verimono.core.operators import NormalCone, NormSubdifferential
from verimono.core.sets import Ball, HalfSpace

_X = np.array([0.6, -0.8, 2.4])          # |x| = 2.6


def _tc(t):
    return t


_CASES = {
    # J_λ x = max(1 - λc/|x|, 0) x with c = t = 0.5, λ = 0.4: the factor 1 - 0.2/2.6
    "norm_resolvent": (lambda: NormSubdifferential(_tc, dim=3).resolvent, (_X, 0.4, 0.5), (1 - 0.2 / 2.6) * _X),
    # g(t, x) = t|x|
    "norm_value": (lambda: NormSubdifferential(_tc, dim=3).value, (_X, 0.5), 0.5 * 2.6),
    # F^0(t, x) = c x/|x|
    "norm_min_norm": (lambda: NormSubdifferential(_tc, dim=3).min_norm, (_X, 0.5), 0.5 * _X / 2.6),
    # proj onto the ball of radius 1.3 about 0: x/2
    "ball_resolvent": (lambda: NormalCone(Ball(np.zeros(3), 1.3)).resolvent, (_X, 0.4, 0.5), 0.5 * _X),
    # proj onto {x3 ≤ 1}: the third coordinate cut to 1
    "halfspace_resolvent": (lambda: NormalCone(HalfSpace([0.0, 0.0, 1.0], 1.0)).resolvent, (_X, 0.4, 0.5),
                            np.array([0.6, -0.8, 1.0])),
}


@pytest.mark.parametrize("name", sorted(_CASES))
def test_catalog_one_point_call(benchmark, name):
    make, args, expected = _CASES[name]
    member = make()
    got = benchmark(member, *args)
    np.testing.assert_allclose(got, expected, rtol=4 * np.finfo(float).eps, atol=0.0)
