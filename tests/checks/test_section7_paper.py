"""Issue 24, Section 7: a "for all t" hypothesis is checked at every t, and the linear-case (A2) error.

* ``lcs.rel_int`` (``thm: linear case`` iii) minimises its margin over ``t``: ``C = 0, D = 0`` and
  ``v = |t − τ|`` fail exactly at ``τ`` (the 64 samples alone reported a margin of 0.0036 at τ = 0.4567);
* ``thm: linear case`` claims (A2) under item iv, "v bounded": false.  ``n = m = 1``, ``A = 0``,
  ``B = C = D = 1``, ``v = 𝟙(t > ½)``: items i–vi hold, ``H(t, x) = min(x + v(t), 0)``, and (A2) fails at ½.
"""

from __future__ import annotations

import numpy as np
import pytest

from verimono import Problem
from verimono.checks.assumptions import check_assumptions
from verimono.lcs import Complementarity, LinearRelationSystem, check_hypotheses
from verimono.records.results import FAILED, PASSED, SKIPPED


def _touching(tau, lift=0.0):
    return LinearRelationSystem([[0.0]], [[1.0]], [[0.0]], [[0.0]], Complementarity(),
                                v=lambda t: np.array([abs(t - tau) + lift]))


def _rel_int(system, T=1.0):
    """The ``lcs.rel_int`` record as :func:`check_hypotheses` evaluates it (its evaluator, default samples and
    seed), without the battery's other items: the same record but ``duration`` (compared field by field on
    τ = 0.4567 and 0.5), ≈ 0.8 of the battery's 1.1 s CPU here."""
    from verimono.checks.core import laws_of

    return laws_of("system", battery=True)["lcs.rel_int"].public(system, T, samples=64, seed=0)


@pytest.mark.parametrize("tau", [0.4567, 0.5, 0.123456789])
def test_rel_int_margin_touching_zero_between_samples_fails(tau):
    r = _rel_int(_touching(tau))
    assert r.status == FAILED, r.message
    assert r.counterexample["t"] == pytest.approx(tau, abs=1e-9) and r.counterexample["margin"] <= 1e-12
    assert min(r.details["margins"]) > 1e-3           # the samples alone did not see it


def test_rel_int_margin_bounded_away_from_zero_passes():
    r = _rel_int(_touching(0.4567, lift=1e-3))
    assert r.status == PASSED and r.details["min_search"]["sup"] == pytest.approx(-1e-3, abs=1e-9), r.message


def _indicator_system():
    return LinearRelationSystem([[0.0]], [[1.0]], [[1.0]], [[1.0]], Complementarity(),
                                v=lambda t: np.array([1.0 if t > 0.5 else 0.0]))


def test_linear_case_A2_is_false_under_bounded_v():
    """Items i–vi hold (i passive, ii the complementarity cone, iii ``D = 1``: ``im(𝓟 + D) = R``, iv
    ``|v| ≤ 1``, v ``θ ≡ 0`` — the domain is ``R`` at every t —, vi ``α = 1``) yet (A2) fails at ½:
    ``(−½, 0) ∈ graph H(t_ℓ)`` for ``t_ℓ ↓ ½`` while ``H(½, −½) = −½``.  verimono derives ``lcs.A2`` only with
    ``v ∈ AC`` (``lcs.v_ac``), which fails here, so it is not established; ``assumption_A2`` on ``H`` fails."""
    sys = _indicator_system()
    rep = check_hypotheses(sys, 1.0)
    for name in ("lcs.passivity", "lcs.relation_maxmon", "lcs.rel_int", "lcs.v_bounded", "lcs.least_norm_growth"):
        assert rep.by_check(name)[0].status == PASSED, name
    assert rep.by_check("lcs.v_ac")[0].status == FAILED
    (a2,) = rep.by_check("lcs.A2")
    assert a2.status == SKIPPED and "lcs.v_ac (failed)" in a2.message
    H = sys.operator()
    np.testing.assert_allclose(H.min_norm(np.array([-0.5]), 0.5), [-0.5])
    np.testing.assert_allclose(H.min_norm(np.array([-0.5]), 0.5 + 1e-9), [0.0])
    rec = {r.check: r for r in check_assumptions(Problem(H, [-0.5], 1.0), composite=False)}["assumption_A2"]
    assert rec.status == FAILED and rec.counterexample["t"] == 0.5, str(rec)
