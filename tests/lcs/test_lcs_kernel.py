"""The LCS stepping kernel (issue 15): same trajectories as the step-by-step verified solver, the least-norm
selection of p:lcp2 where the solution is not unique, batches bit-identical to single runs, typed errors."""

from __future__ import annotations

import numpy as np
import pytest

from verimono import InfeasibleStep, InvalidProblem, SolverFailure
from verimono.lcs import Complementarity, LinearRelationSystem, Relay, solve_lcp
from verimono.lcs import kernel as K
from verimono.lcs.siconos_cases import diode_bridge, filippov, relay_oscillator
from verimono.run.performance import minimal_lcs

# A + Aᵀ ⪯ 0, C = Bᵀ, D = RᵀR + skew with rank-1 R: ker(D + Dᵀ) ≠ {0}, so SOL need not be a singleton
from test_lcs_system import random_passive


def step_by_step(sys, x0, t, theta, gamma=None):
    """Reference: every step by the verified least-norm solver (Relation.solve), from the trajectory's x_k."""
    sm = sys.step_matrices(t[1] - t[0], theta, gamma)
    g = 1.0 if gamma is None else gamma
    X = [np.asarray(x0, float)]
    Z = []
    for k in range(t.size - 1):
        xk = X[-1]
        xf = sm.E @ xk
        xq = g * xf + (1 - g) * xk
        v = sys.v(t[k + 1])
        z = sys.relation.solve(sm.M, sys.C @ xq + v, sys.q_scale(xq, v)).z
        X.append(xf + sm.G @ z)
        Z.append(z)
    return np.array(X), np.array(Z)


def test_diode_bridge_matches_the_verified_solver_to_round_off():
    sys, h, steps = diode_bridge(), 1e-6, 3000
    t = np.arange(steps + 1) * h
    tr = sys.simulate([10.0, 0.0], t, theta=0.5)
    X, Z, W = minimal_lcs(sys, sys.step_matrices(h, 0.5), np.array([10.0, 0.0]), steps)
    assert np.abs(tr.x - X).max() <= 1e-12 * np.abs(X).max()
    assert np.abs(tr.extras["z"] - Z).max() <= 1e-12 * np.abs(Z).max()
    assert np.abs(tr.extras["w"] - W).max() <= 1e-12 * np.abs(W).max()


@pytest.mark.parametrize("make,x0,h", [(relay_oscillator, (0.0, 0.675, 0.0), 1e-2), (filippov, (3.0, 3.0), 1e-3)])
def test_relay_systems_match_the_verified_solver(make, x0, h):
    sys = make()
    t = np.arange(401) * h
    tr = sys.simulate(x0, t, theta=0.5)
    X, Z = step_by_step(sys, x0, t, 0.5)
    assert np.abs(tr.x - X).max() <= 1e-10 * (1 + np.abs(X).max())
    assert np.abs(tr.extras["z"] - Z).max() <= 1e-10 * (1 + np.abs(Z).max())


def _least_norm_agreement(sys, X0, t, theta):
    """(rows × steps checked, of which SOL(q, M) was not a singleton): every step of a batch against
    solve_lcp's least-norm z at that row's state."""
    tr = sys.simulate(X0, t, theta=theta)
    sm = sys.step_matrices(t[1], theta)
    checked = non_unique = 0
    for i in range(X0.shape[0]):
        for k in range(t.size - 1):
            xf = sm.E @ tr.x[k, i]
            v = sys.v(t[k + 1])
            r = solve_lcp(sm.M, sys.C @ xf + v, scale=sys.q_scale(xf, v), info=True)
            assert np.abs(tr.extras["z"][k, i] - r.z).max() <= 1e-9 * (1 + np.abs(r.z).max()), (i, k)
            checked += 1
            non_unique += r.unique is False
    return checked, non_unique


def test_least_norm_where_the_step_is_not_unique():
    """Where SOL(q, M) is not a singleton the kernel must return solve_lcp's least-norm z (p:lcp2 iv): the
    DiodeBridgeCapFilter (a diode with zero current and voltage: 144 of its 600 row-steps here), and the
    paper's Example reaching the edge x = −v2 of dom H, at every step of a batch."""
    from verimono.lcs.siconos_cases import diode_bridge_cap_filter
    from verimono.reference.lcs_example import example_system

    ex = example_system(lambda s: np.array([np.sin(3 * s), 0.0]))
    c1, n1 = _least_norm_agreement(ex, np.array([[0.0], [0.5], [-1.0]]), np.linspace(0.0, 4.0, 201), 1.0)
    cf = diode_bridge_cap_filter()
    c2, n2 = _least_norm_agreement(cf, np.array([[10.0, 0.0, 0.0], [-4.0, 1.0, 0.0]]), np.arange(301) * 1e-6, 1.0)
    assert c1 == 600 and c2 == 600
    assert n2 >= 50, n2   # the non-unique branch is really exercised


def test_a_kernel_without_its_sign_checks_is_caught(monkeypatch):
    """Seen failing: a kernel that accepts the previous pattern's candidate unchecked leaves the verified
    solver's trajectory on the DiodeBridge (the diodes switch) — the comparison above catches it."""
    def unchecked(self, p, x, e, emax):
        return self.fn(p.rows, *x, *e), True

    monkeypatch.setattr(K.StepKernel, "try_row", unchecked)
    sys, h, steps = diode_bridge(), 1e-6, 1500
    t = np.arange(steps + 1) * h
    tr = sys.simulate([10.0, 0.0], t, theta=0.5)
    X, _, _ = minimal_lcs(sys, sys.step_matrices(h, 0.5), np.array([10.0, 0.0]), steps)
    assert np.abs(tr.x - X).max() > 1e-3 * np.abs(X).max()


def _same(a, b):
    return np.array_equal(a, b, equal_nan=True)


@pytest.mark.parametrize("make,x0s,h,theta,gamma", [
    (diode_bridge, [[10.0, 0.0], [-3.0, 2.0], [0.0, 0.0], [1e-3, -7.0]], 1e-6, 0.5, None),
    (diode_bridge, [[10.0, 0.0], [-3.0, 2.0], [5.0, 5.0]], 1e-6, 0.5, 0.5),
    (relay_oscillator, [[0.0, 0.675, 0.0], [1.0, -1.0, 0.5], [0.0, 0.0, 0.0]], 1e-2, 0.5, None),
    (filippov, [[3.0, 3.0], [-1.0, 0.2], [0.0, 0.0]], 1e-3, 0.5, None),
])
def test_a_batch_is_bit_identical_to_separate_runs(make, x0s, h, theta, gamma):
    sys = make()
    t = np.arange(601) * h
    batch = sys.simulate(np.array(x0s), t, theta=theta, gamma=gamma)
    assert batch.x.shape == (601, len(x0s), sys.n) and batch.extras["z"].shape == (600, len(x0s), sys.m)
    for i, x0 in enumerate(x0s):
        one = sys.simulate(x0, t, theta=theta, gamma=gamma)
        assert _same(batch.x[:, i], one.x) and _same(batch.extras["z"][:, i], one.extras["z"])
        assert _same(batch.extras["w"][:, i], one.extras["w"])


def test_batched_inputs_are_bit_identical_to_separate_runs_with_each_input():
    rng = np.random.default_rng(3)
    A, B, C, D = random_passive(rng)
    sys = LinearRelationSystem(A, B, C, D, Complementarity())
    amp = np.array([0.5, 1.0, 2.0])
    X0 = rng.normal(size=(3, 3))
    t = np.linspace(0.0, 3.0, 301)
    u = lambda s: np.outer(amp, [np.sin(s), 0.0, np.cos(s)])           # (B, n)
    v = lambda s: np.outer(amp, [np.cos(2 * s), -0.3])                 # (B, m)
    batch = sys.simulate(X0, t, u=u, v=v)
    for i in range(3):
        one = sys.simulate(X0[i], t, u=lambda s, i=i: u(s)[i], v=lambda s, i=i: v(s)[i])
        assert _same(batch.x[:, i], one.x) and _same(batch.extras["z"][:, i], one.extras["z"])
    # shared inputs and a per-row constant v
    vc = rng.normal(size=(3, 2))
    batch = sys.simulate(X0, t, u=lambda s: np.array([np.sin(s), 0.0, 1.0]), v=vc)
    for i in range(3):
        one = sys.simulate(X0[i], t, u=lambda s: np.array([np.sin(s), 0.0, 1.0]), v=vc[i])
        assert _same(batch.x[:, i], one.x) and _same(batch.extras["w"][:, i], one.extras["w"])


def test_inputs_follow_the_scheme_with_the_system_inputs():
    """simulate(u=, v=) for one row gives the same trajectory as a system built with those inputs."""
    rng = np.random.default_rng(4)
    A, B, C, D = random_passive(rng)
    u = lambda s: np.array([np.sin(s), 0.0, 1.0])
    v = lambda s: np.array([np.cos(s), -0.3])
    t = np.linspace(0.0, 2.0, 201)
    a = LinearRelationSystem(A, B, C, D, Complementarity(), u=u, v=v).simulate([1.0, 0.0, -1.0], t)
    b = LinearRelationSystem(A, B, C, D, Complementarity()).simulate([1.0, 0.0, -1.0], t, u=u, v=v)
    assert _same(a.x, b.x)


def test_bad_batches_get_typed_errors():
    sys = diode_bridge()
    t = np.arange(11) * 1e-6
    with pytest.raises(InvalidProblem, match=r"shape \(2,\) or a batch of shape \(B, 2\), got shape \(4, 3\)"):
        sys.simulate(np.zeros((4, 3)), t)
    with pytest.raises(InvalidProblem, match="got shape"):
        sys.simulate(np.zeros((2, 2, 2)), t)
    with pytest.raises(InvalidProblem, match=r"not finite \(rows \[1, 3\]\)"):
        sys.simulate(np.array([[1.0, 0.0], [np.nan, 0.0], [0.0, 1.0], [0.0, np.inf]]), t)
    with pytest.raises(InvalidProblem, match=r"u\(t\) must return shape"):
        sys.simulate(np.zeros((3, 2)), t, u=lambda s: np.zeros((4, 2)))
    with pytest.raises(InvalidProblem, match=r"v must have shape"):
        sys.simulate(np.zeros((3, 2)), t, v=np.zeros((2, 4)))
    with pytest.raises(InvalidProblem, match=r"v must have shape"):
        sys.simulate(np.zeros(2), t, v=np.zeros((3, 4)))           # a batch of inputs needs a batch of x0
    with pytest.raises(InvalidProblem, match=r"rows \[2\]"):
        sys.simulate(np.zeros((3, 2)), t, v=lambda s: np.where(np.arange(3)[:, None] == 2, np.nan, 0.0)
                     * np.ones((3, 4)))


def one_dim(v):
    """w = z·0 + 0·x + v: LCP(v, 0) is solvable iff v ≥ 0 (z = 0), infeasible (q ∉ Q_M^+) once v < 0."""
    return LinearRelationSystem([[0.0]], [[1.0]], [[0.0]], [[0.0]], Complementarity(), v=v)


def test_an_infeasible_row_names_its_row_and_step_and_keeps_the_others():
    t = np.linspace(0.0, 1.0, 11)
    v = lambda s: np.array([[1.0], [0.45 - s], [2.0], [-1.0]])   # row 1 infeasible from t = 0.5 (step 4), row 3 at once
    X0 = np.array([[0.1], [0.2], [0.3], [0.4]])
    sys = one_dim([1.0])
    with pytest.raises(K.BatchStepError) as info:
        sys.simulate(X0, t, v=v)
    err = info.value
    assert err.rows == [1, 3] and [f.step for f in err.failures] == [4, 0]
    assert all(isinstance(f.error, InfeasibleStep) for f in err.failures)
    assert "row 1, step 4" in str(err) and "row 3, step 0" in str(err)
    tr, valid = err.trajectory, err.valid
    for i in (0, 2):       # the other rows: complete, and as separate runs
        one = sys.simulate(X0[i], t, v=lambda s, i=i: v(s)[i])
        assert valid[:, i].all() and _same(tr.x[:, i], one.x) and _same(tr.extras["z"][:, i], one.extras["z"])
    assert valid[:5, 1].all() and not valid[5:, 1].any() and np.isnan(tr.x[5:, 1]).all()
    assert np.all(np.isfinite(tr.x[:5, 1])) and np.isnan(tr.extras["z"][4:, 1]).all()
    assert valid[0, 3] and not valid[1:, 3].any()
    # a single run raises the step's own error, naming the step
    with pytest.raises(InfeasibleStep, match=r"step 4 .*q ∉ Q_M"):
        sys.simulate(X0[1], t, v=lambda s: v(s)[1])


def test_overflow_is_a_typed_error_naming_the_row():
    sys = LinearRelationSystem([[1e300]], [[1.0]], [[1.0]], [[1.0]], Complementarity())
    t = np.linspace(0.0, 1.0, 4)
    with pytest.raises(SolverFailure, match="not finite"):
        sys.simulate([1e10], t, theta=0.0)
    with pytest.raises(K.BatchStepError) as info:
        sys.simulate(np.array([[0.0], [1e10]]), t, theta=0.0)
    assert info.value.rows == [1] and isinstance(info.value.failures[0].error, SolverFailure)
    assert np.array_equal(info.value.trajectory.x[:, 0, 0], np.zeros(4))


def test_non_uniform_grids_and_operator_relations_batch_row_by_row():
    from verimono import NormalCone
    from verimono.core.sets import Box

    sysO = LinearRelationSystem(np.zeros((2, 2)), 2 * np.eye(2), np.eye(2), np.zeros((2, 2)),
                                NormalCone(Box([-1, -1], [1, 1])))
    sysR = LinearRelationSystem(np.zeros((2, 2)), 2 * np.eye(2), np.eye(2), np.zeros((2, 2)), Relay())
    # 25 steps growing from 4e-3 to 12e-3 (span 0.2, step ratio 3): the second row reaches the relay's switch
    # (x = 0) inside the grid, the first does not (100 steps of 1e-3..3e-3 cost 16 s CPU, the same span and ratio)
    t = np.concatenate([[0.0], np.cumsum(np.linspace(4e-3, 12e-3, 25))])
    X0 = np.array([[1.0, -1.0], [0.2, 0.3]])
    bR = sysR.simulate(X0, t, theta=0.5)
    for i in range(2):
        assert _same(bR.x[:, i], sysR.simulate(X0[i], t, theta=0.5).x)
    # an operator relation is solved by splitting to its stopping tolerance (two single runs of it differ
    # by ~1e-9 here: its resolvent keeps state), so its rows agree to that accuracy
    bO = sysO.simulate(X0, t, theta=0.5)
    for i in range(2):
        np.testing.assert_allclose(bO.x[:, i], sysO.simulate(X0[i], t, theta=0.5).x, rtol=0, atol=1e-8)
    np.testing.assert_allclose(bO.x, bR.x, atol=1e-8)
    assert np.all(np.abs(bR.x[-1, 1]) < 1e-12) and np.all(np.abs(bR.x[-1, 0]) > 0.5)     # one row switched, one not


def test_a_degenerate_candidate_is_accepted_only_when_it_is_least_norm(monkeypatch):
    """M = [[0,0,1],[0,1,0],[−1,0,0]] (M + Mᵀ ⪰ 0), q = (0, −1, 1): SOL = {(t, 1, 0) : 0 ≤ t ≤ 1}, least-norm
    (0, 1, 0).  Both ends are degenerate (z_i = w_i = 0 in one component); the far end, pattern {1, 2, 3}
    with M nonsingular, must be rejected by the tangent-cone certificate (−e1 keeps w3 ≥ 0 and shortens
    it), the near end, pattern {2}, accepted — and simulate returns the least-norm multiplier."""
    M = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
    q = np.array([0.0, -1.0, 1.0])
    sys = LinearRelationSystem([[0.0]], np.zeros((1, 3)), np.zeros((3, 1)), M, Complementarity(), v=q)
    t = np.linspace(0.0, 1.0, 6)
    tr = sys.simulate([0.0], t)
    assert np.array_equal(tr.extras["z"], np.tile([0.0, 1.0, 0.0], (5, 1)))
    kern = K.StepKernel(sys, sys.step_matrices(0.2, 1.0), exo_u=False, exo_v=True, v_const=None)
    far, near = kern.pattern(np.array([1, 1, 1])), kern.pattern(np.array([0, 1, 0]))
    y_far, ok_far = kern.try_row(far, [0.0], q.tolist(), 1.0)
    y_near, ok_near = kern.try_row(near, [0.0], q.tolist(), 1.0)
    assert not ok_far and not ok_near                         # neither is strictly complementary
    assert y_far[1:4] == [1.0, 1.0, 0.0] and y_near[1:4] == [0.0, 1.0, 1.0]   # (z1, z2, w3) / (w1, z2, w3)
    assert not kern._least_norm_degenerate(far, y_far, [0.0], 1.0)
    assert kern._least_norm_degenerate(near, y_near, [0.0], 1.0)
    # seen failing: without the tangent-cone directions the far end would pass
    monkeypatch.setattr(K.StepKernel, "_degenerate_certificate", lambda self, s, deg: [])
    kern2 = K.StepKernel(sys, sys.step_matrices(0.2, 1.0), exo_u=False, exo_v=True, v_const=None)
    far2 = kern2.pattern(np.array([1, 1, 1]))
    assert kern2._least_norm_degenerate(far2, kern2.try_row(far2, [0.0], q.tolist(), 1.0)[0], [0.0], 1.0)


@pytest.mark.parametrize("n", [1, 2, 4, 9])
def test_direct_lapack_lu_is_scipys_bit_for_bit(n):
    """The kernels' LU (LAPACK getrf/getrs without SciPy's per-call wrapper) returns exactly what
    ``scipy.linalg.lu_factor``/``lu_solve`` return, for one right-hand side and several; a wrong shape is refused."""
    import scipy.linalg as sla

    from verimono.lcs._lu import lu_factor, lu_solve

    rng = np.random.default_rng(n)
    A = rng.normal(size=(n, n)) + n * np.eye(n)
    lu, piv = lu_factor(A)
    ref = sla.lu_factor(A, check_finite=False)
    assert np.array_equal(lu, ref[0]) and np.array_equal(piv, ref[1])
    for b in (rng.normal(size=n), rng.normal(size=(n, 3))):
        x = lu_solve((lu, piv), b)
        assert np.array_equal(x, sla.lu_solve(ref, b, check_finite=False))
        assert np.allclose(A @ x, b, rtol=0, atol=1e-12 * (1 + np.abs(b).max()))
    assert lu_solve((lu, piv), np.empty((n, 0))).shape == (n, 0)
    with pytest.raises(ValueError, match="incompatible"):
        lu_solve((lu, piv), np.ones(n + 1))


def test_enumerated_patterns_are_all_patterns_looked_up_in_order():
    """``StepKernel.enumerated`` (the patterns' keys made once per kernel) gives what a loop of ``pattern(s)`` over
    ``all_patterns()`` gives — the same maps, ``None`` where a map fails — and builds them in the same order, so
    the patterns' ids (``by_id``) are those of the loop it replaces; a second pass builds nothing."""
    M = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])   # singular principal blocks: some None
    sys = LinearRelationSystem([[0.0]], np.zeros((1, 3)), np.zeros((3, 1)), M, Complementarity(),
                               v=np.array([0.0, -1.0, 1.0]))
    make = lambda: K.StepKernel(sys, sys.step_matrices(0.2, 1.0), exo_u=False, exo_v=True, v_const=None)  # noqa: E731
    a, b = make(), make()
    a.pattern(np.array([0, 1, 0]))            # one built before: the others keep the loop's order after it
    b.pattern(np.array([0, 1, 0]))
    got = list(a.enumerated())
    want = [b.pattern(s) for s in b.all_patterns()]
    assert [None if p is None else (p.key, p.s.tolist()) for p in got] == \
           [None if p is None else (p.key, p.s.tolist()) for p in want]
    assert None in got and len(got) == 8
    built = len(a.by_id)
    assert list(a.enumerated()) == got and len(a.by_id) == built
