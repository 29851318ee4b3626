"""The paper's Example (v = (−t, 0): A = 0, B = (0 1), C = (0 1)ᵀ, D = ((0 1), (−1 0))) has the resolvent in closed
form: the one-step LCP w = (−t + z₂, x − z₁ + λz₂) gives z = (x + λt, t) for x ≥ −λt and z = (0, −x/λ) below, so
J_λ(x) = x + λz₂ = max(x + λt, 0).  At tiny λ the second multiplier is huge (|x|/λ: 1.4e6 at x = −5e-7, λ = 3.6e-13)
and M = D + λCB spans 13 decades: the least-norm QP over SOL(q, M) was declared infeasible (HiGHS drops matrix
entries below 1e-9) and the resolvent raised InfeasibleStep — a false alarm of `yosida_nonincreasing` on the
reference operator, found by a search at ci seed 3 (branch members7).  Seen failing before the fix in lcs/lcp.py."""

from __future__ import annotations

import numpy as np
import pytest

from verimono.lcs.lcp import solve_lcp
from verimono.reference import get


@pytest.mark.parametrize("lam", [3.6370365339207447e-13, 1e-15, 1e-11, 1e-7, 1e-3, 1.0, 30.0])
def test_the_examples_resolvent_is_max_x_plus_lam_t_and_zero_at_every_step_size(lam):
    shared = get("Example ex, v = (−t, 0)").operator      # its stepper warmed by the calls before
    for t in (0.7204323649772348, 0.0, 1.3, 2.0):
        for x in (-5e-7, -5.004142472482779e-07, -1e-3, -2.0, -lam * t, 0.0, 1e-7, 0.5, 3.0):
            fresh = get("Example ex, v = (−t, 0)").operator   # its first call
            want = max(x + lam * t, 0.0)
            for op in (fresh, shared):
                got = op.resolvent(np.array([x]), lam, t)
                assert abs(got[0] - want) <= 1e-9 * (1.0 + abs(x)), (lam, t, x, got, want)


def test_a_least_norm_qp_that_fails_numerically_keeps_the_verified_solution():
    """SOL(q, M) ∋ z̄, so the selection QP's "no point" is its numerical limit: the verified z̄ comes back, not
    certified the least-norm one (``LCPResult.least_norm`` False), with the reason."""
    lam, t, x = 3.6370365339207447e-13, 0.7204323649772348, -5e-7
    M = np.array([[0.0, 1.0], [-1.0, lam]])
    q = np.array([-t, x])
    r = solve_lcp(M, q, info=True)
    assert np.all(r.z >= 0) and np.all(r.w >= -1e-9 * np.abs(q).max())
    assert abs(r.z[0]) <= 1e-6 and r.z[1] == pytest.approx(-x / lam, rel=1e-6)
    assert r.residual <= 1e-8 * r.scale


# H itself at extreme data (branch probe5): with v = (−t, 0) the multipliers of (x, −t) are z = (x, t) for x > 0,
# unique, so H(t, x) = {−t} and H⁰ = −max(t, 0); dom H(t) = [0, ∞).  Where t/x is below RTOL (t = 3.6e-13 at
# x = 1e-3, t = 1e-9 at x = 1, x = 1e8 at t = 0.5) the uniqueness certificate cannot see z₂ = t > 0 at RTOL·|x|,
# and the selection QP over SOL — a wedge t/x wide in angle — is verified by no back-end: min_norm raised
# UnverifiedSolution (the min_norm laws undecided there).  Seen failing before the fix in lcs/system.py.
@pytest.mark.parametrize("x,t", [(1e-3, 3.6e-13), (1.0, 1e-9), (1e8, 0.5), (1e8, 2.0), (1.0, 1e-15), (1e3, 1e-8),
                                 (0.0, 0.5), (0.0, 1e-13), (1e-15, 1.3), (2.0, 0.0), (1e8, 1e8)])
def test_the_examples_least_norm_selection_is_minus_t_at_every_scale(x, t):
    op = get("Example ex, v = (−t, 0)").operator
    want = -max(t, 0.0)
    got = op.min_norm(np.array([x]), t)
    assert abs(got[0] - want) <= 1e-9 * (1.0 + abs(x) + abs(t)), (x, t, got, want)
    assert op.contains(np.array([x]), got, t)
    assert abs(op.project_domain(np.array([-x]), t)[0] - 0.0) <= 1e-9 * (1.0 + abs(x))


# The resolvent where x + λt is tiny against the multiplier −x/λ (branch probe5): x = −1e-9 at λ = 1e-15, t = 2
# has z = (0, 1e6) with M = [[0, 1], [−1, 1e-15]] — Lemke ends on a ray and the phase-1 QP is not verified, so the
# LCP raised UnverifiedSolution although its 2×2 pieces hold the verified point (z₂ = −x/λ); likewise λ = 1e8 at
# t = 1e-12, x = −1e-9 (J = 1e-4 − 1e-9) and t = 2, x = −1e3.  Seen failing before the fix in lcs/lcp.py.
@pytest.mark.parametrize("lam,t,x", [(1e-15, 2.0, -1e-9), (3.6e-13, 2.0, -1e-9), (1e7, 1e-12, -1e-9),
                                     (1e7, 2.0, -1e3), (1e7, 0.7, -1e3), (1e-15, 0.7, -1e-9)])
def test_the_examples_resolvent_where_lemke_ends_on_a_ray(lam, t, x):
    want = max(x + lam * t, 0.0)
    for op in (get("Example ex, v = (−t, 0)").operator,):
        got = op.resolvent(np.array([x]), lam, t)
        assert abs(got[0] - want) <= 1e-8 * (1.0 + abs(x) + lam * t), (lam, t, x, got, want)
