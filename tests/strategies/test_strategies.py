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
from verimono.core.tolerances import tolerance

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


# -- the stated functions of (A3), (LG), (YB) hold for the generated operators ---------------------------

STATED = {"linear": lambda: vs.stated_operators(None, 1.0, ("linear",), shifted=False),
          "subdifferential": lambda: vs.stated_operators(None, 1.0, ("subdifferential",), shifted=False),
          "moving_set": lambda: vs.stated_operators(None, 1.0, ("moving_set",), shifted=False),
          "shifted": lambda: vs.stated_operators(None, 1.0, shifted=True),
          "lcs": lambda: vs.lcs_operators(moving_v=None)}


def _stated_all():
    """Every stated family, drawn with equal weight (one_of would favour the first)."""
    return st.sampled_from(list(STATED)).flatmap(lambda f: STATED[f]())


@pytest.mark.parametrize("family", list(STATED))
def test_stated_functions_hold(family):
    @settings(FAST, max_examples=100)
    @given(STATED[family](), vs.points(scale=5.0), vs.step_sizes(1e-3, 1.0), st.floats(0.0, 1.0),
           st.floats(0.0, 1.0), vs.step_sizes(1e-3, 1.0))
    def run(stated, w, lam, s, t, nu):
        _stated_functions_hold(stated, w, lam, s, t, nu)
    run()


def _stated_functions_hold(stated, w, lam, s, t, nu):
    """σ: |F^0(t,x)| ≤ σ(t)(1 + |x|) (LG); θ: |Y_λ(s+λ,x)| ≤ θ(s+λ) − θ(s) + |F^0(s,x)| (YB); φ:
    dist(z, dom F(t)) ≤ φ(t) − φ(s) for z ∈ dom F(s), s ≤ t (A3) — at x = J_ν w ∈ dom F(s,·) (item v), which
    lands on the kinks of F where the bounds are tight.  Yosida values carry the resolvent's rounding divided
    by λ (quotient_tolerance); hypothesis climbs on each ratio lhs/(rhs + slack)."""
    from hypothesis import target

    from verimono.core.tolerances import quotient_tolerance

    op = stated.operator
    w = np.resize(w, op.dim)
    s, t = min(s, t), max(s, t)
    s = min(s, 1.0 - lam)
    x = np.asarray(op.resolvent(w, nu, s), dtype=float)
    f0 = float(np.linalg.norm(op.min_norm(x, s)))
    slack = quotient_tolerance(nu, w, x) * 10
    if stated.sigma is not None:
        assert stated.sigma(s) >= 0.0
        ratio = f0 / (stated.sigma(s) * (1.0 + np.linalg.norm(x)) + slack)
        target(ratio, label="LG")
        assert ratio <= 1.0, (stated, x, f0)
    if stated.theta is not None:
        assert stated.theta(t) >= stated.theta(s)
        J = np.asarray(op.resolvent(x, lam, s + lam), dtype=float)
        Y = float(np.linalg.norm((x - J) / lam))
        rhs = stated.theta(s + lam) - stated.theta(s) + f0
        ratio = Y / (rhs + slack + quotient_tolerance(lam, x, J) * 10)
        target(ratio, label="YB")
        assert ratio <= 1.0, (stated, x, lam, s, Y, rhs)
    if stated.phi is not None:
        assert stated.phi(t) >= stated.phi(s)
        z = np.asarray(op.project_domain(w, s), dtype=float)
        d = float(np.linalg.norm(z - op.project_domain(z, t)))
        ratio = d / (stated.phi(t) - stated.phi(s) + tolerance(z, w) * 10)
        target(ratio, label="A3")
        assert ratio <= 1.0, (stated, z, s, t, d)


def _expected_statements(family, stated):
    """Which of (φ, σ, θ) the generator must state for ``stated`` of ``family`` — the rules of
    :class:`verimono.strategies.Stated` and its makers: (A3) everywhere but a Section 7 system with moving
    ``v``; (LG) everywhere but the log-barrier and a system with (numerically) singular ``D + Dᵀ``; (YB) for
    operators that do not move, for moving weights of subdifferentials, never for shifts or moving sets."""
    op = stated.operator
    if family == "lcs":
        D = stated.system.D
        mu = float(np.linalg.eigvalsh(0.5 * (D + D.T))[0])
        static = stated.system.v_constant
        return static, mu > vs.LCS_MU_FLOOR, static
    base = op.F if family == "shifted" else op
    barrier = type(base).__name__ == "LogBarrier"
    if family == "shifted":
        return True, not barrier, False
    if family == "linear":
        return True, True, op.static
    if family == "moving_set":
        return True, True, stated.phi.rate == 0
    return True, not barrier, True


@pytest.mark.parametrize("family", list(STATED))
def test_every_family_states_what_holds(family):
    """Each drawn operator states exactly the functions its family's rules give (a generator that drops a
    stated θ leaves bounds_yb untested; one that states a θ for a moving set asserts a false bound), and
    over the draws both outcomes of every rule that can go either way are seen."""
    seen = set()

    @settings(FAST, max_examples=60)
    @given(STATED[family]())
    def collect(stated):
        expected = _expected_statements(family, stated)
        got = tuple(getattr(stated, k) is not None for k in ("phi", "sigma", "theta"))
        assert got == expected, (stated, expected)
        seen.add(got)
    collect()
    varies = {"linear": {2}, "subdifferential": {1}, "moving_set": {2}, "shifted": set(), "lcs": {0, 1, 2}}[family]
    for i in varies:
        assert {g[i] for g in seen} == {True, False}, (family, i, seen)


@FAST
@given(vs.ac_inputs(T=1.5), st.floats(0.0, 1.5))
def test_ac_input_bound(u, t):
    assert np.linalg.norm(u(t)) <= u.bound + tolerance(u(t))


def test_logbarrier_theta_is_needed_and_nearly_tight():
    """∂(-c(t) ln x) with c = 1 + t (L = 1): at r = √(x² + 4λc) = √(3λc²/δ), δ = Lλ, the Yosida value at s + λ
    exceeds |F^0(s, x)| by 2L^{3/2}λ/(3√3 c) - O(λ²) — so θ ≡ 0 fails and the stated θ = LOGBARRIER_YB·L^{3/2}/c_min·t
    (the derivation's maximum) holds with little room."""
    from verimono import LogBarrier

    c = vs.TimeFunction(1.0, 1.0, "affine")
    op = LogBarrier(c, 1)
    rate = vs.LOGBARRIER_YB * c.lipschitz ** 1.5 / 1.0
    for lam in (1e-2, 1e-3):
        x = np.array([np.sqrt(3.0 - 4.0 * lam)])            # r² = 3λc²/δ = 3 at s = 0
        Y = float(np.linalg.norm((x - op.resolvent(x, lam, lam)) / lam))
        excess = Y - float(np.linalg.norm(op.min_norm(x, 0.0)))
        assert 0.9 * rate * lam < excess <= rate * lam, (lam, excess, rate * lam)


def test_shift_constants_are_needed():
    """Stated.shifted: F = ∇(½x²) shifted by Φ = 2t (u ≡ 2, M = 2): |G^0(1, 0)| = |Φ(1)| = 2 exceeds σ = 1 but not
    σ(1)(1 + M) = 3 (LG); N_[0,1] shifted: dom G(t) = [-2t, 1 - 2t] moves by 2(t - s) = Mt-increments (A3)."""
    from verimono import Linear, NormalCone
    from verimono.core.sets import Box

    u = vs.ACInput("const", np.array([2.0]), np.zeros(1))
    g = vs.Stated(Linear([[1.0]]), phi=vs.ZERO, sigma=vs.Constant(1.0), theta=vs.ZERO).shifted(u)
    assert g.theta is None                                    # (YB) fails for shifts (see Stated.shifted)
    f0 = float(np.linalg.norm(g.operator.min_norm(np.zeros(1), 1.0)))
    assert 1.0 < f0 == 2.0 <= g.sigma(1.0)
    n = vs.Stated(NormalCone(Box([0.0], [1.0])), phi=vs.ZERO, sigma=vs.ZERO, theta=vs.ZERO).shifted(u)
    z = n.operator.project_domain(np.array([1.0]), 0.0)                                  # 1 ∈ dom G(0)
    d = float(np.linalg.norm(z - n.operator.project_domain(z, 0.25)))
    assert d == pytest.approx(0.5) and d <= n.phi(0.25) - n.phi(0.0) + 1e-12


@FAST
@given(vs.convex_sets(6, kinds=("polyhedron", "halfspace")))
def test_constraint_normals_have_no_rounding_sized_components(S):
    """Rows of G and A (and half-space normals) have components 0 or ≥ ENTRY_FLOOR: near-parallel rows 1e-7
    apart in angle make projections no double-precision QP verifies (see _nonzero_vectors)."""
    for param in (getattr(S, "_G", None), getattr(S, "_A", None), getattr(S, "_a", None)):
        if param is not None:
            M = np.abs(np.asarray(param(0.0)))
            assert np.all((M == 0) | (M >= vs.ENTRY_FLOOR)), M
