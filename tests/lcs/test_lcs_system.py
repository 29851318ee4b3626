"""LinearRelationSystem: H as an Operator, its resolvent = the one-step problem, errors on bad input."""

from __future__ import annotations

import numpy as np
import pytest

from verimono import (InfeasibleStep, InvalidProblem, NormalCone, NotMonotone, operator_from_resolvent, solve,
                      uniform_grid)
from verimono.lcs import Complementarity, LinearRelationSystem, OperatorRelation, Relay, check_hypotheses
from verimono.core.sets import Box


def random_passive(rng, n=3, m=2):
    """Passive with K = I: A + Aᵀ ⪯ 0, C = Bᵀ, D + Dᵀ ⪰ 0 (Q(I) = blockdiag(A + Aᵀ, −(D + Dᵀ)))."""
    S = rng.normal(size=(n, n))
    A = (S - S.T) - 0.3 * np.diag(rng.uniform(size=n))
    B = rng.normal(size=(n, m))
    R = rng.normal(size=(1, m))
    Dk = rng.normal(size=(m, m))
    D = R.T @ R + (Dk - Dk.T)
    return A, B, B.T.copy(), D


def test_theta_one_is_the_proximal_scheme_on_H():
    rng = np.random.default_rng(1)
    A, B, C, D = random_passive(rng)
    sys = LinearRelationSystem(A, B, C, D, Complementarity(), v=lambda t: np.array([np.sin(t), -0.5]))
    t = uniform_grid(1.0, steps=50)
    x0 = [1.0, -0.5, 0.3]
    tr = sys.simulate(x0, t)
    ref = solve(sys.problem(x0, 1.0), t)
    np.testing.assert_allclose(tr.x, ref.x, rtol=0, atol=1e-12)
    # (z, w) of every step are complementary and reproduce the state update
    z, w = tr.extras["z"], tr.extras["w"]
    assert z.min() >= 0 and w.min() >= -1e-10 and np.abs(np.sum(z * w, 1)).max() <= 1e-10
    h = 1 / 50
    np.testing.assert_allclose((tr.x[1:] - tr.x[:-1]) / h, tr.x[1:] @ A.T + z @ B.T, atol=1e-9)


def test_operator_laws_on_random_passive_systems():
    rng = np.random.default_rng(2)
    for _ in range(5):
        A, B, C, D = random_passive(rng)
        H = LinearRelationSystem(A, B, C, D, Complementarity(), v=rng.normal(size=2)).operator()
        assert check_hypotheses(H.system, 1.0).by_check("lcs.passivity")[0].status == "passed"
        X = rng.normal(size=(12, 3)) * 2
        for lam in (0.1, 1.0):
            J = np.array([H.resolvent(x, lam) for x in X])
            Y = (X - J) / lam
            for i in range(len(X)):
                assert H.contains(J[i], Y[i], tol=1e-7)        # Y_λ x ∈ H(J_λ x)
                hn = H.min_norm(J[i])
                assert np.linalg.norm(hn) <= np.linalg.norm(Y[i]) + 1e-7   # |H^0| ≤ |y| for y ∈ H
                for j in range(i):                             # firm nonexpansiveness (monotone H)
                    d = J[i] - J[j]
                    assert d @ d <= d @ (X[i] - X[j]) + 1e-9 * (1 + np.abs(X).max())


def test_generic_operator_relation_matches_relay():
    sysR = LinearRelationSystem(np.zeros((2, 2)), 2 * np.eye(2), np.eye(2), np.zeros((2, 2)), Relay())
    # Relay −w ∈ N_[−1,1](z) is 𝓜 = N_[−1,1] as (−z, w) ∈ graph 𝓜
    sysO = LinearRelationSystem(np.zeros((2, 2)), 2 * np.eye(2), np.eye(2), np.zeros((2, 2)),
                                NormalCone(Box([-1, -1], [1, 1])))
    assert isinstance(sysO.relation, OperatorRelation)
    t = np.arange(301) * 1e-3
    a, b = sysR.simulate([1, -1], t, theta=0.5), sysO.simulate([1, -1], t, theta=0.5)
    np.testing.assert_allclose(a.x, b.x, atol=1e-8)


def test_operator_relation_refuses_non_finite_one_step_data():
    """A NaN in the one-step problem is named at once, not iterated on by the splitting to its limit."""
    rel = OperatorRelation(NormalCone(Box([-1, -1], [1, 1])))
    assert np.all(np.isfinite(rel.solve(np.eye(2), np.array([0.5, 3.0])).z))
    for M, q in ((np.eye(2), np.array([np.nan, 1.0])), (np.array([[1.0, np.inf], [0.0, 1.0]]), np.ones(2))):
        with pytest.raises(InvalidProblem, match="not finite"):
            rel.solve(M, q)


def test_bad_input_and_non_monotone_relations_are_typed():
    with pytest.raises(InvalidProblem, match="B must have n = 2 rows"):
        LinearRelationSystem(np.zeros((2, 2)), np.ones((3, 1)), np.ones((1, 2)), [[0]], Complementarity())
    with pytest.raises(InvalidProblem, match="D must have shape"):
        LinearRelationSystem(np.zeros((2, 2)), np.ones((2, 1)), np.ones((1, 2)), np.eye(2), Complementarity())
    with pytest.raises(InvalidProblem, match="finite"):
        LinearRelationSystem([[np.inf]], [[1]], [[1]], [[0]], Complementarity())
    with pytest.raises(InvalidProblem, match="relation must be"):
        LinearRelationSystem([[0]], [[1]], [[1]], [[0]], "relay")
    with pytest.raises(NotMonotone, match="lower .* exceeds upper"):
        Relay(lower=1, upper=-1)
    expanding = operator_from_resolvent(lambda x, lam, t: 2.0 * np.asarray(x), 1, name="expanding")
    with pytest.raises(NotMonotone, match="not firmly nonexpansive"):
        LinearRelationSystem([[0]], [[1]], [[1]], [[0]], expanding)
    sys = LinearRelationSystem([[0]], [[1]], [[1]], [[0]], Complementarity())
    with pytest.raises(InvalidProblem, match="x0 must be"):
        sys.simulate([1.0, 2.0], [0, 1])


def test_infeasible_step_and_failing_hypothesis():
    # w = 0·x + 0·z − 1 ≥ 0 is impossible: LCP(−1, 0) is infeasible, and im C ∩ ri(im(𝓟 + D) − v) = ∅
    sys = LinearRelationSystem([[0.0]], [[1.0]], [[0.0]], [[0.0]], Complementarity(), v=[-1.0])
    with pytest.raises(InfeasibleStep, match="q ∉ Q_M"):
        sys.simulate([0.0], [0.0, 0.1])
    rep = check_hypotheses(sys, 1.0)
    assert rep.by_check("lcs.rel_int")[0].status == "failed"
    assert rep.by_check("lcs.A1")[0].status == "skipped"


def test_non_passive_system_fails_the_check():
    sys = LinearRelationSystem([[1.0]], [[1.0]], [[1.0]], [[0.0]], Complementarity())
    rep = check_hypotheses(sys, 1.0)
    assert rep.by_check("lcs.passivity")[0].status == "failed" and not rep.ok
    assert all(r.status == "skipped" for r in rep.by_check("lcs.A1"))


@pytest.mark.parametrize("T", [1e-6, 1.0, 1e4])
def test_v_ac_is_invariant_under_a_change_of_time_scale(T):
    """v(t) = V(t/T) on [0, T]: a jump of V at 0.3 is found at 0.3 T, a smooth V passes, at every T (the
    bisection floor and the grid are relative to T)."""
    def record(V):
        sys = LinearRelationSystem([[-1.0]], [[1.0]], [[1.0]], [[1.0]], Complementarity(),
                                   v=lambda t: np.array([V(t / T)]))
        return check_hypotheses(sys, T).by_check("lcs.v_ac")[0]

    jump = record(lambda s: 1.0 if s >= 0.3 else 0.0)
    assert jump.status == "failed" and jump.counterexample["t"] == pytest.approx(0.3 * T, rel=1e-9)
    assert record(lambda s: np.sin(6 * s)).status == "passed"


def test_least_norm_growth_on_random_passive_systems():
    """Proposition p:lcp2 iv–v on D = RᵀR + skew (ker(D + Dᵀ) ≠ {0}, so SOL(q, D) need not be a singleton):
    homogeneous and least-norm on every sample; a bounded box relation needs no sampling."""
    rng = np.random.default_rng(5)
    for _ in range(3):
        A, B, C, D = random_passive(rng)
        sys = LinearRelationSystem(A, B, C, D, Complementarity(), v=rng.normal(size=2))
        (r,) = check_hypotheses(sys, 1.0, samples=32).by_check("lcs.least_norm_growth")
        assert r.status == "passed" and r.worst <= r.bound and r.details["least_norm_checked"] == 32
        assert 0 < r.details["alpha"] < np.inf
    (r,) = check_hypotheses(LinearRelationSystem([[-1.0]], [[1.0]], [[1.0]], [[1.0]], Relay()), 1.0
                            ).by_check("lcs.least_norm_growth")
    assert r.status == "passed" and "exact" in r.message


def test_membership_with_a_negligible_entry_in_D():
    """ẋ₂ = z₁, w = (x₂ + z₁/2 + 1, 1.4e-37 z₂ + 1): at x = 0, η = (1, 1) > 0 gives z = 0, so 0 ∈ H(0) and
    H^0(0) = 0.  The 1.4e-37 entry once made the multiplier selection return z = (-0.67, 0) and contains
    answer False (found by the Section 7 operator property of properties/laws_operators.py)."""
    D = np.array([[0.5, 0.0], [0.0, 1.4411277378133533e-37]])
    S = LinearRelationSystem(np.zeros((2, 2)), [[0.0, 0.0], [1.0, 0.0]], [[0.0, 1.0], [0.0, 0.0]], D,
                             Complementarity(), v=[1.0, 1.0])
    H = S.operator()
    assert H.contains(np.zeros(2), np.zeros(2)) and np.allclose(H.min_norm(np.zeros(2)), 0.0, atol=1e-14)
    assert not H.contains(np.zeros(2), np.array([0.0, 0.5]))


def test_membership_within_rounding_of_the_edge_of_dom_H():
    """The Example's H(0,·) = N_[0,∞): J_λ(-1.25) rounds to 2.2e-16 (not 0) and Y_λ = -0.28 ∈ H(0, 0) =
    (-∞, 0] but ∉ H(0, 2.2e-16) = {0}.  The pair is 2.2e-16 from the graph point (0, -0.28), so contains must
    accept it (its contract: a graph point within tol in each coordinate) — a 20-seed sweep of the operator
    laws found yosida_in_graph failing here — while pairs far from the graph are still rejected."""
    from verimono.checks.operator_laws import check_yosida_in_graph
    from verimono.checks.engine.samples import Sample
    from verimono.reference.lcs_example import ramp_problem

    H = ramp_problem().operator
    lam = 4.4646433849248
    J = H.resolvent(np.array([-1.25]), lam, 0.0)
    assert 0.0 < J[0] <= 1e-15                                               # the rounding is real
    assert H.contains(J, (np.array([-1.25]) - J) / lam, 0.0)
    assert not H.contains(np.array([1.0]), np.array([-0.28]), 0.0)          # H(0, 1) = {0}
    assert not H.contains(np.array([-1e-3]), np.array([-0.28]), 0.0)        # outside dom H(0,·) = [0, ∞)
    assert not H.contains(np.array([2.2e-16]), np.array([0.28]), 0.0)       # H(0, 0) = (-∞, 0]
    s = Sample(np.array([-1.25]), np.zeros(1), lam, 1.0, 1.0, 0.0)
    assert check_yosida_in_graph(H, sample=s).status == "passed"


def test_a_new_step_size_starts_from_the_last_active_pattern_and_a_wrong_guess_is_never_taken():
    """The operator's resolvent at a new λ tries the active pattern of the previous step size first (every
    random partition asks for a new λ per step): verified for the new M, so the answers are the closed
    form's (paper Example ex: J = max(x + λ max(−v1, 0), −v2)); and a stepper seeded with a wrong pattern
    still answers right (the pattern fails its sign checks and the full solve decides)."""
    from verimono.reference.lcs_example import closed_form_resolvent, example_system

    from verimono.lcs.relations import _BoxStepper

    op = example_system(lambda t: np.array([-t, 0.0])).operator()
    lams = 0.01 * (1.0 + np.random.default_rng(0).random(15))     # 15 kept: none forgotten
    for k, lam in enumerate(lams):
        t, x = 0.05 * k, np.array([0.3 + 0.01 * k])
        assert op.resolvent(x, lam, t) == pytest.approx(closed_form_resolvent(x, lam, -t, 0.0), abs=1e-14)
    solves = sum(sm.step.full_solves for sm in op._mats.values())
    assert len(op._mats) == 15 and solves <= 2  # the first λ and a change of pattern solved, not all 15
    rel = Complementarity()
    M = np.array([[2.0, 1.0], [-1.0, 0.5]])
    right = rel.stepper(M)
    wrong = rel.stepper(M)
    other = rel.stepper(M)
    other.last = np.array([1, 1], dtype=np.int8).tobytes()     # both strictly inside: wrong for this q
    wrong.warm_from(other)
    assert isinstance(wrong, _BoxStepper) and wrong.last == other.last
    q = np.array([1.0, 2.0])                    # q ≥ 0: z = 0 is the solution
    assert np.array_equal(wrong(q)[0], right(q)[0]) and np.all(wrong(q)[0] == 0.0)
    assert wrong.full_solves == 1
