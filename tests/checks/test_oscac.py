"""sec:oscac: absolute continuity of t ↦ F(t,·) in Vladimirov's pseudo-distance (def:dis) implies (A2).

The implication is a proof, not a computation; what verimono can do is check both sides on the same
operators: on the translating ball (dis(F(s), F(t)) = d_H = |v||t − s|, AC) the sampled pseudo-distance
vanishes with |t − s| and ``assumption_A2`` passes; on a ball that jumps right after 0.45 the
pseudo-distance across the jump stays ≈ 3 however close the times (not continuous, the implication says
nothing) and ``assumption_A2`` fails there — consistent with the statement, as every operator must be.
(The proof's ``r(t) − r(t_ℓ)`` should read ``r(t_ℓ) − r(t)`` for t_ℓ ≥ t; harmless.)"""

from __future__ import annotations

import numpy as np

import verimono as vm
from verimono import Problem, pseudo_distance_lower_bound
from verimono.checks.assumptions import check_assumptions
from verimono.reference import get


def _dis(op, s, t, rng):
    P = rng.standard_normal((64, op.dim)) * 3.0
    return float(pseudo_distance_lower_bound(op, op, P, lams=(1e3, 1e-6), t1=s, t2=t))


def test_AC_in_the_pseudo_distance_and_A2_hold_together():
    p = get("translating ball")
    rng = np.random.default_rng(0)
    speed = np.hypot(1.0, 0.5)
    for delta in (1e-1, 1e-2, 1e-3):
        assert _dis(p.operator, 0.3, 0.3 + delta, rng) <= speed * delta * (1 + 1e-6)
    rec = {r.check: r for r in check_assumptions(p)}["assumption_A2"]
    assert rec.status == "passed", str(rec)


def test_a_jump_in_the_pseudo_distance_goes_with_an_A2_failure():
    centre = lambda t: np.array([3.0 if t > 0.45 else 0.0, 0.0])             # noqa: E731
    op = vm.NormalCone(vm.sets.Ball(centre, 1.0))
    rng = np.random.default_rng(0)
    for delta in (1e-2, 1e-6, 1e-12):
        assert _dis(op, 0.45, 0.45 + delta, rng) > 2.5
    rec = {r.check: r for r in check_assumptions(Problem(op, [0.0, 0.0], 1.0), composite=False)}["assumption_A2"]
    assert rec.status == "failed" and rec.counterexample["t"] == 0.45, str(rec)
