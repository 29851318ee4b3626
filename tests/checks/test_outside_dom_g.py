"""``J_λx`` outside ``dom g`` by the user's value function: a float32 projection onto the unit ball from ``|x|``
of 900 or 1e3 can land outside it by a few float32 ulps, which a strict indicator (``inf`` for any point
outside) rejects although the projection is exact to its precision — no sample of the law (issue 42: judged
at the subject's precision; it failed, with an explanation, before); a projection leaving the ball by more than
that round-off fails, and the record says the value function said so and gives J's round-off (issue 33)."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.checks import operator_laws, prox_laws  # noqa: F401 - the laws join the registry on import
from verimono.checks.engine.search import run_law


def ball_projection32(x, lam):
    """The projection onto the unit ball, computed in float32 (the prox of its indicator, for every λ)."""
    x = np.asarray(x, dtype=np.float32)
    n = np.linalg.norm(x)
    return x if n <= 1 else x / n


def strict_indicator(x):
    return 0.0 if float(np.linalg.norm(np.asarray(x, dtype=np.float64))) <= 1.0 else np.inf


def _outside_sample(radius: float, dim: int):
    """A point of norm ``radius`` whose float32 projection lands outside the unit ball (searched along a few
    directions: which do depends on round-off)."""
    rng = np.random.default_rng(int(radius) * 31 + dim)
    for _ in range(200):
        d = rng.standard_normal(dim)
        x = radius * d / np.linalg.norm(d)
        if strict_indicator(ball_projection32(x, 0.5)) == np.inf:
            return x
    pytest.skip(f"no direction found whose float32 projection from |x| = {radius} leaves the ball")


@pytest.mark.parametrize("radius, dim", [(900.0, 3), (1e3, 2), (1e3, 5)])
def test_a_projection_outside_by_its_round_off_is_no_sample(radius, dim):
    op = vm.operator_from_prox(ball_projection32, value=strict_indicator, shape=dim, name="ball32")
    x = _outside_sample(radius, dim)
    sample = {"x1": x.tolist(), "x2": (0.5 * x).tolist(), "lam": 0.5, "mu": 0.25, "nu": 1.0, "t": 0.0}
    rec = run_law("prox_inequality", op, sample=sample)
    assert rec.status == "skipped" and "only by round-off" in rec.message, rec


@pytest.mark.parametrize("radius, dim", [(900.0, 3), (1e3, 2), (1e3, 5)])
def test_a_law_failed_by_the_value_function_says_so_and_gives_js_roundoff(radius, dim):
    # the projection onto the ball of radius 1.01: 0.01 outside, five times the 16 ulps of round-off at |x| = 1e3
    op = vm.operator_from_prox(lambda x, lam: 1.01 * ball_projection32(np.asarray(x) / 1.01, lam),
                               value=strict_indicator, shape=dim, name="ball32 of radius 1.01")
    x = _outside_sample(radius, dim)
    sample = {"x1": x.tolist(), "x2": (0.5 * x).tolist(), "lam": 0.5, "mu": 0.25, "nu": 1.0, "t": 0.0}
    rec = run_law("prox_inequality", op, sample=sample)
    assert rec.status == "failed", rec
    assert "the value function says p = J_λx lies outside dom g" in rec.message
    cx = rec.counterexample
    assert cx["outside_dom_g"] and cx["precision"] == "float32"
    eps32 = float(np.finfo(np.float32).eps)
    # the round-off of J at that point: eps32 (1 + |x|), which the projection exceeded
    assert cx["resolvent_roundoff"] == pytest.approx(eps32 * (1 + radius), rel=1e-6)
    p = np.asarray(cx["p"])
    assert np.linalg.norm(p) - 1.0 > 16 * cx["resolvent_roundoff"]


def _singleton_at_one_step():
    """``g`` the indicator of ``{c}``, whose prox ``c`` answers only at ``λ = 1/2`` (it raises at every other step):
    at ``x1, x2 ≠ c`` every candidate ``z`` of the prox inequality but ``p`` itself has ``g(z) = +∞``."""
    c = np.array([1.0, 2.0])

    def prox(x, lam, t=0.0):
        if lam != 0.5:
            raise ValueError("answers at λ = 1/2 only")
        return c.copy()
    return vm.operator_from_prox(prox, shape=2, value=lambda z, t=0.0: 0.0 if np.array_equal(z, c) else np.inf,
                                 name="singleton at one step")


def test_prox_inequality_with_no_candidate_in_dom_g_tested_nothing():
    """Every candidate ``z`` outside ``dom g``: the inequality holds trivially at each, so the sample is inconclusive
    (the whole record then skipped: nothing was evaluated), never a pass — and never the failure it was, blind set
    10's `log_barrier_prox_cancellation` at thorough: the law returned no outcome and the search's
    ``AttributeError`` was counted as the subject's."""
    from verimono.checks.engine.samples import Sample
    s = Sample(np.array([3.0, 3.0]), np.array([4.0, 4.0]), lam=0.5, mu=0.3, nu=0.7, t=0.0)
    rec = run_law("prox_inequality", _singleton_at_one_step(), sample=s)
    assert rec.status == "skipped" and "no candidate z with g(z) < ∞" in rec.message, rec.message


def test_a_law_answering_no_outcome_is_a_limit_of_the_harness(monkeypatch):
    """A law of verimono's own that answers no :class:`Outcome` is verimono's fault: the sample is inconclusive and
    counted as a limit of the harness, never the subject's failure nor a pass."""
    from verimono.checks.core import REGISTRY
    from verimono.core.sets import Ball
    from verimono.checks.engine.batches import VECTORISED
    import dataclasses

    decl = REGISTRY["operator"]["resolvent_nonexpansive"]
    monkeypatch.setitem(REGISTRY["operator"], "resolvent_nonexpansive",
                        dataclasses.replace(decl, evaluate=lambda op, s: None))
    monkeypatch.delitem(VECTORISED, "resolvent_nonexpansive")      # every sample through the law's evaluator
    rec = run_law("resolvent_nonexpansive", vm.NormalCone(Ball(np.zeros(2), 1.0)), seed=0, examples=5)
    assert rec.status in ("undecided", "skipped"), rec
    # every sample the law's evaluator met is a limit of the harness (the scale phase's far points are not judged)
    assert rec.details["harness_limited"] >= rec.details["evaluations"] - 2 > 50, rec.details
