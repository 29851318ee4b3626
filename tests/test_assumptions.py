"""check_assumptions: evidence for (A1), (A2), (A3), (LG), (YB) — passing where the paper's assumptions
hold, failing on a non-monotone operator, on a graph that jumps right after t, on understated φ/σ/θ, and
flagging (LG) for the log barrier and (YB) for moving sets (where the paper says they fail)."""

from __future__ import annotations

import numpy as np
import pytest

from verimono import Linear, Problem, operator_from_resolvent
from verimono.checks.assumptions import EVIDENCE, check_assumptions
from verimono.checks.sample_problems import sample_problem
from verimono.reference import get
from verimono.results import FAILED, PASSED

NAMES = ["assumption_A1", "assumption_A2", "assumption_A3", "assumption_LG", "assumption_YB"]


def _by(report):
    return {r.check: r for r in report}


def test_records_are_labelled_evidence():
    rep = check_assumptions(get("t|x| (n=1)"))
    assert [r.check for r in rep] == NAMES + ["assumptions_thm_main"] and rep.ok
    assert all(r.details.get("evidence") == EVIDENCE for r in rep)


@pytest.mark.parametrize("seed", range(8))
def test_stated_functions_of_sample_problems_survive(seed):
    rep = _by(check_assumptions(sample_problem(seed), seed=seed))
    for name in ("assumption_A1", "assumption_A2", "assumption_A3", "assumption_LG"):
        assert rep[name].status == PASSED, str(rep[name])


def test_non_monotone_operator_fails_A1():
    # F = -x/2 (not monotone): J_λ x = x/(1 - λ/2) for λ < 2
    op = operator_from_resolvent(lambda x, lam, t: np.asarray(x) / (1.0 - 0.5 * lam), 2, name="minus_half")
    rec = _by(check_assumptions(Problem(op, [0.5, 0.2], 1.0)))["assumption_A1"]
    assert rec.status == FAILED and rec.counterexample["inner"] < 0


def _scaled_identity(c):
    """``F(t, x) = c(t) x`` on R^2: maximal monotone for each t, dom F = R^2 (so (A3) holds with φ = 0)."""
    return Problem(Linear(lambda t: c(t) * np.eye(2)), [0.5, 0.2], 1.0)


@pytest.mark.parametrize("after", [lambda t: 2.0, lambda t: 2.0 + (t - 0.5)], ids=["constant", "converging"])
def test_graph_jumping_right_after_t_fails_A2(after):
    # c = 1 up to and including t = 0.5 (a sampled time), then 2 (+ (t - 0.5)): J_λ(0.5 + δ) p → p/(1 + 2λ)
    # ≠ J_λ(0.5) p = p/(1 + λ); "converging" reaches its limit only as δ ↓ 0 (a nonzero tail)
    rep = _by(check_assumptions(_scaled_identity(lambda t: 1.0 if t <= 0.5 else after(t))))
    rec = rep["assumption_A2"]
    assert rec.status == FAILED and rec.counterexample["t"] == 0.5, str(rec)
    c = rec.counterexample
    np.testing.assert_allclose(c["limit"], c["p"] / (1 + 2 * c["lam"]), rtol=1e-3)
    np.testing.assert_allclose(c["resolvent_at_t"], c["p"] / (1 + c["lam"]), rtol=1e-12)
    assert rep["assumption_A1"].status == PASSED and rep["assumption_A3"].status == PASSED


def test_right_continuous_jump_satisfies_A2():
    # the same jump with c(0.5) = 2: outer semicontinuous *from the right* (the paper's (A2)) — no evidence
    rec = _by(check_assumptions(_scaled_identity(lambda t: 1.0 if t < 0.5 else 2.0)))["assumption_A2"]
    assert rec.status == PASSED and rec.details["unsettled"] == 0 and rec.details["sequences"] == 6 * 13


def test_understated_phi_sigma_theta_are_contradicted():
    ball = get("translating ball")                          # moves at |v| = sqrt(1.25)
    rec = _by(check_assumptions(ball.replace(phi=lambda t: 0.5 * t)))["assumption_A3"]
    assert rec.status == FAILED and rec.counterexample["dist"] > 0
    tn = get("t|x| (n=1)")                                  # |F^0(t,x)| = t, |Y_λ(s+λ)| - |Y_λ(s)| ≤ λ
    rep = _by(check_assumptions(tn.replace(sigma=lambda t: 0.3 * t, theta=lambda t: 0.5 * t)))
    assert rep["assumption_LG"].status == FAILED and rep["assumption_YB"].status == FAILED


def test_stated_phi_of_moving_set_is_tight():
    rec = _by(check_assumptions(get("translating ball")))["assumption_A3"]
    assert rec.status == PASSED and 0.9 < rec.worst <= 1.0        # φ(t) = |v| t is attained
    speed = np.hypot(1.0, 0.5)                                      # sampled sup ≤ the true one
    assert 0.99 * speed <= rec.details["max_rate"] <= speed * (1 + 1e-9)


def test_paper_failures_are_flagged():
    # the raw evidence of each law (composite=False: thm_main would make the failing alternative an xfail)
    lg = _by(check_assumptions(get("x' = c/x from 0 (order 1/2)"), composite=False))["assumption_LG"]
    assert lg.status == FAILED and "evidence that (LG) fails" in lg.message     # |F^0| = c/x unbounded
    yb = _by(check_assumptions(get("moving box"), composite=False))["assumption_YB"]
    assert yb.status == FAILED and "YB" in yb.message                            # moving domain
    assert _by(check_assumptions(get("moving box")))["assumption_LG"].status == PASSED  # σ ≡ 0 for N_S


def test_static_operator_has_constant_theta_and_estimated_sigma():
    rep = _by(check_assumptions(get("linear x' = -Mx")))
    assert rep["assumption_YB"].details["theta_hat_slope"] <= 1e-6                # Prop. vi
    M = np.array([[1.0, 3.0], [-3.0, 0.5]])
    assert max(rep["assumption_LG"].details["sigma_hat"]) <= np.linalg.norm(M, 2) + 1e-9


def test_a_stated_theta_is_judged_on_YB_not_on_the_stronger_YB_prime():
    """F(t, x) = (1 + t)x with θ ≡ 0.  (YB): |Y_λ(s+λ, z)| = (1+s+λ)|z|/(1 + λ(1+s+λ)) ≤ (1+s)|z| = |F^0(s, z)|
    holds; (YB'), against |Y_λ(s, z)| = (1+s)|z|/(1 + λ(1+s)), does not.  θ ≡ 0 satisfies the paper's
    assumption and must not be reported contradicted (an audit found it was); the same θ against a
    faster-growing F(t, x) = (1 + 5t)x, where (YB) fails too, is."""
    import verimono as vm

    ok = vm.Problem(vm.Linear(lambda t: np.array([[1.0 + t]])), [1.0], 1.0, theta=lambda s: 0.0, name="(1+t)x")
    rec = check_assumptions(ok).by_check("assumption_YB")[0]
    assert rec.status == PASSED and rec.details["form"] == "YB", str(rec)
    bad = vm.Problem(vm.Linear(lambda t: np.array([[1.0 + 5.0 * t]])), [1.0], 1.0, theta=lambda s: 0.0,
                     name="(1+5t)x")
    assert check_assumptions(bad, composite=False).by_check("assumption_YB")[0].status == FAILED
