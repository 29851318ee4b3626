"""Values: dimensions, points, step sizes, times, matrices with ``M + Mᵀ ⪰ 0``, functions of time
(:class:`TimeFunction`), the functions of the paper's assumptions (φ, σ, θ) and absolutely continuous
inputs (:class:`ACInput`).  Bounds: :mod:`verimono.strategies`."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
from hypothesis import strategies as st


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

#: the most values a function of time remembers (then it forgets them all and starts again)
MEMO_SIZE = 4096


def _memo_of(obj: Any) -> dict:
    """``obj``'s memo of values by time (kept out of the frozen dataclass's fields: its ``==``, ``repr`` and
    ``dataclasses.replace`` ignore it)."""
    memo = obj.__dict__.get("_memo")
    if memo is None:
        memo = {}
        object.__setattr__(obj, "_memo", memo)
    return memo


def _memo_key(t: float) -> Any:
    """``t`` as a memo key: ``0.0`` and ``-0.0`` are equal keys in a dict but may give values of another sign."""
    return t if t != 0.0 else (0.0, math.copysign(1.0, t))


def _remember(memo: dict, key: Any, v: Any) -> None:
    if len(memo) >= MEMO_SIZE:
        memo.clear()
    memo[key] = v


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
        a, b = self.a, self.b
        if type(a) is float and type(b) is float and type(t) is float:
            # a scalar function at a float time: the same two IEEE operations, a + (g(t)·b), in Python floats
            # (NumPy's 0-d arithmetic rounds each alike), the same type (np.float64), remembered per time — the
            # operator laws call c(t) ~20 times per time drawn (_memo_key: -0.0 and 0.0 apart)
            memo = _memo_of(self)
            key = _memo_key(t)
            v = memo.get(key)
            if v is None:
                v = np.float64(a + self.g(t) * b)
                _remember(memo, key, v)
            return v
        return np.asarray(a, dtype=float) + self.g(t) * np.asarray(b, dtype=float)

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


# -- matrices ------------------------------------------------------------------------------------

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


# -- the functions of the paper's assumptions -----------------------------------------------------

@dataclasses.dataclass(frozen=True)
class Constant:
    """``t ↦ value``."""

    value: float

    def __call__(self, t: float) -> float:
        return self.value

    def __repr__(self) -> str:
        return f"{self.value:.4g}"


@dataclasses.dataclass(frozen=True)
class Rate:
    """``t ↦ rate·t`` (nondecreasing for ``rate ≥ 0``; ``0`` is the constant function 0)."""

    rate: float

    def __call__(self, t: float) -> float:
        return self.rate * float(t)

    def __repr__(self) -> str:
        return "0" if self.rate == 0 else f"{self.rate:.4g}·t"


ZERO = Rate(0.0)


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


# -- inputs -------------------------------------------------------------------------------------

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
        """``Φ(t) = ∫_0^t u(s) ds`` in closed form (a copy of the one computed before at the same float ``t``: the
        shifted operators' laws ask ~60 times per time drawn, and the piecewise linear one is a Python loop)."""
        if type(t) is not float:
            return self._integral(t)
        memo = _memo_of(self)
        key = _memo_key(t)
        v = memo.get(key)
        if v is None:
            v = self._integral(t)
            _remember(memo, key, v.copy())
            return v
        return v.copy()

    def _integral(self, t: float) -> np.ndarray:
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


# made once, at import: hypothesis reads a composite's source each time one is made (5-10 ms), and the
# battery's six generated problems made this one five times per run; the same draws (arguments, not a closure)
@st.composite
def _ac_input(draw, m: int | None, T: float, scale: float) -> ACInput:
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


def ac_inputs(m: int | None = None, T: float = 1.0, scale: float = 2.0) -> st.SearchStrategy[ACInput]:
    """Absolutely continuous inputs on ``[0, T]`` with known Lipschitz bound (see :class:`ACInput`);
    values ``≤ scale`` per entry, slopes ``≤ 2·scale``, knots spaced at least ``T/100``."""
    return _ac_input(m, T, scale)
