"""Maximal monotone operators: monotone linear maps, subdifferentials, normal cones of moving sets, their
input shifts, each with the functions of the assumptions that hold for it by construction
(:class:`Stated`); the fixed :func:`catalog`.  Bounds: :mod:`verimono.strategies`."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from hypothesis import strategies as st

from ..core import sets as _sets
from ..core.operators import (L1Subdifferential, Linear, LogBarrier, NormalCone, NormSubdifferential, Operator,
                         Shifted)
from .sets import MovingSet, convex_sets, moving_sets
from .values import (ZERO, ACInput, TimeFunction, Constant, _dim, _fmt, _Grown, _nonneg_time_functions, _NormOf,
                     _PlusRate, Rate, _vec, ac_inputs, floats, psd_matrices)


# -- linear operators ------------------------------------------------------------------------------

def monotone_linear_operators(n: int | None = None, time_dependent: bool | None = None
                              ) -> st.SearchStrategy[Linear]:
    """``Linear(M(t))`` with ``M(t) = M0 + g(t) M1``, ``M0, M1`` from :func:`psd_matrices` and
    ``g ∈ {0, t, t², 1 + sin ωt} ≥ 0`` on ``t ≥ 0``, so ``M(t) + M(t)ᵀ ⪰ 0`` for every ``t ≥ 0``
    (the operators of :func:`stated_linear_operators`)."""
    return stated_linear_operators(n, time_dependent).map(_operator_of)


def stated_linear_operators(n: int | None = None, time_dependent: bool | None = None
                            ) -> st.SearchStrategy["Stated"]:
    """:func:`monotone_linear_operators` with their assumptions: ``dom F = R^n`` so (A3) with ``φ ≡ 0``;
    (LG) with ``σ(t) = ‖M(t)‖₂`` (``|F^0(t,x)| = |M(t)x| ≤ ‖M(t)‖₂|x|``); (YB) with ``θ ≡ 0`` for a constant
    ``M`` (Prop. ``prop:maxmon-resolvent-Yosida`` vi), not stated for a moving one (its Yosida values move by
    ``O(λ|x|)``, not uniformly in ``x``)."""
    @st.composite
    def _draw(draw):
        k = draw(_dim(n), label="n")
        M0 = draw(psd_matrices(k), label="M0")
        td = draw(st.booleans(), label="time_dependent") if time_dependent is None else time_dependent
        if not td:
            return Stated(Linear(M0, name=f"Linear[M={_fmt(M0)}]"), phi=ZERO,
                          sigma=Constant(float(np.linalg.norm(M0, 2))), theta=ZERO)
        M1 = draw(psd_matrices(k), label="M1")
        g = draw(st.sampled_from(["t", "t^2", "1+sin(t)"]), label="g")
        fn = _MatrixPath(M0, M1, g)
        return Stated(Linear(fn, name=f"Linear[M(t)={fn!r}]"), phi=ZERO, sigma=_NormOf(fn))
    return _draw()


@dataclasses.dataclass(frozen=True)
class _MatrixPath:
    """``t ↦ M0 + g(t) M1`` with ``g ≥ 0`` on ``t ≥ 0``."""

    M0: np.ndarray
    M1: np.ndarray
    g: str

    @property
    def __name__(self) -> str:
        return repr(self)

    def __call__(self, t: float) -> np.ndarray:
        w = {"t": t, "t^2": t * t, "1+sin(t)": 1.0 + np.sin(t)}[self.g]
        return self.M0 + w * self.M1

    def __repr__(self) -> str:
        return f"{_fmt(self.M0)} + {self.g}·{_fmt(self.M1)}"


def _operator_of(stated: "Stated") -> Operator:
    return stated.operator


@dataclasses.dataclass(frozen=True)
class Stated:
    """An operator with the functions of the paper's assumptions that hold for it by construction on
    ``t ≥ 0``: ``phi`` of (A3), ``sigma`` of (LG), ``theta`` of (YB) (nondecreasing, as the assumptions
    require).  ``None``: not stated — the assumption fails (``(LG)`` for the log-barrier, ``(YB)`` for a
    moving set) or its constant is not explicit; the laws needing it then skip with that reason.
    ``system``: the :class:`verimono.lcs.LinearRelationSystem` of a Section 7 operator ``H``.
    """

    operator: Operator
    phi: Any = None
    sigma: Any = None
    theta: Any = None
    system: Any = None

    @property
    def dim(self) -> int:
        return self.operator.dim

    def assumptions(self) -> dict[str, Any]:
        """``phi``/``sigma``/``theta`` as keyword arguments of :class:`verimono.Problem`."""
        return {"phi": self.phi, "sigma": self.sigma, "theta": self.theta}

    def shifted(self, u: "ACInput") -> "Stated":
        """``G(t, ξ) = F(t, ξ + Φ(t))``, ``Φ = ∫_0^t u`` (lemma ``l:extinput``), with ``M = sup|u|`` so that
        ``|Φ(t) - Φ(s)| ≤ M(t - s)`` and ``|Φ(t)| ≤ Mt``: (A3) with ``φ + Mt`` (``dom G(t) = dom F(t) - Φ(t)``);
        (LG) with ``σ(t)(1 + Mt)`` (``|G^0(t,ξ)| ≤ σ(t)(1 + |ξ| + |Φ(t)|)``).  (YB) is not stated: it fails
        in general — ``Y^G_λ(s+λ, ξ) = Y^F_λ(s+λ, ξ + Φ(s+λ))`` moves by up to ``|Φ(s+λ) - Φ(s)|/λ ≈ |u|``,
        an amount that does not vanish with ``λ`` (``F = ∂|·|``, ``u = 1``: ``|Y^G_λ(λ, 0)| = 1`` while
        ``G^0(0, 0) = 0``, for every ``λ ≤ 1``)."""
        M = u.bound
        G = Shifted(self.operator, u.integral, name=f"Shifted[{self.operator.name}, Φ=∫{u!r}]")
        return Stated(G, phi=None if self.phi is None else _PlusRate(self.phi, M),
                      sigma=None if self.sigma is None else _Grown(self.sigma, M))

    def __repr__(self) -> str:
        return f"Stated({self.operator.name}, φ={self.phi!r}, σ={self.sigma!r}, θ={self.theta!r})"


# -- operators --------------------------------------------------------------------------------------

def subdifferential_operators(n: int | None = None, time_dependent: bool | None = None
                              ) -> st.SearchStrategy[Operator]:
    """Subdifferentials of convex functions: ``∂(c‖·‖₂)``, ``∂(Σ cᵢ|xᵢ|)``, ``∂(-c Σ ln xᵢ)``,
    ``N_S = ∂ι_S`` (static sets) and ``∇(½xᵀPx)`` with ``P = Pᵀ ⪰ 0``.  Weights ``c(t) ≥ 0``
    (``> 0`` for the barrier) are constant, increasing affine or sinusoidal (the operators of
    :func:`stated_subdifferential_operators`)."""
    return stated_subdifferential_operators(n, time_dependent).map(_operator_of)


#: the Yosida values of the log-barrier ``-c/x`` move with ``c`` by at most ``LOGBARRIER_YB · L^{3/2}/c_min · λ``
#: per component (``L = Lip(c)``): ``max_r (Lλ/r - λc²/r³) = 2(Lλ)^{3/2}/(3√3 √λ c)`` — see
#: :func:`stated_subdifferential_operators`
LOGBARRIER_YB = 2.0 / (3.0 * np.sqrt(3.0))


def stated_subdifferential_operators(n: int | None = None, time_dependent: bool | None = None
                                     ) -> st.SearchStrategy[Stated]:
    """:func:`subdifferential_operators` with their assumptions (all domains are static: φ ≡ 0).

    * ``∂(c(t)|·|)``: ``|F^0| ≤ c`` so σ = c; (YB) with ``θ = Lip(c)·t``: ``|Y_λ(s+λ,x)| = min(|x|/λ,
      c(s+λ)) ≤ c(s+λ) - c(s) + |F^0(s,x)|`` for ``x ≠ 0`` (0 at 0) — the paper's example ``g = t|x|``,
      ``θ(s) = s``; a sinusoidal ``c`` is not monotone, ``θ`` is then its Lipschitz majorant.
    * ``∂(Σ c(t)|x_i|)``: σ = ``|c(t) 1|``; ``Y_λ`` is componentwise ``min(|x_i|/λ, c) sgn x_i``, so (YB) with
      ``θ = √n Lip(c) t``.
    * ``∂(-c(t) Σ ln x_i)``: (LG) fails (``|F^0| = c/x`` is unbounded near the boundary).  (YB): per
      component ``|Y_λ| = f(c) = (√(x² + 4λc) - x)/(2λ)`` is concave in ``c`` with ``f' = 1/r``,
      ``r = √(x² + 4λc)``, and ``c/x - f(c) = 4λc²/(x(r + x)²) ≥ λc²/r³``; with ``c(s+λ) - c(s) ≤ Lλ``,
      ``|Y_λ(s+λ,x)_i| - |F^0(s,x)_i| ≤ Lλ/r - λc²/r³ ≤ LOGBARRIER_YB·L^{3/2}λ/c_min``, so
      ``θ = √n·LOGBARRIER_YB·L^{3/2}/c_min·t``.
    * ``N_S`` (static), ``∇(½xᵀPx)``: static, ``θ ≡ 0``; σ = 0 and ``‖P‖₂``.
    """
    @st.composite
    def _draw(draw):
        k = draw(_dim(n), label="n")
        kind = draw(st.sampled_from(["norm", "l1", "normalcone", "quadratic", "logbarrier"]), label="kind")
        td = draw(st.booleans(), label="time_dependent") if time_dependent is None else time_dependent
        if kind == "norm":
            c = draw(_nonneg_time_functions(0.0, 5.0) if td else floats(0.0, 5.0).map(lambda v: TimeFunction(v, 0.0)))
            op = NormSubdifferential(c if td else c.a, k, name=f"NormSubdifferential[c={c!r}, n={k}]")
            return Stated(op, phi=ZERO, sigma=_NormOf(c), theta=Rate(c.lipschitz))
        if kind == "l1":
            if td:
                c = draw(_nonneg_time_functions(0.0, 5.0))
                op = L1Subdifferential(c, k, name=f"L1Subdifferential[c={c!r}, n={k}]")
                root = float(np.sqrt(k))
                return Stated(op, phi=ZERO, sigma=_NormOf(c, root), theta=Rate(root * c.lipschitz))
            c = draw(_vec(k, 0.0, 5.0))
            return Stated(L1Subdifferential(c, k, name=f"L1Subdifferential[c={_fmt(c)}]"), phi=ZERO,
                          sigma=Constant(float(np.linalg.norm(c))), theta=ZERO)
        if kind == "logbarrier":
            c = draw(_nonneg_time_functions(0.1, 5.0) if td else floats(0.1, 5.0).map(lambda v: TimeFunction(v, 0.0)))
            op = LogBarrier(c if td else c.a, k, name=f"LogBarrier[c={c!r}, n={k}]")
            cmin = float(c.a) - (abs(float(c.b)) if c.kind == "sin" else 0.0)
            rate = np.sqrt(k) * LOGBARRIER_YB * c.lipschitz ** 1.5 / cmin
            return Stated(op, phi=ZERO, theta=Rate(float(rate)))
        if kind == "quadratic":
            P = draw(psd_matrices(k, symmetric=True))
            return Stated(Linear(P, name=f"Gradient[P={_fmt(P)}]"), phi=ZERO,
                          sigma=Constant(float(np.linalg.norm(P, 2))), theta=ZERO)
        S = draw(convex_sets(k))
        return Stated(NormalCone(S, name=f"NormalCone[{S.name}]"), phi=ZERO, sigma=ZERO, theta=ZERO)
    return _draw()


def stated_moving_set_normal_cones(n: int | None = None, T: float = 1.0) -> st.SearchStrategy[Stated]:
    """``N_{S(t)}`` for :func:`moving_sets`: (A3) with their ``φ = rate·t``; ``F^0 = 0`` on ``S(t)`` so (LG)
    with ``σ ≡ 0``; (YB) only for a set that does not move (``θ ≡ 0``) — for ``rate > 0``,
    ``|Y_λ(s+λ, x)| = dist(x, S(s+λ))/λ`` is of order ``rate`` at ``F^0 = 0``, which no ``θ`` increment
    ``θ(s+λ) - θ(s) → 0`` bounds: (YB) fails and is not stated."""
    def build(ms: MovingSet) -> Stated:
        op = NormalCone(ms.set, name=f"NormalCone[{ms.set.name}]")
        return Stated(op, phi=Rate(ms.rate), sigma=ZERO, theta=ZERO if ms.rate == 0 else None)
    return moving_sets(n, T).map(build)


def stated_operators(n: int | None = None, T: float = 1.0,
                     families: tuple[str, ...] = ("linear", "subdifferential", "moving_set"),
                     shifted: bool | None = None) -> st.SearchStrategy[Stated]:
    """An operator of one of ``families`` with its assumptions (:class:`Stated`), optionally shifted by
    ``Φ = ∫_0^t u`` for an absolutely continuous ``u`` of :func:`ac_inputs` (:meth:`Stated.shifted`;
    ``shifted=None`` draws it)."""
    makers = {"linear": lambda k: stated_linear_operators(k),
              "subdifferential": lambda k: stated_subdifferential_operators(k),
              "moving_set": lambda k: stated_moving_set_normal_cones(k, T)}

    @st.composite
    def _draw(draw):
        k = draw(_dim(n), label="n")
        base = draw(st.one_of(*(makers[f](k) for f in families)), label="F")
        if draw(st.booleans(), label="shifted") if shifted is None else shifted:
            return base.shifted(draw(ac_inputs(k, T), label="u"))
        return base
    return _draw()


def maximal_monotone_operators(n: int | None = None, T: float = 1.0) -> st.SearchStrategy[Operator]:
    """Every family: monotone linear maps (also time-dependent), subdifferentials (also with moving
    weights), normal cones of moving sets (the sweeping process, with (A3) from :func:`moving_sets`) and
    ``Shifted(F, Φ)`` (the input shift of Section 6) of any of these with ``Φ(t) = ∫_0^t u`` for an
    absolutely continuous ``u`` from :func:`ac_inputs` (the operators of :func:`stated_operators`)."""
    return stated_operators(n, T).map(_operator_of)


def catalog(n: int = 2) -> list[Operator]:
    """Fixed representatives of every catalog operator on ``R^n`` (``n ≥ 2``): static and time-dependent,
    shifted, normal cones of every set type (static and moving), the log-barrier.  Used to show that no
    law fails on a correct operator."""
    if n < 2:
        raise ValueError("catalog() needs n >= 2")
    rng = np.random.default_rng(12345)
    e = np.eye(n)
    M = rng.uniform(-1, 1, (n, n))
    M = M @ M.T / n + (M - M.T)
    Msing = np.outer(e[0], e[0]) + (np.outer(e[0], e[1]) - np.outer(e[1], e[0]))
    G = np.vstack([np.ones(n), -e[0], e[1] - e[0]])
    Gp = rng.uniform(-1, 1, (n + 1, n))
    return [
        Linear(M, name="Linear[M]"),
        Linear(Msing, name="Linear[singular]"),
        Linear(lambda t: M + t * t * np.eye(n), name="Linear[M + t²I]"),
        NormSubdifferential(1.5, n, name="NormSubdifferential[c=1.5]"),
        NormSubdifferential(lambda t: t, n, name="NormSubdifferential[c=t]"),
        L1Subdifferential(np.linspace(0.0, 2.0, n), n, name="L1Subdifferential[c=0..2]"),
        L1Subdifferential(lambda t: 1.0 + np.sin(3 * t), n, name="L1Subdifferential[c=1+sin 3t]"),
        LogBarrier(1.0, n, name="LogBarrier[c=1]"),
        LogBarrier(lambda t: 0.5 + t, n, name="LogBarrier[c=0.5+t]"),
        NormalCone(_sets.Ball(np.zeros(n), 1.0), name="NormalCone[Ball]"),
        NormalCone(_sets.Ball(lambda t: np.full(n, t), lambda t: 1.0 + 0.5 * np.sin(t)), name="NormalCone[moving Ball]"),
        NormalCone(_sets.Box(-np.ones(n), np.r_[np.inf, np.ones(n - 1)]), name="NormalCone[Box]"),
        NormalCone(_sets.Box(lambda t: -np.ones(n) + t, lambda t: np.ones(n) + 2 * t), name="NormalCone[moving Box]"),
        NormalCone(_sets.HalfSpace(np.ones(n), 0.5), name="NormalCone[HalfSpace]"),
        NormalCone(_sets.HalfSpace(e[0], lambda t: -t), name="NormalCone[moving HalfSpace]"),
        NormalCone(_sets.Polyhedron(G, np.array([1.0, 1.0, 1.0])), name="NormalCone[Polyhedron]"),
        NormalCone(_sets.Polyhedron(Gp, Gp @ np.full(n, 0.3) + 0.5, e[:1], np.array([0.3])),
                   name="NormalCone[Polyhedron with equality]"),
        NormalCone(_sets.Translated(_sets.Ball(np.zeros(n), 0.0), lambda t: np.full(n, np.cos(t))),
                   name="NormalCone[moving point]"),
        Shifted(L1Subdifferential(1.0, n), lambda t: np.full(n, t), name="Shifted[L1, Φ=t]"),
        Shifted(NormalCone(_sets.Box(-np.ones(n), np.ones(n))), lambda t: np.sin(np.arange(1, n + 1) * t),
                name="Shifted[NormalCone Box, Φ=sin]"),
        Shifted(LogBarrier(1.0, n), np.full(n, -0.5), name="Shifted[LogBarrier, Φ=-1/2]"),
        Shifted(Linear(M), lambda t: t * e[0], name="Shifted[Linear, Φ=t e1]"),
    ]


def catalog_operators(n: int = 2) -> st.SearchStrategy[Operator]:
    """One of :func:`catalog` (shrinks toward the first, a static linear map)."""
    return st.sampled_from(catalog(n))
