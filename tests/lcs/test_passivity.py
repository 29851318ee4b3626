"""is_passive: the KYP LMI with K = I (eigenvalues) or K unknown (SDP), and Proposition p:pass."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from verimono import SolverFailure
from verimono.lcs import is_passive
from verimono.lcs.passivity import MissingOptionalDependency, kyp_matrix
from verimono.core.tolerances import SDP_RTOL

L, Cc, R = 1e-2, 1e-6, 1e3
DIODE = (np.array([[0, -1 / Cc], [1 / L, 0]]), np.array([[0, 0, -1 / Cc, 1 / Cc], [0, 0, 0, 0]]),
         np.array([[0, 0], [0, 0], [-1, 0], [1, 0]]),
         np.array([[1 / R, 1 / R, -1, 0], [1 / R, 1 / R, 0, -1], [1, 0, 0, 0], [0, 1, 0, 0]]))
EXAMPLE = (np.zeros((1, 1)), np.array([[0.0, 1.0]]), np.array([[0.0], [1.0]]), np.array([[0.0, 1.0], [-1.0, 0.0]]))


def test_identity_storage():
    r = is_passive(*EXAMPLE, K=np.eye(1))
    assert r and r.D_psd and r.kernel_ok and r.margin == 0.0
    # the diode bridge is passive with the physical storage ½(C Vc² + L IL²), not with ½|x|²
    assert not is_passive(*DIODE, K=np.eye(2))
    r = is_passive(*DIODE, K=np.diag([Cc, L]))
    assert r and r.kernel_ok and np.abs(kyp_matrix(*DIODE, np.diag([Cc, L]))[:2, :2]).max() == 0.0


def test_non_passive_and_proposition_consequences():
    r = is_passive([[1.0]], [[1.0]], [[1.0]], [[0.0]], K=np.eye(1))   # unstable A: AᵀK + KA = 2 > 0
    assert not r and r.margin == pytest.approx(-2.0)
    r = is_passive([[-1.0]], [[1.0]], [[1.0]], [[-1.0]], K=np.eye(1))  # D not PSD (Prop. p:pass i fails)
    assert not r and not r.D_psd
    r = is_passive([[-1.0]], [[2.0]], [[1.0]], [[0.0]], K=np.eye(1))   # (KB − Cᵀ) ker(D + Dᵀ) = 1 ≠ 0
    assert not r and not r.kernel_ok and r.kernel_residual == pytest.approx(1.0)


def test_sdp_finds_a_storage_matrix():
    pytest.importorskip("cvxpy")
    r = is_passive(*DIODE)
    assert r and r.kernel_ok
    # the kernel condition forces K B = Cᵀ on ker(D + Dᵀ): K = diag(C, L) up to round-off
    np.testing.assert_allclose(r.K, np.diag([Cc, L]), atol=1e-9)
    assert not is_passive([[1.0]], [[1.0]], [[1.0]], [[0.0]])


@pytest.mark.parametrize("b", [1e-2, 1e-4])
def test_sdp_finds_a_large_storage_without_a_trace_bound(b):
    """A = 0, B = b, C = 1, D = 0: Q(K) = [[0, bK − 1], [bK − 1, 0]] ⪯ 0 iff K = 1/b exactly (no interior).
    Seen failing: the SDP with tr K ≤ n returned K = 1, margin −0.99, passive=False."""
    pytest.importorskip("cvxpy")
    r = is_passive([[0.0]], [[b]], [[1.0]], [[0.0]])
    assert r and r.passive is True and r.certificate is None
    assert r.K[0, 0] == pytest.approx(1.0 / b, rel=1e-6)
    # independent eigenvalue check of the returned K at the stated SDP accuracy (units of KB and C: size 1)
    lam_max = np.linalg.eigvalsh(kyp_matrix(np.zeros((1, 1)), np.array([[b]]), np.ones((1, 1)), np.zeros((1, 1)),
                                            r.K))[-1]
    assert lam_max <= SDP_RTOL * 2 and r.margin == pytest.approx(-lam_max)


@pytest.mark.parametrize("system", [([[1.0]], [[1.0]], [[1.0]], [[0.0]]),     # unstable: needs K = 1 and 2K ≤ 0
                                    ([[-1.0]], [[1.0]], [[1.0]], [[-1.0]])])  # D + Dᵀ = −2: Prop. p:pass i fails
def test_sdp_certifies_a_non_passive_system(system):
    """"Not passive" comes with a Farkas certificate Z ⪰ 0, L*(Z) ⪰ 0, ⟨Z, Q(0)⟩ = 1 > 0, checked here by
    hand: for a feasible K, 0 ≤ ⟨Z, −Q(K)⟩ = −1 − ⟨L*(Z), K⟩ < 0."""
    pytest.importorskip("cvxpy")
    r = is_passive(*system)
    assert not r and r.passive is False and r.K is None and r.margin == -np.inf
    a, bb = system[0][0][0], system[1][0][0]
    Z = r.certificate["Z"]
    assert np.linalg.eigvalsh(Z)[0] >= -1e-12
    assert np.sum(Z * kyp_matrix(*[np.array(X, float) for X in system], np.zeros((1, 1)))) == pytest.approx(1.0)
    assert 2 * a * Z[0, 0] + 2 * bb * Z[0, 1] >= -SDP_RTOL        # L*(Z) = 2aZ11 + 2bZ12 for n = m = 1


def test_solver_failure_is_a_solver_failure_with_status(monkeypatch):
    """Seen failing: a Clarabel failure was raised as MissingOptionalDependency."""
    cp = pytest.importorskip("cvxpy")

    def broken(self, *a, **k):
        self._status = "solver_error"
        raise cp.error.SolverError("Solver 'CLARABEL' failed. Try another solver")

    monkeypatch.setattr(cp.Problem, "solve", broken)
    with pytest.raises(SolverFailure, match="status solver_error.*CLARABEL' failed") as info:
        is_passive(*EXAMPLE)
    assert not isinstance(info.value, MissingOptionalDependency)


def test_an_unverified_answer_is_undecided_never_false(monkeypatch):
    """An inaccurate "optimal" K that fails the eigenvalue check, or no answer at all, is inconclusive:
    SolverFailure naming the status.  Seen failing: passive=False was returned for the first, an untyped
    VerimonoError raised for the second."""
    cp = pytest.importorskip("cvxpy")

    def inaccurate(self, *a, **k):
        self._status = "optimal_inaccurate"
        (K,) = self.variables()
        K.value = np.eye(K.shape[0])       # Q(I) = [[2, 0], [0, 0]] for the unstable system: not verified

    monkeypatch.setattr(cp.Problem, "solve", inaccurate)
    with pytest.raises(SolverFailure, match="undecided.*optimal_inaccurate.*fails the eigenvalue check"):
        is_passive([[1.0]], [[1.0]], [[1.0]], [[0.0]])

    def nothing(self, *a, **k):
        self._status = "infeasible_inaccurate"

    monkeypatch.setattr(cp.Problem, "solve", nothing)
    with pytest.raises(SolverFailure, match="undecided.*infeasible_inaccurate.*no K returned"):
        is_passive(*EXAMPLE)


def test_missing_sdp_dependency_is_a_clear_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "cvxpy", None)
    with pytest.raises(MissingOptionalDependency, match="optional extra 'sdp'"):
        is_passive(*EXAMPLE)
