"""Hypothesis strategies for verimono's objects, valid by construction and shrinking toward simple cases.

Every strategy builds its object so that the property it is advertised with holds exactly in exact
arithmetic (no ``assume``/``filter`` rejection): a PSD matrix is ``LLᵀ + S`` with ``S`` skew, a polyhedron
is built around a point it contains, a passive system is solved from a negative semidefinite KYP block.
Everything shrinks toward the zero/identity/smallest case (dimension 1, zero entries, rank 0, constant in
time, one grid cell).

Bounds (so that conditioning stays moderate and the tolerances of :mod:`verimono.tolerances` apply):

* dimensions ``1 ≤ n ≤ MAX_DIM = 6`` when drawn, ``1 ≤ m ≤ 6`` inputs;
* points have entries in ``[-POINT_SCALE, POINT_SCALE] = [-10, 10]``;
* :func:`psd_matrices`: ``M = LLᵀ + W - Wᵀ`` with entries of ``L`` and ``W`` in ``[-1, 1]``, so
  ``|M_ij| ≤ n + 2 ≤ 8``; ``M + Mᵀ = 2LLᵀ`` has rank ``≤ rank`` (singular ones included);
* sets: centres/offsets in ``[-5, 5]``, radii and widths in ``[0, 5]`` (degenerate ones included),
  normals with a component of size ``≥ 1/2``; polyhedra have ``≤ 2n`` inequality rows (each with a
  component ``≥ 1/2``) and ``≤ n - 1`` equality rows, and contain the drawn point ``p``;
* time dependence on ``[0, T]`` through :class:`TimeFunction` (constant, affine, sinusoid with
  ``ω ≤ 2π``), each with a stated Lipschitz constant; moving sets carry ``φ`` with (A3)
  ``sup_{z ∈ S(s)} dist(z, S(t)) ≤ φ(t) - φ(s)``;
* passive systems: KYP data with entries in ``[-2, 2]``, storage ``K = U diag(k) Uᵀ`` with
  ``k ∈ {0} ∪ [1/4, 4]``;
* matrix entries and constraint normals have components 0 or at least ``ENTRY_FLOOR = 1e-3`` in magnitude
  (no rounding-sized entries, no constraints 1e-7 apart in angle);
* grids: ``1 ≤ K ≤ 64`` cells, nonuniform ones with step ratios ``≤ 100``.

Drawn objects have readable reprs (numbers rounded to 4 digits) so counterexamples can be read.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from hypothesis import strategies as st

from . import sets as _sets
from .grids import validate_grid
from .operators import (L1Subdifferential, Linear, LogBarrier, NormalCone, NormSubdifferential, Operator,
                        Shifted)

MAX_DIM = 6
POINT_SCALE = 10.0
SET_SCALE = 5.0
MAX_CELLS = 64

_PRETTY = dict(precision=4, separator=", ", suppress_small=True, floatmode="maxprec")


def _fmt(a: Any) -> str:
    a = np.asarray(a, dtype=float)
    if not a.ndim:
        return f"{float(a):.4g}"
    return " ".join(np.array2string(a, max_line_width=10_000, **_PRETTY).split())


def floats(lo: float, hi: float) -> st.SearchStrategy[float]:
    """Finite floats in ``[lo, hi]`` without subnormals (shrink toward 0 or the simplest value)."""
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False, allow_subnormal=False)


def _dim(n: int | None) -> st.SearchStrategy[int]:
    return st.integers(1, MAX_DIM) if n is None else st.just(int(n))


def _vec(n: int, lo: float, hi: float) -> st.SearchStrategy[np.ndarray]:
    return st.lists(floats(lo, hi), min_size=n, max_size=n).map(lambda v: np.array(v, dtype=float))


#: matrix entries are 0 or at least this in magnitude (entries are drawn in ranges of size ~1): an entry at
#: the size of rounding is no test of an operator, only of float64 — a drawn 1.2e-19 in G made
#: D = -GGᵀ/2 carry 1.4e-37, an operator of slope 3e37 whose resolvent rounds onto the far side of its graph
ENTRY_FLOOR = 1e-3


def _entry(v: float) -> float:
    return 0.0 if abs(v) < ENTRY_FLOOR else v


def _mat(r: int, c: int, lo: float, hi: float) -> st.SearchStrategy[np.ndarray]:
    """Matrices with entries in ``[lo, hi]`` that are 0 or at least ``ENTRY_FLOOR`` in magnitude."""
    return st.lists(floats(lo, hi).map(_entry), min_size=r * c, max_size=r * c).map(
        lambda v: np.array(v, dtype=float).reshape(r, c))


def points(n: int | None = None, scale: float = POINT_SCALE) -> st.SearchStrategy[np.ndarray]:
    """Points of ``R^n`` (shape ``(n,)``) with entries in ``[-scale, scale]``; shrink toward 0."""
    if n is not None:
        return _vec(int(n), -scale, scale)
    return _dim(n).flatmap(lambda k: _vec(k, -scale, scale))


def step_sizes(lo: float = 1e-3, hi: float = 10.0) -> st.SearchStrategy[float]:
    """Step sizes ``λ ∈ [lo, hi]``: simple values (1, 1/2, 2, 1/10, 10) first, then any float."""
    simple = [v for v in (1.0, 0.5, 2.0, 0.1, 10.0, 1e-3) if lo <= v <= hi]
    return st.one_of(st.sampled_from(simple), floats(lo, hi))


def times(T: float = 1.0) -> st.SearchStrategy[float]:
    """Times ``t ∈ [0, T]`` (0, T and T/2 first)."""
    return st.one_of(st.sampled_from([0.0, float(T), 0.5 * T]), floats(0.0, float(T)))


# -- time dependence ------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class TimeFunction:
    """``t ↦ a + b g(t)`` with ``g`` one of ``0``, ``t``, ``sin(ωt)``; vector or scalar valued.

    ``lipschitz`` is ``|b| · Lip(g)`` (``Lip(t) = 1``, ``Lip(sin ωt) = ω``), a bound on
    ``|p(t) - p(s)| / |t - s|``; ``bound`` bounds ``|g|`` on ``[0, T]`` via ``gmax(T)``.
    """

    a: Any
    b: Any
    kind: str = "const"      # "const" | "affine" | "sin"
    omega: float = 1.0

    @property
    def __name__(self) -> str:  # Param.describe uses it
        return repr(self)

    def g(self, t: float) -> float:
        if self.kind == "const":
            return 0.0
        if self.kind == "affine":
            return float(t)
        return float(np.sin(self.omega * t))

    def __call__(self, t: float) -> np.ndarray:
        return np.asarray(self.a, dtype=float) + self.g(t) * np.asarray(self.b, dtype=float)

    @property
    def slope(self) -> float:
        """Lipschitz constant of ``g``."""
        return {"const": 0.0, "affine": 1.0, "sin": self.omega}[self.kind]

    @property
    def lipschitz(self) -> float:
        return 0.0 if self.kind == "const" else float(np.linalg.norm(np.atleast_1d(self.b))) * self.slope

    def gmax(self, T: float) -> float:
        return {"const": 0.0, "affine": float(T), "sin": 1.0}[self.kind]

    def __repr__(self) -> str:
        if self.kind == "const":
            return _fmt(self.a)
        g = "t" if self.kind == "affine" else f"sin({self.omega:.4g}t)"
        return f"({_fmt(self.a)} + {g}·{_fmt(self.b)})"


def _kinds() -> st.SearchStrategy[tuple[str, float]]:
    return st.one_of(st.just(("const", 1.0)), st.just(("affine", 1.0)),
                     floats(0.5, 2 * np.pi).map(lambda w: ("sin", w)))


def time_functions(shape: tuple[int, ...] = (), lo: float = -SET_SCALE, hi: float = SET_SCALE,
                   rate: float = 2.0) -> st.SearchStrategy[TimeFunction]:
    """``a + b g(t)`` with ``a ∈ [lo, hi]``, ``|b_i| ≤ rate``, ``g ∈ {0, t, sin ωt}``."""
    size = int(np.prod(shape)) if shape else 1

    def build(kind, a, b):
        a = np.array(a).reshape(shape) if shape else float(a[0])
        b = np.array(b).reshape(shape) if shape else float(b[0])
        return TimeFunction(a, b * (kind[0] != "const"), kind[0], kind[1])
    return st.builds(build, _kinds(), st.lists(floats(lo, hi), min_size=size, max_size=size),
                     st.lists(floats(-rate, rate), min_size=size, max_size=size))


def _nonneg_time_functions(lo: float, hi: float, rate: float = 1.0) -> st.SearchStrategy[TimeFunction]:
    """Scalar ``c(t) ≥ lo`` on ``t ≥ 0``: ``c0 + c1 t`` (``c1 ≥ 0``) or ``c0 + c1 sin(ωt)`` with ``c0 - lo ≥ |c1|``."""
    def build(kind, c0, c1):
        if kind[0] == "const":
            return TimeFunction(c0, 0.0)
        if kind[0] == "affine":
            return TimeFunction(c0, abs(c1), "affine")
        amp = min(abs(c1), c0 - lo)
        return TimeFunction(c0, amp, "sin", kind[1])
    return st.builds(build, _kinds(), floats(lo, hi), floats(-rate, rate))


# -- matrices and linear operators ----------------------------------------------------------------

def psd_matrices(n: int | None = None, rank: int | None = None,
                 symmetric: bool | None = None) -> st.SearchStrategy[np.ndarray]:
    """``M ∈ R^{n×n}`` with ``M + Mᵀ ⪰ 0`` ("positive semi-definite" in the paper's sense, not symmetric).

    ``M = LLᵀ + (W - Wᵀ)`` with ``L ∈ R^{n×r}``: ``M + Mᵀ = 2LLᵀ`` has rank ``≤ r``, so ``r < n`` gives
    singular ones and ``r = 0`` a skew (lossless) one.  ``rank=None`` draws ``r ∈ [0, n]``;
    ``symmetric=True`` drops the skew part, ``False`` keeps it, ``None`` draws.  Entries of ``L, W`` lie
    in ``[-1, 1]``; the symmetric part is symmetrised exactly so ``M + Mᵀ`` is PSD up to rounding.
    """
    @st.composite
    def _draw(draw):
        k = draw(_dim(n), label="n")
        r = draw(st.integers(0, k), label="rank") if rank is None else int(rank)
        if not 0 <= r <= k:
            raise ValueError(f"rank must lie in [0, {k}], got {r}")
        L = draw(_mat(k, r, -1.0, 1.0), label="L") if r else np.zeros((k, 0))
        P = L @ L.T
        P = 0.5 * (P + P.T)
        sym = draw(st.booleans(), label="symmetric") if symmetric is None else symmetric
        if sym:
            return P
        W = draw(_mat(k, k, -1.0, 1.0), label="W")
        return P + (W - W.T)
    return _draw()


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
            return Stated(Linear(M0, name=f"Linear[M={_fmt(M0)}]"), phi=_ZERO,
                          sigma=_Const(float(np.linalg.norm(M0, 2))), theta=_ZERO)
        M1 = draw(psd_matrices(k), label="M1")
        g = draw(st.sampled_from(["t", "t^2", "1+sin(t)"]), label="g")
        fn = _MatrixPath(M0, M1, g)
        return Stated(Linear(fn, name=f"Linear[M(t)={fn!r}]"), phi=_ZERO, sigma=_NormOf(fn))
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


# -- the functions of the paper's assumptions -----------------------------------------------------

@dataclasses.dataclass(frozen=True)
class _Const:
    """``t ↦ value``."""

    value: float

    def __call__(self, t: float) -> float:
        return self.value

    def __repr__(self) -> str:
        return f"{self.value:.4g}"


@dataclasses.dataclass(frozen=True)
class _Rate:
    """``t ↦ rate·t`` (nondecreasing for ``rate ≥ 0``; ``0`` is the constant function 0)."""

    rate: float

    def __call__(self, t: float) -> float:
        return self.rate * float(t)

    def __repr__(self) -> str:
        return "0" if self.rate == 0 else f"{self.rate:.4g}·t"


_ZERO = _Rate(0.0)


@dataclasses.dataclass(frozen=True)
class _NormOf:
    """``t ↦ scale·|p(t)|`` (the spectral norm for a matrix-valued ``p``)."""

    p: Any
    scale: float = 1.0

    def __call__(self, t: float) -> float:
        v = np.asarray(self.p(t), dtype=float)
        return self.scale * float(np.linalg.norm(v, 2) if v.ndim == 2 else np.linalg.norm(v))

    def __repr__(self) -> str:
        return ("" if self.scale == 1.0 else f"{self.scale:.4g}·") + f"|{self.p!r}|"


@dataclasses.dataclass(frozen=True)
class _PlusRate:
    """``t ↦ f(t) + rate·t``."""

    f: Any
    rate: float

    def __call__(self, t: float) -> float:
        return float(self.f(t)) + self.rate * float(t)

    def __repr__(self) -> str:
        return f"{self.f!r} + {self.rate:.4g}·t"


@dataclasses.dataclass(frozen=True)
class _Grown:
    """``t ↦ σ(t)(1 + rate·t)``."""

    sigma: Any
    rate: float

    def __call__(self, t: float) -> float:
        return float(self.sigma(t)) * (1.0 + self.rate * float(t))

    def __repr__(self) -> str:
        return f"({self.sigma!r})(1 + {self.rate:.4g}·t)"


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


# -- convex sets ------------------------------------------------------------------------------------

def _nonzero_vectors(k: int, lo: float = 0.5, hi: float = 3.0) -> st.SearchStrategy[np.ndarray]:
    """Vectors with a component of size in ``[lo, hi]`` (nonzero by construction), the others 0 or at least
    ``ENTRY_FLOOR`` in magnitude: constraint normals (rows of ``G`` and ``A``) 1e-7 apart in angle make a
    polyhedron whose projection no double-precision QP answers to ``QP_RTOL`` (a dev-profile run drew eight
    such copies of ``e₁``; ProxQP returned nothing, DAQP a point 5e-9 outside), while rows that are equal or
    at least 1e-3 apart are solved (400 of 400 such polyhedra, measured)."""
    def build(v, i, s, sign):
        v = np.array([_entry(e) for e in v])
        v[i] = sign * s
        return v
    return st.builds(build, _vec(k, -hi, hi), st.integers(0, k - 1), floats(lo, hi), st.sampled_from([1.0, -1.0]))


def convex_sets(n: int | None = None, kinds: tuple[str, ...] = ("ball", "box", "halfspace", "polyhedron")
                ) -> st.SearchStrategy[_sets.ConvexSet]:
    """Nonempty closed convex sets (static): balls (radius 0 allowed), boxes (possibly flat or with
    infinite sides), half-spaces and polyhedra ``{Gx ≤ h, Ax = b}`` built around a point ``p`` with
    ``h = Gp + s``, ``s ≥ 0`` and ``b = Ap`` — so ``p`` belongs to the set."""
    @st.composite
    def _draw(draw):
        k = draw(_dim(n), label="n")
        kind = draw(st.sampled_from(list(kinds)), label="kind")
        return draw(_static_set(k, kind), label=kind)
    return _draw()


def _static_set(k: int, kind: str) -> st.SearchStrategy[_sets.ConvexSet]:
    @st.composite
    def _draw(draw):
        if kind == "ball":
            c = draw(_vec(k, -SET_SCALE, SET_SCALE))
            r = draw(floats(0.0, SET_SCALE))
            return _sets.Ball(c, r, name=f"Ball[c={_fmt(c)}, r={r:.4g}]")
        if kind == "box":
            lo = draw(_vec(k, -SET_SCALE, SET_SCALE))
            w = draw(_vec(k, 0.0, SET_SCALE))
            hi = lo + w
            unb = draw(st.lists(st.sampled_from(["", "lo", "hi"]), min_size=k, max_size=k))
            lo = np.where([u == "lo" for u in unb], -np.inf, lo)
            hi = np.where([u == "hi" for u in unb], np.inf, hi)
            return _sets.Box(lo, hi, name=f"Box[{_fmt(lo)}, {_fmt(hi)}]")
        if kind == "halfspace":
            a = draw(_nonzero_vectors(k))
            b = draw(floats(-SET_SCALE, SET_SCALE))
            return _sets.HalfSpace(a, b, name=f"HalfSpace[{_fmt(a)}·x ≤ {b:.4g}]")
        if kind == "polyhedron":
            p = draw(_vec(k, -SET_SCALE, SET_SCALE))
            rows = draw(st.integers(1, 2 * k))
            G = np.stack([draw(_nonzero_vectors(k)) for _ in range(rows)])
            s = draw(_vec(rows, 0.0, SET_SCALE))
            h = G @ p + s
            eq = draw(st.integers(0, k - 1))
            if eq:
                A = np.stack([draw(_nonzero_vectors(k)) for _ in range(eq)])
                b = A @ p
                return _sets.Polyhedron(G, h, A, b, name=f"Polyhedron[G={_fmt(G)}, h={_fmt(h)}, "
                                                          f"A={_fmt(A)}, b={_fmt(b)}]")
            return _sets.Polyhedron(G, h, name=f"Polyhedron[G={_fmt(G)}, h={_fmt(h)}]")
        raise ValueError(f"unknown set kind {kind!r}")
    return _draw()


@dataclasses.dataclass(frozen=True)
class MovingSet:
    """A moving closed convex set ``S(t)``, ``t ∈ [0, T]``, with a known (A3) modulus ``φ``.

    ``φ(t) = rate · t`` is nondecreasing and absolutely continuous, and
    ``sup_{z ∈ S(s)} dist(z, S(t)) ≤ φ(t) - φ(s)`` for ``0 ≤ s ≤ t ≤ T`` (assumption (A3) for
    ``F(t,·) = N_{S(t)}``, whose domain is ``S(t)``).
    """

    set: _sets.ConvexSet
    rate: float
    T: float
    how: str

    @property
    def dim(self) -> int:
        return self.set.dim

    def phi(self, t: float) -> float:
        return self.rate * float(t)

    def __repr__(self) -> str:
        return f"MovingSet({self.how}, φ(t)={self.rate:.4g}·t)"


def moving_sets(n: int | None = None, T: float = 1.0) -> st.SearchStrategy[MovingSet]:
    """Moving sets with their (A3) bound: a static set translated along ``c(t)`` (``φ' = Lip(c)``), a
    ball with moving centre and radius (``φ' = Lip(c) + Lip(r)``), a box with moving bounds
    (``φ' = |(max(Lip lᵢ, Lip uᵢ))ᵢ|``) and a half-space with moving offset (``φ' = Lip(b)/|a|``)."""
    @st.composite
    def _draw(draw):
        k = draw(_dim(n), label="n")
        kind = draw(st.sampled_from(["translated", "ball", "box", "halfspace"]), label="kind")
        if kind == "translated":
            S0 = draw(convex_sets(k), label="S0")
            c = draw(time_functions((k,), -1.0, 1.0), label="shift")
            S = _sets.Translated(S0, c, name=f"{S0.name} + {c!r}")
            return MovingSet(S, c.lipschitz, T, S.name)
        if kind == "ball":
            c = draw(time_functions((k,)), label="center")
            r = draw(_nonneg_time_functions(0.0, SET_SCALE), label="radius")
            S = _sets.Ball(c, r, name=f"Ball[c={c!r}, r={r!r}]")
            return MovingSet(S, c.lipschitz + r.lipschitz, T, S.name)
        if kind == "box":
            kd = draw(_kinds(), label="g")
            l0 = draw(_vec(k, -SET_SCALE, SET_SCALE))
            dl = draw(_vec(k, -2.0, 2.0))
            du = draw(_vec(k, -2.0, 2.0))
            lo = TimeFunction(l0, dl * (kd[0] != "const"), kd[0], kd[1])
            # width w0 ≥ |du - dl| max|g| keeps lower ≤ upper on [0, T]
            w0 = draw(_vec(k, 0.0, SET_SCALE)) + np.abs(du - dl) * lo.gmax(T)
            hi = TimeFunction(l0 + w0, du * (kd[0] != "const"), kd[0], kd[1])
            rate = float(np.linalg.norm(np.maximum(np.abs(lo.b), np.abs(hi.b)))) * lo.slope
            S = _sets.Box(lo, hi, name=f"Box[{lo!r}, {hi!r}]")
            return MovingSet(S, rate, T, S.name)
        a = draw(_nonzero_vectors(k), label="normal")
        b = draw(time_functions((), rate=2.0), label="offset")
        S = _sets.HalfSpace(a, b, name=f"HalfSpace[{_fmt(a)}·x ≤ {b!r}]")
        return MovingSet(S, b.lipschitz / float(np.linalg.norm(a)), T, S.name)
    return _draw()


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
            return Stated(op, phi=_ZERO, sigma=_NormOf(c), theta=_Rate(c.lipschitz))
        if kind == "l1":
            if td:
                c = draw(_nonneg_time_functions(0.0, 5.0))
                op = L1Subdifferential(c, k, name=f"L1Subdifferential[c={c!r}, n={k}]")
                root = float(np.sqrt(k))
                return Stated(op, phi=_ZERO, sigma=_NormOf(c, root), theta=_Rate(root * c.lipschitz))
            c = draw(_vec(k, 0.0, 5.0))
            return Stated(L1Subdifferential(c, k, name=f"L1Subdifferential[c={_fmt(c)}]"), phi=_ZERO,
                          sigma=_Const(float(np.linalg.norm(c))), theta=_ZERO)
        if kind == "logbarrier":
            c = draw(_nonneg_time_functions(0.1, 5.0) if td else floats(0.1, 5.0).map(lambda v: TimeFunction(v, 0.0)))
            op = LogBarrier(c if td else c.a, k, name=f"LogBarrier[c={c!r}, n={k}]")
            cmin = float(c.a) - (abs(float(c.b)) if c.kind == "sin" else 0.0)
            rate = np.sqrt(k) * LOGBARRIER_YB * c.lipschitz ** 1.5 / cmin
            return Stated(op, phi=_ZERO, theta=_Rate(float(rate)))
        if kind == "quadratic":
            P = draw(psd_matrices(k, symmetric=True))
            return Stated(Linear(P, name=f"Gradient[P={_fmt(P)}]"), phi=_ZERO,
                          sigma=_Const(float(np.linalg.norm(P, 2))), theta=_ZERO)
        S = draw(convex_sets(k))
        return Stated(NormalCone(S, name=f"NormalCone[{S.name}]"), phi=_ZERO, sigma=_ZERO, theta=_ZERO)
    return _draw()


def stated_moving_set_normal_cones(n: int | None = None, T: float = 1.0) -> st.SearchStrategy[Stated]:
    """``N_{S(t)}`` for :func:`moving_sets`: (A3) with their ``φ = rate·t``; ``F^0 = 0`` on ``S(t)`` so (LG)
    with ``σ ≡ 0``; (YB) only for a set that does not move (``θ ≡ 0``) — for ``rate > 0``,
    ``|Y_λ(s+λ, x)| = dist(x, S(s+λ))/λ`` is of order ``rate`` at ``F^0 = 0``, which no ``θ`` increment
    ``θ(s+λ) - θ(s) → 0`` bounds: (YB) fails and is not stated."""
    def build(ms: MovingSet) -> Stated:
        op = NormalCone(ms.set, name=f"NormalCone[{ms.set.name}]")
        return Stated(op, phi=_Rate(ms.rate), sigma=_ZERO, theta=_ZERO if ms.rate == 0 else None)
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
    from .lcs import Complementarity, LinearRelationSystem

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
            sigma = _Const(nA + nB * (nC + vmax) / mu)
        static = None if mv else _ZERO
        return Stated(system.operator(), phi=static, sigma=sigma, theta=static, system=system)
    return _draw()


# -- inputs and grids -------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class ACInput:
    """An absolutely continuous input ``u: [0, T] → R^m``, Lipschitz with constant ``lipschitz``
    (so its total variation on ``[0, T]`` is at most ``variation = lipschitz · T``), with its exact
    integral ``Φ(t) = ∫_0^t u`` (:meth:`integral`), the shift of Section 6's lemma ``l:extinput``.

    ``u(t) = a + b g(t)`` with ``g ∈ {0, t, sin(ωt + θ)}``, or a continuous piecewise linear interpolant
    of values ``v_j`` at knots ``τ_j`` (``lipschitz = max_j |v_{j+1} - v_j| / (τ_{j+1} - τ_j)``).
    """

    kind: str
    a: np.ndarray
    b: np.ndarray
    omega: float = 1.0
    theta: float = 0.0
    knots: np.ndarray | None = None
    values: np.ndarray | None = None
    T: float = 1.0

    @property
    def __name__(self) -> str:
        return repr(self)

    @property
    def m(self) -> int:
        return self.a.shape[0]

    def __call__(self, t: float) -> np.ndarray:
        if self.kind == "const":
            return self.a.copy()
        if self.kind == "affine":
            return self.a + t * self.b
        if self.kind == "sin":
            return self.a + np.sin(self.omega * t + self.theta) * self.b
        return np.array([np.interp(t, self.knots, self.values[:, i]) for i in range(self.m)])

    def integral(self, t: float) -> np.ndarray:
        """``Φ(t) = ∫_0^t u(s) ds`` in closed form."""
        if self.kind == "const":
            return t * self.a
        if self.kind == "affine":
            return t * self.a + 0.5 * t * t * self.b
        if self.kind == "sin":
            w, th = self.omega, self.theta
            return t * self.a + (np.cos(th) - np.cos(w * t + th)) / w * self.b
        # trapezoid on the knots below t, then the partial cell
        tk, v = self.knots, self.values
        out = np.zeros(self.m)
        for j in range(len(tk) - 1):
            if t <= tk[j]:
                break
            hi = min(t, tk[j + 1])
            vhi = v[j] + (v[j + 1] - v[j]) * (hi - tk[j]) / (tk[j + 1] - tk[j])
            out += 0.5 * (hi - tk[j]) * (v[j] + vhi)
        if t > tk[-1]:
            out += (t - tk[-1]) * v[-1]
        return out

    @property
    def lipschitz(self) -> float:
        if self.kind == "const":
            return 0.0
        if self.kind == "affine":
            return float(np.linalg.norm(self.b))
        if self.kind == "sin":
            return float(np.linalg.norm(self.b)) * self.omega
        d = np.diff(self.values, axis=0)
        return float(np.max(np.linalg.norm(d, axis=1) / np.diff(self.knots)))

    @property
    def variation(self) -> float:
        """Bound on the total variation ``∫_0^T |u'|``."""
        return self.lipschitz * self.T

    @property
    def bound(self) -> float:
        """``M ≥ sup_{[0, T]} |u|``: exact at the ends for an affine ``u`` and at the knots for a piecewise
        linear one (``|u|`` is convex on each piece), ``|a| + |b|`` for a sinusoid."""
        if self.kind == "const":
            return float(np.linalg.norm(self.a))
        if self.kind == "affine":
            return max(float(np.linalg.norm(self.a)), float(np.linalg.norm(self.a + self.T * self.b)))
        if self.kind == "sin":
            return float(np.linalg.norm(self.a)) + float(np.linalg.norm(self.b))
        return float(np.max(np.linalg.norm(self.values, axis=1)))

    def __repr__(self) -> str:
        if self.kind == "const":
            return f"u={_fmt(self.a)}"
        if self.kind == "affine":
            return f"u={_fmt(self.a)} + t·{_fmt(self.b)}"
        if self.kind == "sin":
            return f"u={_fmt(self.a)} + sin({self.omega:.4g}t + {self.theta:.4g})·{_fmt(self.b)}"
        return f"u=pwlinear(knots={_fmt(self.knots)}, values={_fmt(self.values)})"


def ac_inputs(m: int | None = None, T: float = 1.0, scale: float = 2.0) -> st.SearchStrategy[ACInput]:
    """Absolutely continuous inputs on ``[0, T]`` with known Lipschitz bound (see :class:`ACInput`);
    values ``≤ scale`` per entry, slopes ``≤ 2·scale``, knots spaced at least ``T/100``."""
    @st.composite
    def _draw(draw):
        k = draw(_dim(m), label="m")
        kind = draw(st.sampled_from(["const", "affine", "sin", "pwlinear"]), label="kind")
        a = draw(_vec(k, -scale, scale), label="a")
        if kind == "const":
            return ACInput("const", a, np.zeros(k), T=T)
        b = draw(_vec(k, -scale, scale), label="b")
        if kind == "affine":
            return ACInput("affine", a, b, T=T)
        if kind == "sin":
            w = draw(floats(0.5, 2 * np.pi), label="ω")
            th = draw(floats(0.0, 2 * np.pi), label="θ")
            return ACInput("sin", a, b, w, th, T=T)
        J = draw(st.integers(1, 5), label="cells")
        w = np.array(draw(st.lists(floats(1.0, 10.0), min_size=J, max_size=J), label="widths"))
        knots = np.concatenate([[0.0], T * np.cumsum(w) / np.sum(w)])
        knots[-1] = T
        vals = np.array(draw(st.lists(_vec(k, -scale, scale), min_size=J + 1, max_size=J + 1), label="values"))
        return ACInput("pwlinear", a, b, knots=knots, values=vals, T=T)
    return _draw()


def grids(T: float = 1.0, max_cells: int = MAX_CELLS, uniform: bool | None = None
          ) -> st.SearchStrategy[np.ndarray]:
    """Partitions ``0 = t_0 < … < t_K = T`` with ``1 ≤ K ≤ max_cells``: uniform, or nonuniform with
    cell weights in ``[1, 100]`` (step ratio ``≤ 100``); validated by :func:`verimono.validate_grid`."""
    @st.composite
    def _draw(draw):
        K = draw(st.integers(1, max_cells), label="K")
        uni = draw(st.booleans(), label="uniform") if uniform is None else uniform
        if uni or K == 1:
            t = np.linspace(0.0, T, K + 1)
        else:
            w = np.array(draw(st.lists(floats(1.0, 100.0), min_size=K, max_size=K), label="weights"))
            t = np.concatenate([[0.0], T * np.cumsum(w) / np.sum(w)])
        t[-1] = T
        return validate_grid(t, T)
    return _draw()


__all__ = [
    "MAX_DIM", "POINT_SCALE", "SET_SCALE", "floats", "points", "step_sizes", "times", "TimeFunction",
    "time_functions", "psd_matrices", "monotone_linear_operators", "convex_sets", "MovingSet", "moving_sets",
    "subdifferential_operators", "maximal_monotone_operators", "catalog", "catalog_operators", "PassiveSystem", "passive_systems",
    "Stated", "stated_linear_operators", "stated_subdifferential_operators", "stated_moving_set_normal_cones",
    "stated_operators", "lcs_operators", "LCS_MU_FLOOR", "LOGBARRIER_YB", "ACInput", "ac_inputs", "grids",
]
