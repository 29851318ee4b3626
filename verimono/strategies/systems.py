"""Systems of Section 7: passive ``Σ(A, B, C, D)`` with a stated storage (KYP, ``e:lmis``) and the operators
``H(t,·)`` of linear complementarity systems with their assumptions.  Bounds: :mod:`verimono.strategies`."""

from __future__ import annotations

import dataclasses

import numpy as np
from hypothesis import strategies as st

from ..lcs.relations import Complementarity
from ..lcs.system import LinearRelationSystem
from .operators import Stated
from .values import ZERO, TimeFunction, Constant, _dim, _fmt, _mat, _vec, floats


# -- passive systems --------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class PassiveSystem:
    """``Σ(A, B, C, D)`` passive with storage ``½ xᵀKx``: the KYP LMI ``e:lmis`` of Section 7 holds,
    ``K = Kᵀ ⪰ 0`` and ``[[AᵀK + KA, KB - Cᵀ], [BᵀK - C, -(D + Dᵀ)]] ⪯ 0``."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    K: np.ndarray

    @property
    def n(self) -> int:
        return self.A.shape[0]

    @property
    def m(self) -> int:
        return self.B.shape[1]

    def kyp_matrix(self, K: np.ndarray | None = None) -> np.ndarray:
        """The block matrix of ``e:lmis`` (``⪯ 0`` for a storage ``K``)."""
        K = self.K if K is None else K
        A, B, C, D = self.A, self.B, self.C, self.D
        return np.block([[A.T @ K + K @ A, K @ B - C.T], [B.T @ K - C, -(D + D.T)]])

    def __repr__(self) -> str:
        return (f"PassiveSystem(A={_fmt(self.A)}, B={_fmt(self.B)}, C={_fmt(self.C)}, "
                f"D={_fmt(self.D)}, K={_fmt(self.K)})")


def passive_systems(n: int | None = None, m: int | None = None, storage: str | None = None
                    ) -> st.SearchStrategy[PassiveSystem]:
    """Passive ``Σ(A, B, C, D)`` with a stated storage ``K`` (``storage="identity"``: ``K = I`` as in
    Section 7's theorems; ``"general"``: ``K = U diag(k) Uᵀ ⪰ 0``, possibly singular; ``None``: either).

    Built by design: draw ``Π = -GGᵀ ⪯ 0`` on ``R^{n+m}`` (rows of ``G`` vanish on ``ker K``, rank drawn,
    so lossless systems are included), skew ``S, Ŝ`` and any ``B``; in coordinates ``x̃ = Uᵀx`` with
    ``K̃ = diag(k₁, 0)`` set ``Ã₁₁ = k₁⁻¹(Π₁₁/2 + S)``, ``Ã₁₂ = 0`` (``Ã₂•`` free),
    ``C̃ = B̃ᵀK̃ - Π₁₂ᵀ``, ``D = -Π₂₂/2 + Ŝ``.  Then the KYP block equals ``diag(U, I) Π diag(U, I)ᵀ ⪯ 0``.
    """
    @st.composite
    def _draw(draw):
        k_n = draw(_dim(n), label="n")
        k_m = draw(_dim(m), label="m")
        kind = draw(st.sampled_from(["identity", "general"]), label="storage") if storage is None else storage
        if kind == "identity":
            U, kd = np.eye(k_n), np.ones(k_n)
        elif kind == "general":
            U = np.linalg.qr(draw(_mat(k_n, k_n, -1.0, 1.0), label="U") + 3.0 * np.eye(k_n))[0]
            kd = draw(st.lists(st.one_of(st.just(0.0), floats(0.25, 4.0)), min_size=k_n, max_size=k_n),
                           label="k")
            kd = np.array(kd, dtype=float)
        else:
            raise ValueError(f"storage must be 'identity' or 'general', got {storage!r}")
        pos = kd > 0
        N = k_n + k_m
        q = draw(st.integers(0, N), label="rank Π")
        G = draw(_mat(N, q, -1.0, 1.0), label="G") if q else np.zeros((N, 0))
        G[:k_n][~pos] = 0.0
        Pi = -(G @ G.T)
        Pi = 0.5 * (Pi + Pi.T)
        S = draw(_mat(k_n, k_n, -1.0, 1.0), label="S")
        S = S - S.T
        Sh = draw(_mat(k_m, k_m, -1.0, 1.0), label="Ŝ")
        Sh = Sh - Sh.T
        Bt = draw(_mat(k_n, k_m, -2.0, 2.0), label="B")
        free = draw(_mat(k_n, k_n, -1.0, 1.0), label="A free rows")
        At = np.zeros((k_n, k_n))
        ip = np.flatnonzero(pos)
        At[np.ix_(ip, ip)] = (0.5 * Pi[np.ix_(ip, ip)] + S[np.ix_(ip, ip)]) / kd[ip][:, None]
        iz = np.flatnonzero(~pos)
        At[iz, :] = free[iz, :]
        Kt = np.diag(kd)
        Ct = Bt.T @ Kt - Pi[:k_n, k_n:].T
        D = -0.5 * Pi[k_n:, k_n:] + Sh
        A, B, C = U @ At @ U.T, U @ Bt, Ct @ U.T
        K = U @ Kt @ U.T
        return PassiveSystem(A, B, C, D, 0.5 * (K + K.T))
    return _draw()


#: smallest ``μ = λ_min((D + Dᵀ)/2)`` for which :func:`lcs_operators` states σ of (LG) through ``|z| ≤ |q|/μ``:
#: eigvalsh is accurate to ~1e-15‖D‖ (‖D‖ ≤ 8 here), so a smaller computed μ cannot be told from a singular
#: ``D + Dᵀ`` (where the constant of Theorem ``thm: linear case`` vi is not explicit), and σ ~ 1/μ would
#: exceed 10^6 — a bound that says nothing
LCS_MU_FLOOR = 1e-6


def lcs_operators(n: int | None = None, m: int | None = None, moving_v: bool | None = False
                  ) -> st.SearchStrategy[Stated]:
    """``H(t,·)`` of a linear complementarity system (Section 7): ``Σ(A, B, C, D)`` from
    :func:`passive_systems` with storage ``K = I`` (Theorem ``thm: linear case`` i), the complementarity
    relation (ii, a normal cone of ``R^m_+``) and ``v(t) ≥ v_0 > 0`` entrywise (``v_0 ∈ [1/4, 2]^m``;
    constant, or ``v_0 + |b| + b sin ωt`` with ``moving_v``): ``x = 0`` gives ``Cx + v(t) ∈ int R^m_+ ⊂
    int im(𝓟 + D)``, so ``im C ∩ ri(im(𝓟 + D) − v(t)) ≠ ∅`` (iii) holds by design and ``0 ∈ dom H(t,·)``;
    ``v`` is bounded and absolutely continuous (iv).  Dimensions ``n ≤ 3``, ``m ≤ 2`` unless given.

    Stated: for constant ``v``, ``H`` is static: (A3) with ``φ ≡ 0``, (YB) with ``θ ≡ 0``.  (LG) when
    ``μ = λ_min((D + Dᵀ)/2) > LCS_MU_FLOOR``: the multiplier of ``0 ≤ z ⊥ Dz + q ≥ 0`` has
    ``μ|z|² ≤ zᵀDz = −zᵀq``, so ``|H^0(t,x)| ≤ ‖A‖|x| + ‖B‖(‖C‖|x| + |v|)/μ ≤ σ(1 + |x|)`` with
    ``σ = ‖A‖ + ‖B‖(‖C‖ + sup|v|)/μ``.  A moving ``v`` moves ``dom H`` by a Hoffman-constant multiple of
    ``|v'|``: φ and θ are then not stated.
    """
    @st.composite
    def _draw(draw):
        k_n = draw(st.integers(1, 3), label="n") if n is None else int(n)
        k_m = draw(st.integers(1, 2), label="m") if m is None else int(m)
        ps = draw(passive_systems(k_n, k_m, storage="identity"), label="Σ")
        v0 = draw(_vec(k_m, 0.25, 2.0), label="v0")
        mv = draw(st.booleans(), label="moving v") if moving_v is None else moving_v
        if mv:
            b = draw(_vec(k_m, -1.0, 1.0), label="v1")
            w = draw(floats(0.5, 2 * np.pi), label="ω")
            v = TimeFunction(v0 + np.abs(b), b, "sin", w)
            vmax = float(np.linalg.norm(v0 + np.abs(b)) + np.linalg.norm(b))
        else:
            v, vmax = v0, float(np.linalg.norm(v0))
        vtext = repr(v) if mv else _fmt(v)
        name = f"LCS[A={_fmt(ps.A)}, B={_fmt(ps.B)}, C={_fmt(ps.C)}, D={_fmt(ps.D)}, v={vtext}]"
        system = LinearRelationSystem(ps.A, ps.B, ps.C, ps.D, Complementarity(), v=v, name=name)
        mu = float(np.linalg.eigvalsh(0.5 * (ps.D + ps.D.T))[0])
        sigma = None
        if mu > LCS_MU_FLOOR:
            nA, nB, nC = (float(np.linalg.norm(X, 2)) for X in (ps.A, ps.B, ps.C))
            sigma = Constant(nA + nB * (nC + vmax) / mu)
        static = None if mv else ZERO
        return Stated(system.operator(), phi=static, sigma=sigma, theta=static, system=system)
    return _draw()
