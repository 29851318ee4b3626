"""is_passive: the KYP LMI with K = I (eigenvalues) or K unknown (SDP), and Proposition p:pass."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from verimono.lcs import is_passive
from verimono.lcs.passivity import MissingOptionalDependency, kyp_matrix

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
    r = is_passive(*DIODE, trace_bound=1.0)
    assert r and r.kernel_ok
    # the kernel condition forces K B = Cᵀ on ker(D + Dᵀ): K = diag(C, L) up to round-off
    np.testing.assert_allclose(r.K, np.diag([Cc, L]), atol=1e-9)
    assert not is_passive([[1.0]], [[1.0]], [[1.0]], [[0.0]])


def test_missing_sdp_dependency_is_a_clear_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "cvxpy", None)
    with pytest.raises(MissingOptionalDependency, match="optional extra 'sdp'"):
        is_passive(*EXAMPLE)
