"""Proposition p:lcp2 v, |z*(q)| ≤ α|q|: the explicit α = 1/λ_min((D + Dᵀ)/2) where the symmetric part is
positive definite, an estimate from below (and said so) where it is singular."""

from __future__ import annotations

import numpy as np
import pytest

from verimono.lcs import Complementarity, LinearRelationSystem, check_hypotheses, solve_lcp
from verimono.lcs.lcp import lcp_alpha
from zoo_estimators import alpha_min_max_slip


def _system(D):
    m = D.shape[0]
    return LinearRelationSystem(-np.eye(m), np.eye(m), np.eye(m), D, Complementarity(), v=np.ones(m), name="pd")


def test_explicit_alpha_bounds_every_solution_and_is_attained():
    """D = [[1, 1], [−1, 4]] (S = diag(1, 4)): α = 1 bounds every solution; D = diag(1, 4) attains it:
    q = (−1, 0) gives z = (1, 0), w = (0, 0), |z|/|q| = 1."""
    D = np.array([[1.0, 1.0], [-1.0, 4.0]])
    assert lcp_alpha(D) == pytest.approx(1.0)
    rng = np.random.default_rng(0)
    for _ in range(200):                      # every solution, not only the sampled unit ones
        q = rng.normal(size=2) * 10 ** rng.uniform(-3, 3)
        assert np.linalg.norm(solve_lcp(D, q)) <= lcp_alpha(D) * np.linalg.norm(q) * (1 + 1e-9)
    D = np.diag([1.0, 4.0])
    assert np.allclose(solve_lcp(D, np.array([-1.0, 0.0])), [1.0, 0.0])
    (r,) = check_hypotheses(_system(D), 1.0).by_check("lcs.least_norm_growth")
    assert r.status == "passed" and r.details["alpha"] == pytest.approx(1.0), str(r)
    assert r.details["alpha_kind"].startswith("explicit") and 0.9 < r.details["alpha_sampled"] <= 1.0 + 1e-9


def test_a_wrong_alpha_is_caught_with_its_counterexample(monkeypatch):
    """Seen failing: 1/λ_max instead of 1/λ_min (α = 1/4 here) is exceeded by a sampled q.  The old record
    had no α to check (it reported the sampled maximum as α)."""
    from verimono.checks import section7 as hypotheses

    monkeypatch.setattr(hypotheses, "lcp_alpha", alpha_min_max_slip)
    (r,) = check_hypotheses(_system(np.diag([1.0, 4.0])), 1.0).by_check("lcs.least_norm_growth")
    assert r.status == "failed" and "exceeds α" in r.message, str(r)
    c = r.counterexample
    assert c["alpha"] == pytest.approx(0.25) and c["|z|/|q|"] > 0.25
    assert np.linalg.norm(c["z"]) == pytest.approx(c["|z|/|q|"] * np.linalg.norm(c["q"]))


def test_singular_symmetric_part_gets_an_honest_estimate():
    """The paper's Example, D = [[0, 1], [−1, 0]] (S = 0): no explicit α; the sampled sup (1, attained at
    q = (−1, 0)) is reported as an estimate from below."""
    assert lcp_alpha(np.array([[0.0, 1.0], [-1.0, 0.0]])) is None
    from verimono.reference import lcs_example as E

    (r,) = check_hypotheses(E.example_system(lambda t: np.array([-t, 0.0])), T=2.0).by_check("lcs.least_norm_growth")
    assert r.status == "passed" and "lower estimate" in r.details["alpha_kind"] and "from below" in r.message
