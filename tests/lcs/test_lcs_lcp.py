"""LCP(q, M): Siconos test problems, least-norm solutions (Proposition p:lcp2 iv), residual checks."""

from __future__ import annotations

import numpy as np
import pytest

from verimono import InfeasibleStep, InvalidProblem, SolverFailure
from verimono.lcs import lcp as L
from verimono.lcs import lcp_residual, read_lcp, solve_box, solve_lcp

INFEASIBLE = {"lcp_Pang_isolated_sol_perturbed.dat"}


def _files(siconos_dir):
    return sorted((siconos_dir / "lcp").glob("*.dat"))


def test_every_siconos_lcp_solved_or_reported_infeasible(siconos_dir):
    files = _files(siconos_dir)
    assert len(files) == 20
    for f in files:
        M, q = read_lcp(f)
        if f.name in INFEASIBLE:
            with pytest.raises(InfeasibleStep, match="no solution"):
                solve_lcp(M, q)
            continue
        r = solve_lcp(M, q, info=True)
        w = M @ r.z + q
        scale = 1.0 + max(np.abs(q).max(), np.abs(M).sum(1).max() * np.abs(r.z).max())
        assert lcp_residual(M, q, r.z) <= 1e-10 * scale, f.name
        assert r.z.min() >= -1e-10 * scale and w.min() >= -1e-10 * scale, f.name
        assert abs(r.z @ w) <= 1e-10 * scale * (1 + np.abs(r.z).sum()), f.name


def test_block_storage_equals_dense(siconos_dir):
    for name in ("deudeu", "ortiz", "trivial"):
        Md, qd = read_lcp(siconos_dir / "lcp" / f"lcp_{name}.dat")
        Mb, qb = read_lcp(siconos_dir / "lcp" / f"lcp_{name}_block.dat")
        np.testing.assert_array_equal(Md, Mb)
        np.testing.assert_array_equal(qd, qb)


def test_closed_forms(siconos_dir):
    M, q = read_lcp(siconos_dir / "lcp" / "lcp_deudeu.dat")  # column-major: M = [[2,1],[1,2]]
    np.testing.assert_array_equal(M, [[2, 1], [1, 2]])
    np.testing.assert_allclose(solve_lcp(M, q), [4 / 3, 7 / 3], rtol=1e-14)
    M, q = read_lcp(siconos_dir / "lcp" / "lcp_exp_murty2.dat")  # P-matrix: unique solution z = (0,...,0,64)
    np.testing.assert_allclose(solve_lcp(M, q), [0, 0, 0, 0, 0, 64], atol=1e-12)


@pytest.mark.parametrize("name, least", [
    ("lcp_CPS_1.dat", [0.5, 0.5]),            # SOL = {z ≥ 0, z1 + z2 = 1}
    ("lcp_CPS_5.dat", [0.0, 1.0]),            # SOL = {(s, s + 1), s ≥ 0}
    ("lcp_inf_sol_perturbed.dat", [1.0, 0.0, 1e-4]),  # skew M: SOL = {(1, s, s + 1e-4)}
])
def test_least_norm_on_degenerate_lcps_and_tikhonov_limit(siconos_dir, name, least):
    M, q = read_lcp(siconos_dir / "lcp" / name)
    r = solve_lcp(M, q, info=True)
    assert r.psd and r.unique is False and r.least_norm
    np.testing.assert_allclose(r.z, least, atol=1e-12)
    # other members of SOL(q, M) are solutions and are longer
    d = {"lcp_CPS_1.dat": [1, -1], "lcp_CPS_5.dat": [1, 1], "lcp_inf_sol_perturbed.dat": [0, 1, 1]}[name]
    for s in (0.1, 0.3):
        other = np.array(least) + s * np.array(d, float)
        if other.min() >= 0:
            assert lcp_residual(M, q, other) <= 1e-12 and other @ other > r.z @ r.z
    # Tikhonov: LCP(q, M + εI) has a unique solution z_ε → z* as ε → 0
    errs = [np.linalg.norm(solve_lcp(M + eps * np.eye(len(q)), q) - r.z) for eps in (1e-2, 1e-4, 1e-6)]
    assert errs[0] > errs[1] > errs[2] and errs[2] <= 1e-5


def test_random_degenerate_psd_least_norm_matches_tikhonov():
    rng = np.random.default_rng(3)
    for _ in range(10):
        n = 5
        R = rng.normal(size=(2, n))
        S = rng.normal(size=(n, n))
        M = R.T @ R + (S - S.T) * (rng.uniform() < 0.5)   # PSD, rank-deficient symmetric part
        supp = rng.uniform(size=n) < 0.5            # q = w0 - M z0 with 0 ≤ z0 ⊥ w0 ≥ 0: solvable
        z0 = np.where(supp, rng.uniform(0.5, 2, n), 0.0)
        w0 = np.where(supp, 0.0, rng.uniform(0, 2, n))
        q = w0 - M @ z0
        z = solve_lcp(M, q)
        zt = solve_lcp(M + 1e-8 * np.eye(n), q)
        assert lcp_residual(M, q, z) <= 1e-10 * (1 + np.abs(q).max() + np.abs(M).max() * np.abs(z).max())
        # Tikhonov solutions are never longer than z* (monotonicity) and converge to it
        assert np.linalg.norm(zt) <= np.linalg.norm(z) * (1 + 1e-9) and np.linalg.norm(z) <= np.linalg.norm(z0) + 1e-9
        assert np.linalg.norm(z - zt) <= 1e-5 * (1 + np.linalg.norm(z))


def test_wrong_backend_status_is_caught(monkeypatch):
    M, q = np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-5.0, -6.0])
    monkeypatch.setitem(L.BACKENDS, "lemke", lambda M, q: (np.array([5.0, -3.0]), "solved"))
    r = solve_lcp(M, q, info=True)
    np.testing.assert_allclose(r.z, [4 / 3, 7 / 3], rtol=1e-12)
    assert r.backend.startswith("qp") and "lemke: status 'solved' but residual" in r.reasons[0]
    with pytest.raises(SolverFailure, match="lemke: status 'solved' but residual"):
        solve_lcp(M, q, backends=("lemke",))


def test_infeasible_psd_lcp_has_certificate():
    M = np.array([[0.0, 1.0], [-1.0, 0.0]])   # skew, PSD; Q_M = {ζ ≥ 0: ζ2 = 0... } ∋ (1, 0)
    q = np.array([-1.0, 1.0])                 # w2 = -z1 + 1, w1 = z2 - 1: feasible; make it infeasible:
    q = np.array([-1.0, -1.0])                # w2 = -z1 - 1 < 0 always
    with pytest.raises(InfeasibleStep, match=r"q ∉ Q_M\^\+.*certificate"):
        solve_lcp(M, q)


def test_bad_input_is_typed():
    with pytest.raises(InvalidProblem, match="square"):
        solve_lcp(np.ones((2, 3)), [1, 1])
    with pytest.raises(InvalidProblem, match="shape"):
        solve_lcp(np.eye(2), [1, 1, 1])
    with pytest.raises(InvalidProblem, match="finite"):
        solve_lcp(np.eye(2), [np.nan, 1])


def test_relay_box_closed_form():
    rng = np.random.default_rng(0)
    h = 1e-3
    for _ in range(20):
        q = rng.normal(size=3) * 5e-3
        lam = solve_box(2 * h * np.eye(3), q, -1.0, 1.0)
        np.testing.assert_allclose(lam, np.clip(-q / (2 * h), -1, 1), atol=1e-12)
    # degenerate: M = 0, q = 0: every λ ∈ [-1, 1]^2 solves it, least norm is 0; q = (0, 1): λ2 = -1
    np.testing.assert_allclose(solve_box(np.zeros((2, 2)), [0.0, 1.0], -1, 1), [0.0, -1.0], atol=1e-12)


# -- scale: LCP(q, M) is homogeneous, z ∈ SOL(q, M) iff (β/s) z ∈ SOL(q/s, M/β) -------------------------
PAPER_M = np.array([[0.0, 1.0], [-1.0, 1.0]])   # D + h C B of the paper's Example with h = 1 (PSD, not symmetric)


@pytest.mark.parametrize("t", [1e-12, 1e-9, 1e-6, 1.0, 1e6])
def test_unique_solution_at_every_scale_of_q(t):
    # SOL(q, M) = {(t, t)} for q = (−t, 0): z2 > 0 forces w2 = 0, i.e. z1 = z2, and then z2 (z2 − t) = 0.
    # The pair qᵀ(z − z̄) = 0 of CPS Thm 3.1.7 pins z1; a rank decision relative to |M| used to drop it
    # for |q| ≪ 1 (SolverFailure at t = 1e-9, the wrong point (0, t) accepted at t = 1e-12).
    r = solve_lcp(PAPER_M, np.array([-t, 0.0]), info=True)
    np.testing.assert_allclose(r.z, [t, t], rtol=1e-9, atol=0)
    assert r.relative_residual <= 1e-10


def test_solutions_scale_with_the_data():
    """Least-norm solutions of degenerate PSD LCPs (rank-deficient symmetric part, non-unique solutions)
    scale as (s/β) z when q → s q and M → β M, from 1e-9 to 1e6."""
    rng = np.random.default_rng(11)
    for _ in range(12):
        n = int(rng.integers(2, 6))
        R, S = rng.normal(size=(n - 1, n)), rng.normal(size=(n, n))
        M = R.T @ R + (S - S.T) * (rng.uniform() < 0.5)
        supp = rng.uniform(size=n) < 0.5               # q = w0 - M z0 with 0 ≤ z0 ⊥ w0 ≥ 0: solvable
        z0, w0 = np.where(supp, rng.uniform(0.5, 2, n), 0.0), np.where(supp, 0.0, rng.uniform(0, 2, n))
        q = w0 - M @ z0
        z = solve_lcp(M, q)
        for s, beta in ((1e-9, 1.0), (1e6, 1.0), (1.0, 1e-7), (1e-8, 1e5)):
            np.testing.assert_allclose(solve_lcp(beta * M, s * q) * (beta / s), z, rtol=1e-7,
                                       atol=1e-9 * (1 + np.abs(z).max()))


def test_relay_solutions_scale_with_the_data():
    """λ solves the box problem (M, q, l, u) iff (s/β)λ solves (βM, s q, (s/β) l, (s/β) u): least-norm relay
    solutions of a singular PSD M (non-unique) at data sizes from 1e-9 to 1e6."""
    from verimono.lcs.lcp import solve_box

    rng = np.random.default_rng(5)
    for _ in range(8):
        R = rng.normal(size=(1, 3))
        M, q = R.T @ R, rng.normal(size=3)
        lam = solve_box(M, q, -1.0, 1.0)
        for s, beta in ((1e-9, 1.0), (1e6, 1.0), (1e-8, 1e5)):
            r = s / beta
            np.testing.assert_allclose(solve_box(beta * M, s * q, -r, r) / r, lam, rtol=1e-7, atol=1e-9)
