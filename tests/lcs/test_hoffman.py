"""hoffman_bound (e:hoffman, used in the proof of e: linear case-comp): the Hoffman constant of
verimono.lcs.hoffman bounds dist(x, 𝓡) by the residual on sampled polyhedra, and wrong constants fail."""

from __future__ import annotations

import numpy as np
import pytest

from verimono.checks.hoffman import check_hoffman
from verimono.lcs.hoffman import hoffman_constant
from zoo_estimators import hoffman_sigma_max, hoffman_without_equalities


@pytest.mark.parametrize("seed", range(3))
def test_hoffman_constant_bounds_the_distance(seed):
    rec = check_hoffman(seed=seed)
    assert rec.status == "passed" and rec.worst <= 1.0, str(rec)


def test_the_wedge_needs_a_large_constant():
    # 0 ≤ ζ_2 ≤ ε ζ_1: the two rows are nearly parallel (σ_min ≈ ε/√2), so α ≈ √2/ε
    Q = np.array([[0.0, -1.0], [-0.05, 1.0]])
    assert hoffman_constant(Q) > 10.0


@pytest.mark.parametrize("est", [hoffman_sigma_max, hoffman_without_equalities])
def test_wrong_constants_fail(est):
    rec = check_hoffman(est, seed=0)
    assert rec.status == "failed" and rec.counterexample["dist"] > rec.counterexample["alpha"] * rec.counterexample["residual"], str(rec)
    assert "e:hoffman" in rec.message
