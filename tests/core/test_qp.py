"""The verified QP layer (:mod:`verimono.core.qp`): no back-end status trusted, the same accuracy at every scale."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest
from scipy.optimize import LinearConstraint, minimize

from verimono import InfeasibleStep, SolverFailure
from verimono.core.qp import _qpsolvers, equilibrate, kkt_residual, solve_qp

# the triangle {z1 + z2 <= 1, z >= 0} and a slab cut by an equality, as (G, h, A, b)
TRIANGLE = (np.array([[1.0, 1.0], [-1.0, 0.0], [0.0, -1.0]]), np.array([1.0, 0.0, 0.0]), None, None)
SLAB = (np.array([[1.0, 1.0, 0.0], [0.0, -2.0, 0.0]]), np.array([1.0, 0.5]),
        np.array([[0.0, 0.0, 3.0]]), np.array([0.75]))


def slsqp_projection(x, G, h, A, b):
    """proj(x) onto {Gz <= h, Az = b} by SciPy's SLSQP: independent of every QP back-end."""
    cons = [LinearConstraint(G, -np.inf, h)] + ([] if A is None else [LinearConstraint(A, b, b)])
    res = minimize(lambda z: 0.5 * np.sum((z - x) ** 2), np.zeros_like(x), jac=lambda z: z - x,
                   constraints=cons, method="SLSQP", options=dict(ftol=1e-15, maxiter=500))
    return res.x


@pytest.mark.parametrize("data", [TRIANGLE, SLAB], ids=["triangle", "slab"])
def test_projection_matches_slsqp_and_scales_exactly_with_the_data(data):
    """proj_{sS}(s x) = s proj_S(x): the same relative accuracy from s = 1e-12 to 1e12.

    SLSQP's own accuracy is about 1e-8, hence the looser comparison at unit scale; the scaled answers are
    compared with the unit one at 1e-9 relative (the QP_RTOL-verified accuracy with headroom)."""
    G, h, A, b = data
    rng = np.random.default_rng(7)
    for _ in range(5):
        x = rng.normal(size=G.shape[1]) * 2
        z = solve_qp(np.eye(x.size), -x, G, h, A, b)
        np.testing.assert_allclose(z, slsqp_projection(x, G, h, A, b), atol=1e-6)
        for s in (1e-12, 1e-9, 1e-6, 1e3, 1e12):
            zs = solve_qp(np.eye(x.size), -s * x, G, s * h, A, None if b is None else s * b)
            np.testing.assert_allclose(zs / s, z, rtol=0, atol=1e-9 * (1 + np.abs(z).max()))


@pytest.mark.slow
def test_a_linear_term_far_larger_than_the_constraints_is_solved_and_returns():
    """min ½y₂² − c y₂ over {y₁ = 0, y ≥ 0, y₂ ≥ δ} with δ = 1e-108 c: the minimiser is (0, c).

    ProxQP 0.8 given these data unscaled never returns (seen in a membership query of the Section 7
    Example), so the solve runs in a subprocess with a time limit: a regression fails, it does not hang."""
    code = textwrap.dedent("""
        import numpy as np
        from verimono.core.qp import solve_qp
        c = 0.7953406842482188
        P, q = np.diag([0.0, 1.0]), np.array([0.0, -c])
        G = np.array([[-1.0, 0.0], [0.0, -1.0], [0.0, -1.0], [1.0, 0.0]])
        h = np.array([0.0, 0.0, -1e-108 * c, 0.0])
        z = solve_qp(P, q, G, h, np.array([[1.0, 0.0]]), np.array([0.0]))
        assert abs(z[0]) <= 1e-12 and abs(z[1] - c) <= 1e-12 * c, z
        z = solve_qp(P, q * 1e100, G, h, np.array([[1.0, 0.0]]), np.array([0.0]))
        assert abs(z[1] - c * 1e100) <= 1e-12 * c * 1e100, z
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr


def test_equilibrated_data_are_of_unit_size():
    G, h, A, b = SLAB
    S = equilibrate(4e-7 * np.eye(3), np.array([1e-9, 0.0, 2e-9]), G * 5.0, h * 5e-9, A, b * 1e-9)
    assert np.abs(S.P).max() == 1.0
    np.testing.assert_allclose(np.linalg.norm(S.G, axis=1), 1.0)
    np.testing.assert_allclose(np.linalg.norm(S.A, axis=1), 1.0)
    assert max(np.abs(S.h).max(), np.abs(S.b).max(), np.abs(S.q).max()) == pytest.approx(1.0)
    assert S.scale == pytest.approx(max(5e-9 / np.sqrt(2), 0.25e-9, 2e-9 / 4e-7))


def test_zero_rows_are_dropped_or_prove_infeasibility():
    G = np.array([[0.0, 0.0], [-1.0, 0.0]])
    np.testing.assert_allclose(solve_qp(np.eye(2), [1.0, -1.0], G, [0.0, 0.0]), [0.0, 1.0], atol=1e-12)
    with pytest.raises(InfeasibleStep, match="zero constraint row"):
        solve_qp(np.eye(2), [1.0, -1.0], G, [-1.0, 0.0])
    # -5e-17 against data of size 1 (the caller's scale) is rounding: the row holds; as exact data it fails
    np.testing.assert_allclose(solve_qp(np.eye(2), [1.0, -1.0], G, [-5e-17, 0.0], scale=1.0), [0.0, 1.0], atol=1e-12)
    with pytest.raises(InfeasibleStep, match="zero constraint row"):
        solve_qp(np.zeros((1, 1)), [0.0], np.zeros((1, 1)), [-5e-17])
    with pytest.raises(InfeasibleStep, match="zero constraint row"):
        solve_qp(np.eye(2), [1.0, -1.0], None, None, np.zeros((1, 2)), [1.0])


def test_a_back_end_reporting_a_wrong_answer_is_not_trusted(monkeypatch):
    """Every back-end 'solves' the projection of (2, 3) onto the triangle with an interior point (the answer
    is (0, 1)): the KKT check rejects it, and polishing on its (empty) active set does not rescue it."""
    # the qpsolvers verimono calls: its private copy without the unused back-ends (or the shared package where
    # one was imported before); this module does not import qpsolvers itself, which imports JAX where installed
    # (≈ 1 s of CPU at collection in every pytest process) and would make verimono use the shared package
    monkeypatch.setattr(_qpsolvers(), "solve_qp", lambda P, q, *args, **kwargs: np.full(q.shape, 0.1))
    G, h, _, _ = TRIANGLE
    with pytest.raises(SolverFailure, match="KKT check failed"):
        solve_qp(np.eye(2), -np.array([2.0, 3.0]), G, h)
    assert not kkt_residual(np.eye(2), -np.array([2.0, 3.0]), G, h, None, None, np.array([0.3, 0.3])).ok
    assert kkt_residual(np.eye(2), -np.array([2.0, 3.0]), G, h, None, None, np.array([0.0, 1.0])).ok


def test_a_point_near_a_bound_that_its_multipliers_treat_as_active_is_rejected():
    """Projection of x = -2 onto dom H = [0.464, ∞) of the paper's Example with v = (-4.04, -0.464), as the
    QP over (x', z): min ½(x' - x)² s.t. z ≥ 0, D z + C x' + v ≥ 0 (P singular in z).  ProxQP returned
    z1 = 2.5e-7, forcing x' = 0.4640005; with -z1 ≤ 0 counted active the multipliers explained the gradient
    (dual residual 0), and only complementary slackness (μ1 z1 = 2.5 μ1e-7 ≠ 0) shows it is not optimal."""
    G = np.array([[0.0, -1.0, 0.0], [0.0, 0.0, -1.0], [0.0, 0.0, -1.0], [-1.0, 1.0, 0.0]])
    h = np.array([0.0, 0.0, -4.04, -0.464])
    P, q = np.diag([1.0, 0.0, 0.0]), np.array([2.0, 0.0, 0.0])
    near = np.array([0.4640005008383915, 2.502493740e-07, 7.28822407])
    rep = kkt_residual(P, q, G, h, None, None, near)
    assert rep.primal <= 1e-12 and rep.dual <= 1e-12 and rep.comp > 1e-8 and not rep.ok
    z = solve_qp(P, q, G, h)
    assert z[0] == pytest.approx(0.464, rel=1e-12) and abs(z[1]) <= 1e-12


def test_a_half_space_far_beyond_the_data_does_not_set_the_units():
    """z ≥ 0, z1 + z2 = 0 and 1.4e-37·z2 ≥ -1 (the LCP row of a matrix with a 1.4e-37 entry): the last is a
    half-space 7e36 from the origin.  Taken as the unit of the solve it made every other constraint
    unresolvable and a verified answer of -0.67 for z1 (the minimiser is 0)."""
    G = np.array([[-1.0, 0.0], [0.0, -1.0], [0.0, -1.4411277378133533e-37]])
    z = solve_qp(np.diag([1.0, 0.0]), [0.0, 0.0], G, [0.0, 0.0, 1.0], np.array([[1.0, 1.0]]), [0.0])
    np.testing.assert_allclose(z, [0.0, 0.0], atol=1e-12)
    z = solve_qp(np.eye(2), [-1.0, -2.0], G, [0.0, 0.0, 1.0])       # the far row never binds
    np.testing.assert_allclose(z, [1.0, 2.0], rtol=1e-12)


def test_rows_scaled_down_together_are_not_far():
    """z₁ = 5 and z₁ ≤ 1 written with rows of norm 1e-20 (and right-hand sides to match): in unit-normal form
    both offsets are of size 1 — neither is far from the other, whatever the raw numbers — so the
    contradiction is found, and z₁ ≤ 10 instead binds nothing."""
    A, G = np.array([[1e-20, 0.0]]), np.array([[1e-20, 0.0]])
    with pytest.raises(InfeasibleStep):
        solve_qp(np.eye(2), np.zeros(2), G, [1e-20], A, [5e-20])
    np.testing.assert_allclose(solve_qp(np.eye(2), np.zeros(2), G, [1e-19], A, [5e-20]), [5.0, 0.0], rtol=1e-12)


def test_a_far_half_space_is_never_dropped_from_the_answer():
    """min -z₂ + ½z₁² s.t. 1e-37·z₂ ≤ 1: the only bound on z₂ is 1e37 away (far).  Set aside, the problem is
    unbounded and no back-end's point verifies; the solve is retried with the row in its units, and the
    answer satisfies it.  (The linear term is then 1e-37 of the data's size, below double precision: any
    feasible z with z₁ = 0 is a minimiser to that precision, which is all a relative check can decide.)"""
    from verimono.core.qp import equilibrate

    P, q, G, h = np.diag([1.0, 0.0]), np.array([0.0, -1.0]), np.array([[0.0, 1e-37]]), np.array([1.0])
    S = equilibrate(P, q, G, h, None, None)
    assert S.G is None and S.G_far is not None and S.scale == 1.0       # set aside: the units stay those of q
    assert S.far_violation(np.array([0.0, 2e37])) > 0.9 and S.far_violation(np.array([0.0, 1.0])) == 0.0
    z = solve_qp(P, q, G, h)
    assert G @ z <= h * (1 + 1e-12) and abs(z[0]) <= 1e-12


def test_no_point_from_any_back_end_is_infeasible_only_when_certified():
    """No back-end returning a point is not a proof of infeasibility: a back-end may fail on a feasible QP (the
    paper Example's H at v ~ 1e-7, where ProxQP and DAQP return nothing).  Infeasibility is reported only on
    HiGHS' certificate (z₁ = 5 and z₁ ≤ 1); otherwise it is verimono's own limit (UnverifiedSolution: undecided,
    never charged to the subject).  A back-end that is not installed stands for back-ends that all fail."""
    from verimono.core.errors import UnverifiedSolution

    G, A = np.array([[1.0, 0.0]]), np.array([[1.0, 0.0]])
    with pytest.raises(InfeasibleStep):
        solve_qp(np.eye(2), np.zeros(2), G, [1.0], A, [5.0], backends=("no such back-end",))
    with pytest.raises(UnverifiedSolution):
        solve_qp(np.eye(2), np.zeros(2), G, [10.0], A, [5.0], backends=("no such back-end",))


def test_feasibility_certificate_is_linprogs_answer_on_feasible_and_infeasible_systems():
    """``_feasible`` asks HiGHS through ``linprog_highs`` (no ``linprog`` wrapper): the same answer as ``linprog``
    itself with free variables — ``False`` on its certificate of infeasibility, ``True`` on a point — on random
    systems with and without equalities, infeasible ones (a row and its negation shifted apart) among them."""
    from scipy.optimize import linprog

    from verimono.core.qp import _feasible

    def reference(G, h, A, b, n):
        res = linprog(np.zeros(n), A_ub=G, b_ub=h, A_eq=A, b_eq=b, bounds=[(None, None)] * n, method="highs")
        return False if res.status == 2 else (True if res.status == 0 else None)

    rng = np.random.default_rng(11)
    answers = []
    for k in range(60):
        n, m = int(rng.integers(1, 6)), int(rng.integers(1, 8))
        G, h = rng.normal(size=(m, n)), rng.normal(size=m)
        if k % 3 == 0:                       # x·g <= c and -x·g <= -c - 1: no point
            G, h = np.vstack([G, -G[:1]]), np.r_[h, -h[0] - 1.0]
        A, b = (rng.normal(size=(1, n)), rng.normal(size=1)) if k % 2 else (None, None)
        got = _feasible(G, h, A, b, n)
        assert got == reference(G, h, A, b, n), k
        answers.append(got)
    assert {True, False} <= set(answers)
