"""Problems ``x' ∈ -F(t, x) + f(x) + u(t)``, ``x(0) = x0`` on ``[0, T]``, valid by construction, with the
functions of the paper's assumptions that hold for them (:class:`verimono.Problem`'s ``phi``, ``sigma``,
``theta``, ``lipschitz``): what the stepper battery searches besides the references
(:mod:`verimono.checks.generated_problems`).

The coordinates of the problem space a stepper can get wrong, each drawn:

* the dimension ``n`` — ``size="small"`` (1–4), ``"medium"`` (5–12) or ``"large"`` (13 to
  :data:`MAX_PROBLEM_DIM` = 50);
* the horizon ``T`` — one of :data:`HORIZONS` (0.3, 1, 2.5, 2π) or any in ``[0.2, 6.5]``;
* the operator ``F`` — from :func:`verimono.strategies.stated_operators` (every family, shifted or not) for an
  interior start in ``n ≤ MAX_DIM``; otherwise a time-dependent one: a normal cone of a *solid* moving domain
  (ball, box, half-space, translated ball or box: an interior with a known point, radii and widths ≥ 1/2,
  moving with a stated (A3) rate > 0), ``∂(c(t)|·|)``, ``∂(c(t)|·|₁)`` or a linear ``M0 + g(t) M1``;
* the Lipschitz field ``f`` (:class:`LipschitzField`: ``B x + b`` or ``B tanh(x) + b``, ``‖B‖₂ = L`` stated
  as ``lipschitz``, every ``b_i`` at least 0.3 in magnitude, ``L T ≤ 3``) and the input ``u`` (an
  :func:`ac_inputs` input plus a constant that keeps every ``|u_j(t)| ≥ 1/4`` on ``[0, T]``,
  :class:`OffsetInput`, with its exact primitive ``U``) — both act on every coordinate; ``terms`` says which
  are present;
* where ``x0`` lies (``placement``, :data:`PLACEMENTS`): ``"inside"`` (an interior point of a moving domain,
  or any point of ``cl dom F(0)``), ``"on"`` the boundary of the moving domain (where a ray from an interior point
  along the free motion ``f + u``, else along another direction, leaves it — the first such point where the
  constraint is active at ``t = 0``: the free motion leaves the moving domain), ``"near_inside"`` and
  ``"near_outside"`` (``NEAR = 1e-6`` inside or outside along the outer normal at that boundary point; outside,
  ``x0 ∉ cl dom F(0)`` and the problem starts with the catching-up jump, ``initial_jump=True``).

Stated constants: those of :class:`verimono.strategies.Stated` for the operator (a moving domain: (A3) with
``φ = rate·t``, (LG) with σ ≡ 0, (YB) not stated since it fails for a moving set; ``∂(c|·|)``: σ = c,
θ = Lip(c) t; linear: σ = ‖M(t)‖₂); ``lipschitz = ‖B‖₂`` rounded up by 1e-10 relative (the computed
spectral norm is within ``n·eps`` of the true one).  Large arrays (``B``, the matrices of a linear ``F`` in
``n > MAX_DIM``) come from a NumPy generator seeded by a drawn integer: hypothesis draws a float in about
0.1 ms here, so the ``2n²`` entries of two matrices in ``n = 50`` would take half a second a problem.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
from hypothesis import strategies as st

from ..core import sets as _sets
from ..core.operators import L1Subdifferential, Linear, NormalCone, NormSubdifferential
from ..core.problem import Problem
from .operators import Stated, _MatrixPath, stated_operators
from .sets import _nonzero_vectors
from .values import (MAX_DIM, ZERO, ACInput, Rate, TimeFunction, _fmt, _NormOf, _nonneg_time_functions, _vec,
                     ac_inputs, floats)

#: largest dimension a generated problem has
MAX_PROBLEM_DIM = 50
#: dimension ranges of the size classes
SIZES = {"small": (1, 4), "medium": (5, 12), "large": (13, MAX_PROBLEM_DIM)}
#: where ``x0`` lies with respect to the boundary of a moving domain
PLACEMENTS = ("inside", "on", "near_inside", "near_outside")
#: which of ``f`` and ``u`` the problem has
TERMS = ("f+u", "f", "u", "none")
#: horizons drawn first (besides any ``T ∈ [0.2, 6.5]``)
HORIZONS = (0.3, 1.0, 2.5, 2 * math.pi)
#: the distance of a ``near_*`` start to the boundary
NEAR = 1e-6
#: ``L T`` at most this: ``e^{LT} ≤ 20``, so that the solutions stay of the size of their data
MAX_LT = 3.0


@dataclasses.dataclass(frozen=True, eq=False)
class LipschitzField:
    """``f(x) = B x + b`` (``kind="affine"``) or ``B tanh(x) + b`` (``"tanh"``; ``tanh`` is 1-Lipschitz
    componentwise), Lipschitz with constant ``‖B‖₂``."""

    B: np.ndarray
    b: np.ndarray
    kind: str

    @property
    def lipschitz(self) -> float:
        # the computed spectral norm is within a few n·eps of the true one: rounded up, a true upper bound
        return float(np.linalg.norm(self.B, 2)) * (1.0 + 1e-10)

    def __call__(self, x: Any) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        return (np.tanh(x) if self.kind == "tanh" else x) @ self.B.T + self.b

    def __repr__(self) -> str:
        return f"f = B{' tanh(x)' if self.kind == 'tanh' else 'x'} + b (|B| = {self.lipschitz:.3g})"


@dataclasses.dataclass(frozen=True, eq=False)
class OffsetInput:
    """``u(t) = base(t) + c`` (an :class:`ACInput` plus a constant with no zero entry), with ``U = ∫_0^t u``."""

    base: ACInput
    c: np.ndarray

    def __post_init__(self) -> None:
        if self.base.kind == "pwlinear":    # the laws call u and U at every node: one interpolation of all rows
            tk, v = np.asarray(self.base.knots, float), np.asarray(self.base.values, float)
            cum = np.concatenate([np.zeros((1, v.shape[1])),
                                  np.cumsum(0.5 * np.diff(tk)[:, None] * (v[:-1] + v[1:]), axis=0)])
            object.__setattr__(self, "_pw", (tk, v, cum))

    def _piece(self, t: float) -> tuple[int, float]:
        tk = self._pw[0]
        j = int(np.clip(np.searchsorted(tk, t, side="right") - 1, 0, len(tk) - 2))
        return j, float(np.clip((t - tk[j]) / (tk[j + 1] - tk[j]), 0.0, 1.0))

    def __call__(self, t: float) -> np.ndarray:
        if self.base.kind != "pwlinear":
            return self.base(t) + self.c
        j, w = self._piece(float(t))
        v = self._pw[1]
        return (1.0 - w) * v[j] + w * v[j + 1] + self.c

    def integral(self, t: float) -> np.ndarray:
        t = float(t)
        if self.base.kind != "pwlinear":
            return self.base.integral(t) + t * self.c
        tk, v, cum = self._pw
        if t <= tk[0]:
            return t * self.c
        if t >= tk[-1]:
            return cum[-1] + (t - tk[-1]) * v[-1] + t * self.c
        j, w = self._piece(t)
        s = t - tk[j]
        return cum[j] + s * (v[j] + 0.5 * w * (v[j + 1] - v[j])) + t * self.c

    @property
    def bound(self) -> float:
        return self.base.bound + float(np.linalg.norm(self.c))

    def __repr__(self) -> str:
        return f"{self.base!r} + {_fmt(self.c)}"


@dataclasses.dataclass(frozen=True)
class _Domain:
    """A solid moving domain: the set, its (A3) rate, a point of the interior of ``S(0)`` and its kind."""

    set: Any
    rate: float
    interior: np.ndarray
    kind: str


def _signed(k: int, lo: float, hi: float) -> st.SearchStrategy[np.ndarray]:
    """Vectors with every entry of magnitude in ``[lo, hi]``."""
    return st.tuples(_vec(k, lo, hi), st.lists(st.sampled_from([1.0, -1.0]), min_size=k, max_size=k)).map(
        lambda p: p[0] * np.array(p[1]))


def _moving_functions(shape: tuple[int, ...], lo: float, hi: float, rate: float) -> st.SearchStrategy[TimeFunction]:
    """``a + b g(t)`` with ``g ∈ {t, sin ωt}`` (never constant) and every ``|b_i| ∈ [0.2, rate]``."""
    size = int(np.prod(shape)) if shape else 1

    def build(kind, a, b):
        a = a.reshape(shape) if shape else float(a[0])
        b = b.reshape(shape) if shape else float(b[0])
        return TimeFunction(a, b, kind[0], kind[1])
    kinds = st.one_of(st.just(("affine", 1.0)), floats(0.5, 2 * np.pi).map(lambda w: ("sin", w)))
    return st.builds(build, kinds, _vec(size, lo, hi), _signed(size, 0.2, rate))


def moving_domains(n: int, T: float) -> st.SearchStrategy[_Domain]:
    """Solid moving domains of ``R^n`` on ``[0, T]`` (module docstring), each moving (rate > 0)."""
    return _moving_domains(int(n), float(T))


# the composites are made once, at import (hypothesis reads a composite's source when it is made: 5 ms each)
@st.composite
def _moving_domains(draw, n, T):
    kind = draw(st.sampled_from(["ball", "box", "halfspace", "translated ball", "translated box"]), label="kind")
    if kind == "ball":
        c = draw(_moving_functions((n,), -2.0, 2.0, 1.5), label="center")
        r = draw(_nonneg_time_functions(0.5, 3.0), label="radius")
        S = _sets.Ball(c, r, name=f"Ball[c={c!r}, r={r!r}]")
        return _Domain(S, c.lipschitz + r.lipschitz, np.asarray(c(0.0), float), kind)
    if kind == "box":
        g = draw(_moving_functions((), 0.0, 0.0, 1.0), label="g")
        l0 = draw(_vec(n, -3.0, 0.0), label="l0")
        dl, du = draw(_vec(n, -1.5, 1.5), label="dl"), draw(_vec(n, -1.5, 1.5), label="du")
        w0 = draw(_vec(n, 0.5, 3.0), label="w0") + np.abs(du - dl) * g.gmax(T)   # lower ≤ upper - 1/2 on [0, T]
        lo, hi = TimeFunction(l0, dl, g.kind, g.omega), TimeFunction(l0 + w0, du, g.kind, g.omega)
        rate = float(np.linalg.norm(np.maximum(np.abs(dl), np.abs(du)))) * lo.slope
        S = _sets.Box(lo, hi, name=f"Box[{lo!r}, {hi!r}]")
        return _Domain(S, rate, l0 + 0.5 * w0, kind)
    if kind == "halfspace":
        a = draw(_nonzero_vectors(n), label="normal")
        b = draw(_moving_functions((), -2.0, 2.0, 2.0), label="offset")
        p = draw(_vec(n, -2.0, 2.0), label="p")
        na = float(np.linalg.norm(a))
        m = p - (float(a @ p) - float(b(0.0)) + na) * a / na ** 2     # <a, m> = b(0) - |a|: 1 inside
        S = _sets.HalfSpace(a, b, name=f"HalfSpace[{_fmt(a)}·x ≤ {b!r}]")
        return _Domain(S, b.lipschitz / na, m, kind)
    shift = draw(_moving_functions((n,), -1.0, 1.0, 1.5), label="shift")
    if kind == "translated ball":
        c0, r0 = draw(_vec(n, -2.0, 2.0), label="c0"), draw(floats(0.5, 3.0), label="r0")
        S0, m0 = _sets.Ball(c0, r0, name=f"Ball[c={_fmt(c0)}, r={r0:.4g}]"), c0
    else:
        l0, w0 = draw(_vec(n, -3.0, 0.0), label="l0"), draw(_vec(n, 0.5, 3.0), label="w0")
        S0, m0 = _sets.Box(l0, l0 + w0, name=f"Box[{_fmt(l0)}, {_fmt(l0 + w0)}]"), l0 + 0.5 * w0
    S = _sets.Translated(S0, shift, name=f"{S0.name} + {shift!r}")
    return _Domain(S, shift.lipschitz, m0 + np.asarray(shift(0.0), float), kind)


def _domain_operator(d: _Domain) -> Stated:
    op = NormalCone(d.set, name=f"NormalCone[{d.set.name}]")
    return Stated(op, phi=Rate(d.rate), sigma=ZERO)   # (YB) fails for a moving set: not stated


@st.composite
def _time_dependent_operators(draw, n: int, T: float) -> tuple[Stated, str, np.ndarray | None]:
    """``(stated, kind, interior point or None)``: a moving domain's normal cone, ``∂(c(t)|·|)``,
    ``∂(c(t)|·|₁)`` (``c`` increasing affine or sinusoidal, slope or amplitude at least 0.2) or
    ``M0 + g(t) M1`` — each time-dependent."""
    kind = draw(st.sampled_from(["domain", "norm", "l1", "linear"]), label="family")
    if kind == "domain":
        d = draw(moving_domains(n, T), label="domain")
        return _domain_operator(d), f"moving {d.kind}", d.interior
    if kind in ("norm", "l1"):
        c = draw(_weights(), label="c")
        if kind == "norm":
            op = NormSubdifferential(c, n, name=f"NormSubdifferential[c={c!r}, n={n}]")
            return Stated(op, phi=ZERO, sigma=_NormOf(c), theta=Rate(c.lipschitz)), "∂(c(t)|x|)", None
        root = float(np.sqrt(n))
        op = L1Subdifferential(c, n, name=f"L1Subdifferential[c={c!r}, n={n}]")
        return (Stated(op, phi=ZERO, sigma=_NormOf(c, root), theta=Rate(root * c.lipschitz)), "∂(c(t)|x|_1)",
                None)
    rng = np.random.default_rng(draw(st.integers(0, 2 ** 32 - 1), label="matrix seed"))
    M0, M1 = (_psd(rng, n) for _ in range(2))
    g = draw(st.sampled_from(["t", "t^2", "1+sin(t)"]), label="g")
    path = _MatrixPath(M0, M1, g)
    return Stated(Linear(path, name=f"Linear[M(t) = M0 + {g}·M1, n={n}]"), phi=ZERO, sigma=_NormOf(path)), \
        f"linear M0 + {g}·M1", None


@st.composite
def _weights(draw) -> TimeFunction:
    """``c(t) ≥ 0``: ``c0 + c1 t`` or ``c0 + c1 sin ωt``, ``c1 ∈ [0.2, 1.5]`` (``c0 ≥ c1`` for the sinusoid)."""
    kind = draw(st.sampled_from(["affine", "sin"]), label="kind")
    c1 = draw(floats(0.2, 1.5), label="c1")
    if kind == "affine":
        return TimeFunction(draw(floats(0.0, 3.0), label="c0"), c1, "affine")
    return TimeFunction(draw(floats(c1, 3.0), label="c0"), c1, "sin", draw(floats(0.5, 2 * np.pi), label="ω"))


def _psd(rng: np.random.Generator, n: int) -> np.ndarray:
    """``M = LLᵀ/n + (W - Wᵀ)/√n`` (``M + Mᵀ = 2LLᵀ/n ⪰ 0``), entries of ``L, W`` uniform in ``[-1, 1]``:
    ``‖M‖`` of order 1 in every dimension."""
    L = rng.uniform(-1.0, 1.0, (n, n))
    W = rng.uniform(-1.0, 1.0, (n, n))
    P = L @ L.T / n
    return 0.5 * (P + P.T) + (W - W.T) / math.sqrt(n)


@st.composite
def lipschitz_fields(draw, n: int, T: float) -> LipschitzField:
    """:class:`LipschitzField` on ``R^n`` with ``‖B‖₂ ∈ [0.1, 1.5]``, ``‖B‖₂ T ≤ MAX_LT`` and every
    ``|b_i| ∈ [0.3, 1.5]``."""
    kind = draw(st.sampled_from(["affine", "tanh"]), label="f kind")
    L = min(draw(floats(0.1, 1.5), label="L"), MAX_LT / T)
    rng = np.random.default_rng(draw(st.integers(0, 2 ** 32 - 1), label="B seed"))
    B = rng.standard_normal((n, n))
    B *= L / float(np.linalg.norm(B, 2))
    return LipschitzField(B, draw(_signed(n, 0.3, 1.5), label="b"), kind)


def _entry_bounds(u: ACInput, T: float) -> np.ndarray:
    """``sup_{[0, T]} |u_j|`` for every coordinate ``j`` (``|u_j|`` is convex on each affine piece)."""
    if u.kind == "const":
        return np.abs(u.a)
    if u.kind == "affine":
        return np.maximum(np.abs(u.a), np.abs(u.a + T * u.b))
    if u.kind == "sin":
        return np.abs(u.a) + np.abs(u.b)
    return np.max(np.abs(u.values), axis=0)


def every_coordinate_inputs(n: int, T: float) -> st.SearchStrategy[OffsetInput]:
    """:func:`ac_inputs` ``u0`` on ``R^n`` plus a constant ``c`` with ``|c_j| = sup|u0_j| + s_j``, ``s_j ∈ [1/4, 1]``:
    ``|u_j(t)| ≥ 1/4`` on ``[0, T]`` for every coordinate ``j`` — the input acts on every coordinate throughout."""
    def build(u0: ACInput, s: np.ndarray) -> OffsetInput:
        return OffsetInput(u0, np.sign(s) * (_entry_bounds(u0, T) + np.abs(s)))
    return st.builds(build, ac_inputs(n, T, scale=1.0), _signed(n, 0.25, 1.0))


#: the step over which a boundary start is tested for an active constraint
ACTIVE_STEP = 1e-3


def _boundary_point(op: Any, m: np.ndarray, drift: Any, seed_dir: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(x_on, ν)``: a point of the boundary of ``S(0)`` where the constraint is active — the free motion
    ``x_on + δ drift(x_on)`` leaves ``S(δ)`` for ``δ = ACTIVE_STEP`` — and the unit outer normal ``ν`` there.

    Candidates, in order: where the ray from the interior point ``m`` along ``drift(m)``, ``±seed_dir``, ``±e_i``
    leaves ``S(0)`` (doubling and bisection; the projection of the point one unit beyond the exit, with
    ``ν ∈ N_S(x_on)`` from it); the first active one, else the first found (``drift = None``: no ``f``, no
    ``u``; then active means the domain moves inward there)."""
    def gap(z: np.ndarray, t: float = 0.0) -> float:
        return float(np.linalg.norm(np.asarray(op.project_domain(z, t), float) - z))

    def outside(z: np.ndarray) -> bool:
        return gap(z) > 1e-9 * (1.0 + float(np.linalg.norm(z)))

    def push(z: np.ndarray) -> np.ndarray:
        return np.zeros_like(z) if drift is None else np.asarray(drift(z), dtype=float)

    basis = np.eye(m.size)
    first = None
    # a bounded set is left along every direction; a half-space along one of ±e_i
    for d in [push(m), seed_dir, -seed_dir, *basis, *(-basis)]:
        nd = float(np.linalg.norm(d))
        if not nd > 0:
            continue
        d = d / nd
        lo, hi = 0.0, 0.5
        while hi < 1e4 and not outside(m + hi * d):
            lo, hi = hi, 2.0 * hi
        if hi >= 1e4:
            continue
        for _ in range(30):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if outside(m + mid * d) else (mid, hi)
        far = m + (hi + 1.0) * d
        on = np.asarray(op.project_domain(far, 0.0), dtype=float)
        g = float(np.linalg.norm(far - on))
        if not g > 0.1:
            continue
        found = (on, (far - on) / g)
        if gap(on + ACTIVE_STEP * push(on), ACTIVE_STEP) > 1e-3 * ACTIVE_STEP:
            return found
        first = first or found
    if first is None:
        raise ValueError("no boundary point found along any direction")    # a solid domain is never all of R^n
    return first


def stated_problems(n: int | None = None, T: float | None = None, *, size: str | None = None,
                    placement: str | None = None, terms: str | None = None) -> st.SearchStrategy[Problem]:
    """Valid :class:`verimono.Problem` with their stated constants (module docstring); ``n``/``size``,
    ``T``, ``placement`` and ``terms`` fix those coordinates (``None``: drawn).  The problem's ``name``
    describes it (``n``, ``T``, the operator, where ``x0`` lies, the terms)."""
    for what, value, allowed in (("size", size, SIZES), ("placement", placement, PLACEMENTS),
                                 ("terms", terms, TERMS)):
        if value is not None and value not in allowed:
            raise ValueError(f"{what} must be one of {tuple(allowed)}, got {value!r}")

    return _problems(n, T, size, placement, terms)


@st.composite
def _problems(draw, n, T, size, placement, terms) -> Problem:
    sz = size or draw(st.sampled_from(list(SIZES)), label="size")
    k = int(n) if n is not None else draw(st.integers(*SIZES[sz]), label="n")
    TT = float(T) if T is not None else draw(st.one_of(st.sampled_from(HORIZONS), floats(0.2, 6.5)), label="T")
    where = placement or draw(st.sampled_from(PLACEMENTS), label="placement")
    which = terms or draw(st.sampled_from(TERMS), label="terms")
    f = draw(lipschitz_fields(k, TT), label="f") if "f" in which.split("+") else None
    u = draw(every_coordinate_inputs(k, TT), label="u") if "u" in which.split("+") else None
    interior = None
    if where == "inside" and k <= MAX_DIM and draw(st.booleans(), label="any family"):
        stated = draw(stated_operators(k, TT), label="F")
        kind = stated.operator.name.partition("[")[0]
    elif where == "inside":
        stated, kind, interior = draw(_time_dependent_operators(k, TT), label="F")
    else:
        d = draw(moving_domains(k, TT), label="domain")
        stated, kind, interior = _domain_operator(d), f"moving {d.kind}", d.interior
    op = stated.operator
    jump = False
    if interior is not None and where != "inside":
        drift = None
        if f is not None or u is not None:
            def drift(x, f=f, u=u):
                return (f(x) if f is not None else 0.0) + (u(0.0) if u is not None else 0.0)
        seed_dir = draw(_nonzero_vectors(k, 0.5, 1.0), label="direction")
        on, nu = _boundary_point(op, interior, drift, seed_dir)
        x0 = {"on": on, "near_inside": on - NEAR * nu, "near_outside": on + NEAR * nu}[where]
        jump = where == "near_outside"
    elif interior is not None:
        # an interior point of S(0): halfway from the known one to a drawn point of S(0)
        q = np.asarray(op.project_domain(draw(_vec(k, -3.0, 3.0), label="x0"), 0.0), dtype=float)
        x0 = interior + 0.5 * (q - interior)
    else:
        x0 = draw(_vec(k, -3.0, 3.0), label="x0")
        try:
            x0 = np.asarray(op.project_domain(x0, 0.0), dtype=float)
        except NotImplementedError:
            pass
    parts = [f"n={k}", f"T={TT:.4g}", kind, f"x0 {where.replace('_', ' ')}"]
    parts += [s for s, v in (("f", f), ("u", u)) if v is not None]
    extra: dict[str, Any] = {}
    if f is not None:
        extra.update(f=f, lipschitz=f.lipschitz)
    if u is not None:
        extra.update(u=u, U=u.integral)
    notes = (f"F: {op.name}; " + (f"{f!r}; " if f is not None else "") + (f"u = {u!r}; " if u is not None else "")
             + f"x0 = {_fmt(x0)}")
    return Problem(op, x0, TT, name=", ".join(parts), initial_jump=jump, notes=notes,
                   **stated.assumptions(), **extra)


__all__ = ["MAX_PROBLEM_DIM", "SIZES", "PLACEMENTS", "TERMS", "HORIZONS", "NEAR", "LipschitzField", "OffsetInput",
           "moving_domains", "lipschitz_fields", "every_coordinate_inputs", "stated_problems"]
