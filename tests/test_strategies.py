"""The generators draw valid objects: PSD matrices, nonempty sets, moving sets within their (A3) bound,
passive systems satisfying the KYP LMI ``e:lmis`` with the stated storage, AC inputs within their
Lipschitz bound, valid partitions."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from verimono import Operator, validate_grid
from verimono import strategies as vs
from verimono.tolerances import tolerance

FAST = settings(max_examples=30, deadline=None, database=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


def _psd(S: np.ndarray) -> bool:
    return float(np.linalg.eigvalsh(0.5 * (S + S.T))[0]) >= -tolerance(S)


@FAST
@given(vs.psd_matrices())
def test_psd_matrices_are_monotone(M):
    assert M.ndim == 2 and M.shape[0] == M.shape[1] <= vs.MAX_DIM
    assert _psd(M + M.T)
    assert np.max(np.abs(M)) <= M.shape[0] + 2


@FAST
@given(st.integers(1, 5).flatmap(lambda n: st.tuples(st.just(n), st.integers(0, n))).flatmap(
    lambda nr: st.tuples(st.just(nr[1]), vs.psd_matrices(nr[0], rank=nr[1]))))
def test_psd_matrices_rank_parameter(rM):
    r, M = rM
    S = M + M.T
    assert _psd(S)
    assert np.linalg.matrix_rank(S, tol=1e-9 * (1 + np.abs(S).max())) <= r


def test_psd_matrices_include_singular_and_nonsymmetric():
    seen = {"singular": False, "nonsymmetric": False}

    @FAST
    @given(vs.psd_matrices(3))
    def collect(M):
        if np.linalg.matrix_rank(M + M.T) < 3:
            seen["singular"] = True
        if not np.allclose(M, M.T):
            seen["nonsymmetric"] = True
    collect()
    assert all(seen.values()), seen


@FAST
@given(vs.monotone_linear_operators(), st.floats(0.0, 1.0))
def test_linear_operators_monotone_at_all_times(op, t):
    assert _psd(op.M(t) + op.M(t).T)
    assert "lambda" not in repr(op) and "object at" not in repr(op)


@FAST
@given(vs.convex_sets(), vs.points())
def test_convex_sets_nonempty_and_projection_lands_inside(S, w):
    w = np.resize(w, S.dim)
    p = S.project(w)
    assert p.shape == (S.dim,) and np.all(np.isfinite(p))
    assert S.contains(p, tol=tolerance(p, w) * 10)
    assert np.allclose(S.project(p), p, atol=tolerance(p) * 10)
    assert "object at" not in repr(S)


@FAST
@given(vs.moving_sets(), st.lists(vs.points(scale=10.0), min_size=3, max_size=3), st.floats(0.0, 1.0),
       st.floats(0.0, 1.0))
def test_moving_sets_move_within_phi(ms, ws, s, t):
    """(A3): sup_{z ∈ S(s)} dist(z, S(t)) ≤ φ(t) - φ(s) for s ≤ t, sampled at points z of S(s)."""
    s, t = min(s, t), max(s, t)
    assert ms.phi(t) >= ms.phi(s) >= 0.0 or ms.rate == 0.0
    for w in ws:
        z = ms.set.project(np.resize(w, ms.dim), s)
        assert ms.set.contains(z, s, tol=tolerance(z) * 10)
        d = float(np.linalg.norm(z - ms.set.project(z, t)))
        assert d <= ms.phi(t) - ms.phi(s) + tolerance(z) * 10, (ms, s, t, z, d)


@FAST
@given(vs.maximal_monotone_operators())
def test_maximal_monotone_operators_are_operators_with_readable_reprs(op):
    assert isinstance(op, Operator) and 1 <= op.dim <= vs.MAX_DIM
    r = repr(op)
    assert "<lambda>" not in r and "object at" not in r and "<function" not in r
    x = op.resolvent(np.ones(op.dim), 0.5, 0.5)
    assert x.shape == (op.dim,) and np.all(np.isfinite(x))


@FAST
@given(vs.subdifferential_operators())
def test_subdifferential_operators(op):
    assert isinstance(op, Operator)
    assert np.all(np.isfinite(op.resolvent(np.zeros(op.dim), 1.0, 1.0)))


def _check_kyp(sys_):
    K = sys_.K
    assert np.allclose(K, K.T) and _psd(K)
    Pi = sys_.kyp_matrix()
    scale = 1.0 + max(np.abs(a).max() for a in (sys_.A, sys_.B, sys_.C, sys_.D, K))
    assert float(np.linalg.eigvalsh(0.5 * (Pi + Pi.T))[-1]) <= 1e-10 * scale ** 2
    # consequences of passivity (Prop. p:pass): D ⪰ 0 and (KB - Cᵀ) ker(D + Dᵀ) = 0
    D = sys_.D
    assert _psd(D + D.T)
    w, V = np.linalg.eigh(D + D.T)
    ker = V[:, w <= 1e-9 * scale]
    assert np.allclose((K @ sys_.B - sys_.C.T) @ ker, 0.0, atol=1e-8 * scale)


@FAST
@given(vs.passive_systems(storage="identity"))
def test_passive_systems_identity_storage(sys_):
    assert np.array_equal(sys_.K, np.eye(sys_.n))
    _check_kyp(sys_)


@FAST
@given(vs.passive_systems(storage="general"))
def test_passive_systems_general_storage(sys_):
    _check_kyp(sys_)
    assert "object at" not in repr(sys_)


@FAST
@given(vs.ac_inputs(T=2.0), st.floats(0.0, 2.0), st.floats(0.0, 2.0))
def test_ac_inputs_lipschitz_and_integral(u, s, t):
    us, ut = u(s), u(t)
    assert us.shape == (u.m,)
    assert np.linalg.norm(ut - us) <= u.lipschitz * abs(t - s) + tolerance(us, ut)
    assert u.variation == pytest.approx(u.lipschitz * 2.0)
    grid = np.linspace(0.0, t, 2001)
    vals = np.array([u(g) for g in grid])
    quad = np.trapezoid(vals, grid, axis=0) if hasattr(np, "trapezoid") else np.trapz(vals, grid, axis=0)
    # trapezoid error ≤ (t/2000)² · t · |u''|/12 ≤ 1e-5 for the drawn families
    assert np.allclose(u.integral(t), quad, atol=1e-4 * (1 + u.lipschitz))


@FAST
@given(st.floats(0.1, 10.0).flatmap(lambda T: st.tuples(st.just(T), vs.grids(T))))
def test_grids_are_partitions(Tg):
    T, t = Tg
    assert np.array_equal(validate_grid(t, T), t)
    assert t[0] == 0.0 and t[-1] == T and np.all(np.diff(t) > 0)
    h = np.diff(t)
    assert h.max() / h.min() <= 100.0 * (1 + 1e-9)


@FAST
@given(vs.points(3))
def test_points(x):
    assert x.shape == (3,) and np.all(np.abs(x) <= vs.POINT_SCALE)


def test_catalog_names_unique():
    for n in (2, 3):
        names = [op.name for op in vs.catalog(n)]
        assert len(names) == len(set(names))
