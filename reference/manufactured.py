"""Manufactured solutions for ``x' ∈ -F(t, x) + f(x) + u(t)``: an exact solution for any operator.

Pick a path ``z(t)`` and ``μ > 0`` and set

    x*(t) = J_{μF(t,·)}(z(t)),     y*(t) = (z(t) - x*(t))/μ ∈ F(t, x*(t)),     u = x*' + y* - f(x*).

``y*`` is the Yosida approximation ``Y_μ(t, z(t))``, which lies in ``F(t, J_μ z)`` for every ``t``
(Proposition ``prop:maxmon-resolvent-Yosida``), so ``x*' = -y* + f(x*) + u`` with ``y* ∈ F(t, x*)``
wherever ``x*'`` exists, and ``x*(t) ∈ dom F(t,·)`` for every ``t`` (the range of a resolvent is the
domain).

**Regularity relied on.**  ``x*`` must be absolutely continuous (the paper's notion of solution,
Section 3: ``x ∈ AC``, ``x(t) ∈ dom F(t,·)`` and the inclusion for almost all ``t``).  By nonexpansiveness,

    |x*(t) - x*(s)| ≤ |z(t) - z(s)| + sup_{w ∈ z([0,T])} |J_{μF(t,·)} w - J_{μF(s,·)} w|,

so ``x*`` is Lipschitz when ``z`` is and ``t ↦ J_{μF(t,·)}`` is Lipschitz on the path's range — for the
normal cone of ``Ball(c(t), r(t))`` with modulus ``|c'| + |r'|``, for ``∂(c(t)|·|)`` with ``μ|c'|``, for
``F_0(· + e(t)) + Ae(t)`` with ``(1 + |I - μA|)|e'|`` (the complementarity example below).  Then ``y*`` is
Lipschitz, ``u ∈ L^∞`` (it exists a.e.), and ``x*`` is *the* solution from ``x0 = x*(0)``: two solutions
``x1, x2`` satisfy ``½ d/dt |x1 - x2|² ≤ L |x1 - x2|²`` by monotonicity of ``F(t,·)`` and the Lipschitz
constant ``L`` of ``f`` (the input cancels).  What is assumed, not checked: ``z`` Lipschitz and the
resolvent Lipschitz in ``t``; what is measured: the Lipschitz constants of ``x*`` and ``y*`` on a fine
adaptive sample (:attr:`ManufacturedSolution.lipschitz_x`, ``lipschitz_y``), and a jump of ``x*`` is an
:class:`InvalidProblem`.

**The input without a derivative.**  The scheme consumes ``∫_{t_k}^{t_{k+1}} u`` per cell
(:meth:`verimono.Problem.input_increments`), which the primitive

    U(t) = ∫_0^t u = x*(t) - x*(0) + ∫_0^t (y* - f(x*)) ds

gives with no derivative at all.  ``g = y* - f(x*)`` is Lipschitz but kinks where ``x*`` does (where the
resolvent switches regime: a constraint engages or releases, the soft threshold starts or stops
clipping), so it is integrated on an adaptive partition of ``[0, T]``: a cell is accepted when 8-point
Gauss–Legendre and 9-point Gauss–Lobatto (both exact to degree 15; Lobatto samples the cell's ends, so a
kink in a sliver that Gauss never samples is seen too) agree to ``rtol · scale`` times its length, else it
is halved.  ``U(t)`` is the tabulated integral up to the cell holding ``t`` plus 8-point Gauss–Legendre on
the rest of it, where ``g`` is smooth.  :attr:`ManufacturedSolution.quadrature_error` sums the cells'
estimates (``≈ 1e-15`` on the examples, checked against SciPy's adaptive Gauss–Kronrod in the tests): against
scheme errors ``≥ 1e-6`` it is invisible.  The kinks (:attr:`ManufacturedSolution.kinks`) are located where
the refinement closed in (each local maximum of the halving depth) — at the crossing of cubics through ``x*`` on
either side, kept when the slope of ``x*`` jumps there — and at cell edges whose one-sided slopes differ; a jump of
``x*`` is an error.  The
pointwise ``u(t)`` (for laws that need ``|u|``, and for users) takes ``x*'`` from ``velocity`` when given,
else from Richardson-extrapolated central differences (error ``O(δ⁶)``, estimated) — one-sided (``O(δ⁵)``),
away from the kink, when a kink or an end of ``[0, T]`` lies within the stencil or the central estimate's
error is large; at a kink ``u`` is the right limit (``u`` is defined a.e.).

**Expected order of the proximal scheme: 1, derived.**  With ``e_k = x_k - x*(t_k)`` and
``y_{k+1} = (x_k + h f(x_k) + ∫u - x_{k+1})/h ∈ F(t_{k+1}, x_{k+1})``,

    e_{k+1} + h (y_{k+1} - y*(t_{k+1})) = e_k + ∫_{t_k}^{t_{k+1}} (y*(s) - y*(t_{k+1})) ds + h f(x_k) - ∫ f(x*),

and ``⟨y_{k+1} - y*(t_{k+1}), e_{k+1}⟩ ≥ 0`` (monotonicity of ``F(t_{k+1},·)``, both selections at the same
time) gives ``|e_{k+1}| ≤ (1 + hL)|e_k| + h² (Lip y* + L Lip x*)/2``, hence

    max_k |x_k - x*(t_k)| ≤ h (Lip y* + L Lip x*) (e^{LT} - 1)/(2L)        (T h Lip y*/2 when L = 0),

with ``h`` the largest step (:meth:`ManufacturedSolution.error_bound`).  It needs only a selection of
bounded variation along the solution and ``x0 ∈ dom F(0,·)``, the hypotheses of Rulla's order 1 for
``∂φ`` with a fixed ``φ`` (SIAM J. Numer. Anal. 33, 1996; ``x0 ∈ D(∂φ)``, BV forcing) — here for any
time-dependent maximal monotone ``F``.  The order is not more than 1 in general: ``x*'`` jumps at the kinks.
**Regularity, derived.**  Away from the times where the resolvent switches regime, ``x*`` is as smooth as the path
and ``t ↦ F(t,·)`` (``smoothness``; C^∞ by default, as :func:`lissajous` is): a ``Linear`` operator, or a set the
path never leaves, gives a smooth solution, and a scheme claiming order 5 is held to 5 there.  A kink of ``x*``
caps any scheme's order at 1; a kink of the input only (a field Lipschitz but not smooth along ``x*``) at 2
(:meth:`ManufacturedSolution.regularity`, in the problem's ``order.regularity``).  The kinks are located to about
``1e-15 T`` on the examples (tested against the closed forms of the switching times), two kinks a short stretch
apart included.

An operator evaluated at ``t_k`` instead of ``t_{k+1}`` is the proximal scheme of ``F(t - h, ·)``, an
``O(h)`` change of ``F`` when it moves Lipschitz in ``t``: on the order-1 examples it converges with order 1
as well (the tests show it), so only a problem of higher order — :func:`moving_box`, order 2 — catches it by
its order; its selections ``y_{k+1}`` leave ``F(t_{k+1}, x_{k+1})``, which the ``selections`` law sees.
"""

from __future__ import annotations

import bisect
import math
from typing import Any, Callable, Sequence

import numpy as np

from ..core.errors import InvalidProblem
from ..core.operators import NormalCone, NormSubdifferential
from ..core.problem import Order, Problem
from ..core.sets import Box
from ._kinks import find_kinks

#: 8-point Gauss–Legendre on [-1, 1]: exact for polynomials of degree 15
_XI, _W = np.polynomial.legendre.leggauss(8)
#: 9-point Gauss–Lobatto on [-1, 1] (the ends and the roots of P_8'): exact for degree 15 too
_XL = np.concatenate([[-1.0], np.sort(np.polynomial.legendre.Legendre.basis(8).deriv().roots().real), [1.0]])
_WL = 2.0 / (72.0 * np.polynomial.legendre.Legendre.basis(8)(_XL) ** 2)
#: no cell is halved below this fraction of T (a jump of y*, e.g. a jumping weight c(t), stops here)
_MIN_FRACTION = 2.0 ** -44
#: at most this many values of x* and U are kept per solution (a study's ∫u and errors meet every grid node
#: twice, a block of at most 8192 nodes apart: the cache saves half the resolvents, and stays small)
_CACHE_SIZE = 1 << 15


def lissajous(dim: int, amplitude: float = 1.5, center: Any = 0.0) -> Callable[[float], np.ndarray]:
    """The default path ``z(t) = center + amplitude (cos t, sin 2t, cos 3t, sin 4t, ...)`` in ``R^dim``.

    Smooth and ``2π``-periodic; in 2-D a figure eight through ``center`` (at ``t = π/2, 3π/2``) reaching
    ``amplitude`` away.  With the default amplitude ``1.5`` about the origin it leaves and re-enters sets
    of unit size there (the unit ball, boxes of half-width 1) and passes through the kinks of weights
    ``μc ≲ 1`` (``∂(c|·|)``, ``∂(c|·|_1)``): the nonsmooth part of ``F`` is active part of the time.
    """
    if int(dim) != dim or dim < 1:
        raise InvalidProblem(f"dim must be a positive integer, got {dim!r}")
    c = np.broadcast_to(np.asarray(center, dtype=float), (int(dim),)).copy()
    a = float(amplitude)
    k = np.arange(1, int(dim) + 1, dtype=float)
    phase = np.where(k % 2 == 1, 0.0, -0.5 * math.pi)     # cos for odd k, sin for even k

    def path(t: float) -> np.ndarray:
        return c + a * np.cos(k * float(t) + phase)
    path.__name__ = f"lissajous(dim={int(dim)}, amplitude={a:g})"
    return path


class ManufacturedSolution:
    """``x*(t) = J_{μF(t,·)}(z(t))`` with its selection ``y*``, input ``u`` and primitive ``U`` (see the module).

    Calling it gives ``x*(t)`` (it is the problem's ``exact``).  Built once: the adaptive partition of
    ``[0, T]`` with ``∫ (y* - f(x*))`` tabulated, the kinks, the measured Lipschitz constants.
    """

    def __init__(self, operator: Any, path: Callable[[float], Any], mu: float, T: float,
                 f: Callable | None = None, *, velocity: Callable | None = None, kinks: Sequence[float] = (),
                 cells: int = 64, rtol: float = 1e-13, smoothness: float = math.inf) -> None:
        if not hasattr(operator, "resolvent") or not hasattr(operator, "dim"):
            raise InvalidProblem(f"operator must be a verimono.Operator, got {operator!r}")
        if not callable(path):
            raise InvalidProblem(f"path must be a callable of t returning ({operator.dim},), got {path!r}")
        try:
            mu, T = float(mu), float(T)
        except (TypeError, ValueError):
            raise InvalidProblem(f"mu and T must be numbers, got mu = {mu!r}, T = {T!r}") from None
        if not (0.0 < mu < math.inf and 0.0 < T < math.inf):
            raise InvalidProblem(f"need 0 < mu < inf and 0 < T < inf, got mu = {mu!r}, T = {T!r}")
        for what, fn in (("f", f), ("velocity", velocity)):
            if fn is not None and not callable(fn):
                raise InvalidProblem(f"{what} must be callable, got {fn!r}")
        self.operator, self.path, self.mu, self.T, self.f = operator, path, mu, T, f
        try:
            self.smoothness = float(smoothness)
        except (TypeError, ValueError):
            raise InvalidProblem(f"smoothness must be a number >= 1 or inf, got {smoothness!r}") from None
        if not self.smoothness >= 1.0:
            raise InvalidProblem(f"smoothness must be a number >= 1 or inf, got {smoothness!r}")
        self._velocity = velocity
        self.n = int(operator.dim)
        self._x_cache: dict[float, np.ndarray] = {}
        self._U_cache: dict[float, np.ndarray] = {}
        z0 = self.z(0.0)
        if z0.shape != (self.n,):
            raise InvalidProblem(f"path(0) must have shape ({self.n},), got {z0.shape}")
        self.x0 = self.x(0.0)
        self._tabulate(int(cells), float(rtol), sorted({float(k) for k in kinks if 0.0 < float(k) < T}))

    # -- the solution, pointwise --------------------------------------------------------------------
    def z(self, t: float) -> np.ndarray:
        """The path ``z(t)``."""
        return np.asarray(self.path(float(t)), dtype=float)

    def x(self, t: float) -> np.ndarray:
        """``x*(t) = J_{μF(t,·)}(z(t))``."""
        t = float(t)
        v = self._x_cache.get(t)
        if v is None:
            v = self._resolve(t)[0]
            _remember(self._x_cache, t, v)
        return v.copy()

    __call__ = x

    def y(self, t: float) -> np.ndarray:
        """``y*(t) = (z(t) - x*(t))/μ ∈ F(t, x*(t))``."""
        return self._resolve(float(t))[1]

    def _xs(self, t: float) -> np.ndarray:
        return self._resolve(t)[0]

    def _resolve(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        z = self.z(t)
        x = np.asarray(self.operator.resolvent(z, self.mu, t), dtype=float)
        if x.shape != (self.n,) or not np.all(np.isfinite(x)) or not np.all(np.isfinite(z)):
            raise InvalidProblem(f"J_(mu F(t))(z(t)) at t = {t!r} is {x!r} for z(t) = {z!r}: need finite ({self.n},)")
        return x, (z - x) / self.mu

    def _g(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(y* - f(x*), x*, y*)`` at ``t``: the integrand of ``U`` besides ``x*``."""
        x, y = self._resolve(t)
        g = y if self.f is None else y - np.asarray(self.f(x), dtype=float)
        return g, x, y

    # -- the input ----------------------------------------------------------------------------------
    def U(self, t: float) -> np.ndarray:
        """``∫_0^t u = x*(t) - x*(0) + ∫_0^t (y* - f(x*))`` (tabulated partition plus 8-point Gauss on the rest)."""
        t = float(t)
        v = self._U_cache.get(t)
        if v is not None:
            return v.copy()
        if not -1e-12 * self.T <= t <= self.T * (1.0 + 1e-12):
            raise InvalidProblem(f"the manufactured input is tabulated on [0, {self.T:g}], not at t = {t!r}")
        t = min(max(t, 0.0), self.T)
        i = min(bisect.bisect_right(self._starts, t) - 1, len(self._starts) - 1)
        a = self._starts[i]
        v = self.x(t) - self.x0 + self._cum[i]
        if t > a:
            v = v + self._gauss(a, t)[0]
        _remember(self._U_cache, t, v)
        return v.copy()

    def u(self, t: float) -> np.ndarray:
        """``u(t) = x*'(t) + y*(t) - f(x*(t))`` (a.e.; the right limit at a kink)."""
        g, _, _ = self._g(float(t))
        return self.velocity(t) + g

    def velocity(self, t: float) -> np.ndarray:
        """``x*'(t)``: the given formula, else the finite difference of :meth:`velocity_with_error`."""
        return self.velocity_with_error(t)[0]

    def velocity_with_error(self, t: float, delta: float | None = None) -> tuple[np.ndarray, float]:
        """``(x*'(t), error estimate)``: Richardson-extrapolated differences (module docstring), ``(v, 0)``
        from a given formula.  Central ``δ, δ/2, δ/4`` (error ``O(δ⁶)``) unless a kink or an end of ``[0, T]``
        lies within ``δ``; then one-sided 3-point ``δ, δ/2, δ/4, δ/8`` (``O(δ⁵)``) away from it."""
        t = float(t)
        if self._velocity is not None:
            return np.asarray(self._velocity(t), dtype=float), 0.0
        # a power of two: t ± δ/2^j are then exact, so the offsets are the ones the formulas divide by (at t = T = 2π
        # an offset rounded by an ulp of t put 1.5e-12 into x*', 1.4e-13 after)
        d0 = 2.0 ** math.floor(math.log2(1e-3 * self.T if delta is None else float(delta)))
        near = 1e-9 * self.T           # a kink this close is at t (kinks are located to about 1e-10 T)
        left = max([0.0] + [k for k in self.kinks if k < t - near])
        right = min([self.T] + [k for k in self.kinks if k > t + near])
        at_kink = any(abs(k - t) <= near for k in self.kinks)
        tried: list[tuple[np.ndarray, float]] = []

        def good(r):
            return r[1] <= 1e-7 * (1.0 + float(np.max(np.abs(r[0]))))

        if not at_kink and t - left >= 1.5 * d0 and right - t >= 1.5 * d0:
            tried.append(self._central(t, d0))
            if good(tried[-1]):
                return tried[-1]
        # one-sided, away from the obstacle: forward first (the right limit at a kink), then backward
        if right - t > near:
            tried.append(self._one_sided(t, _power_of_two_below(min(d0, (right - t) / 2.5)), +1.0))
        if t - left > near and not (tried and good(tried[-1])):
            tried.append(self._one_sided(t, _power_of_two_below(min(d0, (t - left) / 2.5)), -1.0))
        if not tried:
            raise InvalidProblem(f"no finite-difference stencil fits at t = {t!r}")
        return min(tried, key=lambda r: r[1])

    def _central(self, t, d):
        xs = self._xs
        D = [(xs(t + s) - xs(t - s)) / (2.0 * s) for s in (d, d / 2.0, d / 4.0)]
        R1 = [(4.0 * D[1] - D[0]) / 3.0, (4.0 * D[2] - D[1]) / 3.0]
        R2 = (16.0 * R1[1] - R1[0]) / 15.0
        return R2, float(np.max(np.abs(R2 - R1[1])))

    def _one_sided(self, t, d, sign):
        def D(s):
            s = sign * s
            return (-3.0 * self._xs(t) + 4.0 * self._xs(t + s) - self._xs(t + 2.0 * s)) / (2.0 * s)
        D0, D1, D2, D3 = D(d), D(d / 2.0), D(d / 4.0), D(d / 8.0)      # error c2 δ² + c3 δ³ + c4 δ⁴ + ...
        R1 = [(4.0 * D1 - D0) / 3.0, (4.0 * D2 - D1) / 3.0, (4.0 * D3 - D2) / 3.0]
        R2 = [(8.0 * R1[1] - R1[0]) / 7.0, (8.0 * R1[2] - R1[1]) / 7.0]
        R3 = (16.0 * R2[1] - R2[0]) / 15.0                              # O(δ⁵): 3e-13 where O(δ⁴) left 4e-11
        return R3, float(np.max(np.abs(R3 - R2[1])))

    # -- the adaptive table ---------------------------------------------------------------------------
    def _rule(self, a: float, b: float, nodes, weights):
        """``∫_a^b g`` by the rule ``(nodes, weights)`` on ``[-1, 1]`` and the samples ``(s, x*(s), y*(s))``."""
        half, mid = 0.5 * (b - a), 0.5 * (a + b)
        total = np.zeros(self.n)
        samples = []
        for xi, w in zip(nodes, weights):
            s = min(max(mid + half * xi, a), b)
            g, x, y = self._g(s)
            total += (half * w) * g
            samples.append((s, x, y))
        return total, samples

    def _gauss(self, a: float, b: float):
        """8-point Gauss–Legendre ``∫_a^b g`` (degree 15) and its samples."""
        return self._rule(a, b, _XI, _W)

    def _tabulate(self, cells: int, rtol: float, given: list[float]) -> None:
        """The adaptive partition: a cell is accepted when 8-point Gauss–Legendre and 9-point Gauss–Lobatto (both
        of degree 15) agree to ``tol`` times its length, else halved.  Lobatto samples the cell's ends, which
        Gauss does not: a kink in the last 2% of a cell, invisible to Gauss on the cell and on its halves alike
        (both integrate the smooth piece exactly), moves the Lobatto value at first order in the sliver's
        length and is refined away."""
        if cells < 1:
            raise InvalidProblem(f"cells must be >= 1, got {cells}")
        T = self.T
        edges = sorted(set(np.linspace(0.0, T, cells + 1).tolist()) | set(given))
        pieces: list[tuple[float, float, np.ndarray, float, int]] = []
        samples: list[tuple[float, np.ndarray, np.ndarray]] = []
        first = [(a, b, self._gauss(a, b), self._rule(a, b, _XL, _WL)) for a, b in zip(edges[:-1], edges[1:])]
        scale = 1.0 + max(float(np.max(np.abs(y))) for *_, (_, smp) in first for _, _, y in smp)
        if self.f is not None:
            scale += max(float(np.max(np.abs(np.asarray(self.f(x), dtype=float)))) for *_, (_, smp) in first
                         for _, x, _ in smp)
        tol = max(rtol, 64.0 * np.finfo(float).eps) * scale

        def refine(a, b, depth, gauss=None, lobatto=None):
            (gv, gs) = gauss or self._gauss(a, b)
            (lv, ls) = lobatto or self._rule(a, b, _XL, _WL)
            diff = float(np.max(np.abs(gv - lv)))
            if diff <= tol * (b - a) or b - a <= _MIN_FRACTION * T:
                if b - a <= _MIN_FRACTION * T:
                    self._check_continuous(a, b)
                pieces.append((a, b, gv, diff, depth))
                samples.extend(gs + ls)
                return
            m = 0.5 * (a + b)
            refine(a, m, depth + 1)
            refine(m, b, depth + 1)

        for a, b, gauss, lobatto in first:
            refine(a, b, 0, gauss, lobatto)
        self._starts = [p[0] for p in pieces]
        cum = np.zeros((len(pieces), self.n))
        acc = np.zeros(self.n)
        for i, p in enumerate(pieces):
            cum[i] = acc
            acc = acc + p[2]
        self._cum = cum
        self.quadrature_error = float(sum(p[3] for p in pieces))
        self.cells = len(pieces)
        samples.sort(key=lambda smp: smp[0])
        ts = np.array([smp[0] for smp in samples])
        X = np.array([smp[1] for smp in samples])
        Y = np.array([smp[2] for smp in samples])
        ds = np.diff(ts)
        ok = ds > 1e-9 * T        # secants over shorter gaps are round-off
        self.lipschitz_x = float(np.max(np.linalg.norm(np.diff(X, axis=0)[ok], axis=1) / ds[ok]))
        self.lipschitz_y = float(np.max(np.linalg.norm(np.diff(Y, axis=0)[ok], axis=1) / ds[ok]))
        self.kinks, self.input_kinks = find_kinks(self, pieces, given)

    def _integrand(self, t: float) -> np.ndarray:
        return self._g(t)[0]

    def _check_continuous(self, a: float, b: float) -> None:
        xa, xb = self.x(a), self.x(b)
        if np.max(np.abs(xb - xa)) > 1e-8 * (1.0 + float(np.max(np.abs(xa)))):
            raise InvalidProblem(f"x*(t) = J_(mu F(t))(z(t)) jumps near t = {0.5 * (a + b):.9g} (from {xa} to {xb}): the "
                                 "path z and t ↦ F(t,·) must make it Lipschitz (module docstring)")

    # -- what the scheme should do ----------------------------------------------------------------------
    def error_bound(self, h: float, lipschitz: float | None = None, t: float | None = None) -> float:
        """The derived bound on ``max_{t_k ≤ t} |x_k - x*(t_k)|`` of the proximal scheme with largest step ``h``:
        ``h (Lip y* + L Lip x*)(e^{Lt} - 1)/(2L)`` (``t h Lip y*/2`` for ``L = 0``), ``t = T`` by default, with
        the measured Lipschitz constants — an estimate of a bound, whose constants are sampled, not proved."""
        if self.f is not None and lipschitz is None:
            raise InvalidProblem("the bound needs the Lipschitz constant of f (lipschitz=...)")
        L = 0.0 if self.f is None else float(lipschitz)
        t = self.T if t is None else float(t)
        growth = t if L == 0.0 else math.expm1(L * t) / L
        return float(h) * (self.lipschitz_y + L * self.lipschitz_x) * growth / 2.0

    def regularity(self) -> tuple[float, str]:
        """The highest order the data allow any convergent scheme here, derived from the construction (module
        docstring): ``x* = J_{μF(t,·)}(z(t))`` is as smooth as the path and ``t ↦ F(t,·)`` (``smoothness``, C^∞ by
        default) except where the resolvent switches regime — a kink of ``x*``, where ``x*'`` jumps: order 1 at
        most; where only the input's integrand ``y* - f(x*)`` kinks (a field Lipschitz but not smooth along the
        solution), ``x*`` is smooth and ``u`` Lipschitz: the cell holding the kink errs by ``O(h²)``, order 2 at
        most; with neither, the path's and the operator's smoothness."""
        if self.kinks:
            return 1.0, (f"x* = J_(mu F(t))(z(t)) is Lipschitz and x*' jumps where the resolvent switches regime "
                         f"({len(self.kinks)} kinks detected): order 1 at most")
        if self.input_kinks:
            return min(2.0, self.smoothness), (
                f"x* has no kink, but the input u = x*' + y* - f(x*) kinks at {len(self.input_kinks)} times where f is "
                "not smooth along x*: an O(h^2) error on the cell holding each, order 2 at most")
        what = "smooth" if self.smoothness == math.inf else f"of order {self.smoothness:g}"
        return self.smoothness, (f"no kink of x* = J_(mu F(t))(z(t)) or of the input on [0, T] (the resolvent never "
                                 f"switches regime along the path): the data are as smooth as the path and "
                                 f"t -> F(t,.), stated {what}")

    def order(self, lipschitz: float | None = None) -> Order:
        """The derived :class:`Order` of the proximal scheme here: 1 (module docstring), with the solution's
        :meth:`regularity`."""
        bound = ""
        if self.f is None or lipschitz is not None:
            bound = f"; here sup error <= {self.error_bound(1.0, lipschitz):.3g} h with the measured constants"
        reg, why = self.regularity()
        return Order(1.0, "manufactured solution (verimono.reference.manufactured): y* = (z - x*)/mu in F(t, x*) at every t "
                          "and monotonicity of F(t_(k+1),.) give |e_(k+1)| <= (1 + hL)|e_k| + h^2 (Lip y* + L Lip x*)/2"
                          ", order 1 (for a fixed subdifferential: Rulla 1996, x0 in D(dphi), BV forcing)" + bound,
                     regularity=reg, regularity_source=why)

    def describe(self) -> str:
        """One paragraph: the construction, the kinks, the quadrature error, the measured constants."""
        ks = ", ".join(f"{k:.6g}" for k in self.kinks[:12]) + (" ..." if len(self.kinks) > 12 else "")
        return (f"manufactured: x* = J_(mu F(t))(z(t)) with z = {getattr(self.path, '__name__', 'path')}, "
                f"mu = {self.mu:g}; kinks of x* at t = [{ks}]; int u over cells from U (adaptive Gauss-Legendre "
                f"against Gauss-Lobatto, {self.cells} cells, error estimate {self.quadrature_error:.2g}); regularity "
                f"{self.regularity()[0]:g}; measured "
                f"Lip x* = {self.lipschitz_x:.4g}, Lip y* = {self.lipschitz_y:.4g}")

    def __getstate__(self) -> dict:
        """Pickled (to an executor's workers) without the caches of ``x*`` and ``U``."""
        state = dict(self.__dict__)
        state["_x_cache"], state["_U_cache"] = {}, {}
        return state

    def __repr__(self) -> str:
        return f"ManufacturedSolution({self.operator.name}, mu={self.mu:g}, T={self.T:g}, kinks={len(self.kinks)})"


def _power_of_two_below(d: float) -> float:
    return 2.0 ** math.floor(math.log2(d))


def _remember(cache: dict, key: float, value: np.ndarray) -> None:
    if len(cache) >= _CACHE_SIZE:
        cache.clear()
    cache[key] = value


def manufactured_problem(operator: Any, *, T: float, path: Callable[[float], Any] | None = None, mu: float = 1.0,
                         f: Callable | None = None, lipschitz: float | None = None, name: str | None = None,
                         order: Any = None, steps: Sequence[float] | None = None, velocity: Callable | None = None,
                         kinks: Sequence[float] = (), smoothness: float = math.inf, **problem_kw: Any) -> Problem:
    """A :class:`verimono.Problem` whose exact solution is ``x*(t) = J_{μF(t,·)}(z(t))`` (module docstring).

    ``operator`` is ``F``; ``path`` is ``z`` (default :func:`lissajous`: a figure eight of amplitude 1.5
    about the origin, which leaves and re-enters unit-size sets); ``mu`` is ``μ``; ``f`` and its Lipschitz
    constant ``lipschitz`` as in :class:`verimono.Problem`.  The problem has ``x0 = x*(0)``,
    ``exact`` = the :class:`ManufacturedSolution` (``problem.exact.y``, ``.kinks``, ``.error_bound``),
    ``U`` (what the scheme uses: ``∫u`` per cell with no derivative) and ``u`` (pointwise, a.e.), the
    derived order 1 unless ``order`` says otherwise, ``steps`` ``T/50, ..., T/800`` by default, and a
    description in ``notes``.  ``velocity(t) = x*'(t)`` in closed form, when known, replaces the finite
    differences of ``u``; ``kinks`` (times where ``x*'`` jumps, when known) become cell edges.  ``smoothness``: the
    order of smoothness of the path and of ``t ↦ F(t,·)`` (C^∞ by default, as the default path is); the solution's
    regularity — what a scheme claiming a higher order is held to — is derived from it and from the kinks found
    (:meth:`ManufacturedSolution.regularity`: 1 with a kink of ``x*``, 2 with a kink of the input only, else
    ``smoothness``).  Other
    keywords (``phi``, ``sigma``, ``theta``) go to :class:`verimono.Problem`.  Built eagerly (a few thousand
    resolvents), so a module can hold ``problem = manufactured_problem(...)``.
    """
    clash = sorted(set(problem_kw) & {"x0", "exact", "u", "U", "notes", "initial_jump"})
    if clash:
        raise InvalidProblem(f"manufactured_problem sets {', '.join(clash)} itself")
    dim = getattr(operator, "dim", None)
    if dim is None:
        raise InvalidProblem(f"operator must be a verimono.Operator, got {operator!r}")
    sol = ManufacturedSolution(operator, lissajous(dim) if path is None else path, mu, T, f, velocity=velocity,
                               kinks=kinks, smoothness=smoothness)
    return Problem(operator, sol.x0, T, f=f, u=sol.u, U=sol.U, exact=sol,
                   order=sol.order(lipschitz) if order is None else order,
                   name=name or f"manufactured {getattr(operator, 'name', 'F')}", lipschitz=lipschitz,
                   steps=[T / k for k in (50, 100, 200, 400, 800)] if steps is None else steps,
                   notes=sol.describe(), **problem_kw)


# -- three examples: a moving set, a time-dependent subdifferential, a passive complementarity system ---------

def _field(x: np.ndarray) -> np.ndarray:
    """``f(x) = -x/2 + 0.3 sin(Px)``, ``P`` the reversal of the coordinates: Lipschitz with ``L = 0.8``.  Written for a
    batch of states ``(B, n)`` too: the coordinates are reversed along the last axis, never the batch's."""
    return -0.5 * x + 0.3 * np.sin(x[..., ::-1])


def moving_box(T: float = 2 * math.pi, mu: float = 1.0, drift: Sequence[float] = (0.3, -0.2)) -> Problem:
    """``F(t,·) = N_{S(t)}``, ``S(t) = [-1 + 0.3 sin t, 1 + 0.3 sin t] × [-0.8, 0.8 + 0.2 cos t]``, a constant field
    ``f = drift``, the default path: **order 2, derived** (so a lagged operator, order 1, fails here).

    Componentwise the scheme is ``x^i_{k+1} = clamp_{S_i(t_{k+1})}(x^i_k + Δx*^i + ∫ y*^i)`` (``h f`` cancels
    against ``∫ f``), and ``clamp`` is 1-Lipschitz, so ``|e^i_{k+1}| ≤ |e^i_k| + ℓ^i_k`` with ``ℓ^i_k`` the error
    of one step from the exact ``x*(t_k)``.  On a cell where the component stays inside, ``y*^i = 0``; where it
    stays on a face, ``y*^i`` has the sign of that face's normal cone at ``t_{k+1}``: both give ``ℓ^i_k = 0``.
    On a cell holding a switch ``σ`` (a kink of ``x*``), ``y*^i`` vanishes at ``σ`` and is Lipschitz, so
    ``ℓ^i_k ≤ Lip y* · h²/2``.  Hence ``sup |x_k - x*(t_k)| ≤ (number of kinks) · Lip y* · h²/2``.  The path
    crosses each of the four faces: twelve engagements and releases on ``[0, 2π]``, the twelve kinks of ``x*``.
    The steps ``T/101, ..., T/1616`` double exactly; the error constant ``e/h²`` wanders (0.3 to 1.4 over
    grids) with where the switches fall inside their cells, so the fitted interval is wide.
    """
    b = np.array(drift, dtype=float)
    box = Box(lambda t: np.array([-1.0 + 0.3 * math.sin(t), -0.8]),
              lambda t: np.array([1.0 + 0.3 * math.sin(t), 0.8 + 0.2 * math.cos(t)]), name="moving box")
    def drift_field(x):             # constant, with the shape of x: one drift per state of a batch (B, n)
        return np.broadcast_to(b, np.shape(x)).copy()

    sol_problem = manufactured_problem(NormalCone(box), T=T, mu=mu, f=drift_field, lipschitz=0.0,
                                       name="manufactured moving box", steps=[T / k for k in (101, 202, 404, 808, 1616)])
    sol = sol_problem.exact
    c2 = len(sol.kinks) * sol.lipschitz_y / 2.0
    order = Order(2.0, "manufactured moving box with a constant field: componentwise clamps, exact on cells without "
                       "a switch, Lip y* h^2/2 on a cell with one (derived in verimono.reference.manufactured.moving_box): "
                       f"sup error <= kinks * Lip y* h^2/2 = {c2:.3g} h^2 with the measured constants",
                  regularity=sol.regularity()[0], regularity_source=sol.regularity()[1])
    return sol_problem.replace(order=order)


def norm_subdifferential(T: float = 2 * math.pi, mu: float = 0.8) -> Problem:
    """``F(t,·) = ∂(c(t)|·|)``, ``c(t) = 1 + sin(t)/2``, ``f`` Lipschitz (``L = 0.8``), the default path: order 1.

    ``x* = max(1 - μc/|z|, 0) z`` sticks at 0 while ``|z(t)| ≤ μc(t)`` — twice, around ``t = π/2`` and
    ``3π/2``, where the figure eight passes the origin — so ``x*`` has four kinks; ``y* = c x*/|x*|`` off 0.
    The resolvent moves in ``t`` with modulus ``μ|c'| ≤ μ/2``: ``x*`` is Lipschitz.
    """
    F = NormSubdifferential(lambda t: 1.0 + 0.5 * math.sin(t), dim=2, name="∂(c(t)|x|)")
    return manufactured_problem(F, T=T, mu=mu, f=_field, lipschitz=0.8, name="manufactured ∂(c(t)|x|)")


#: the passive complementarity example: a damped oscillator with a hard and a compliant unilateral constraint
LCS_DATA = {"A": [[0.0, 1.0], [-1.0, -0.2]], "C": [[1.0, 0.0], [1.0, 1.0]], "D": [[0.0, 0.0], [0.0, 0.5]]}


def complementarity(T: float = 2 * math.pi, mu: float = 1.0) -> Problem:
    """``x' = Ax + Bz + f(x) + u``, ``w = Cx + Dz + v(t)``, ``0 ≤ z ⊥ w ≥ 0`` with ``B = Cᵀ`` (:data:`LCS_DATA`),
    ``v(t) = (0.6 + 0.2 sin t, 0.8 + 0.3 cos 2t)``; ``F = H`` of :meth:`verimono.lcs.LinearRelationSystem.operator`,
    the default path, ``μ = 1``: order 1.

    Passive with storage ``|x|²/2``: ``A + Aᵀ = diag(0, -0.4) ⪯ 0``, ``B = Cᵀ``, ``D ⪰ 0``.  ``C`` is invertible,
    so with ``e(t) = C^{-1} v(t)``, ``H(t, x) = H_0(x + e) + Ae`` and ``J_{μH(t)}(w) = J_{μH_0}(w + (I - μA)e) - e``:
    the resolvent moves in ``t`` with modulus ``≤ (1 + |I - μA|)|C^{-1}| |v'|``, so ``x*`` is Lipschitz.  Along
    the default path the compliant contact (second row) engages at ``t ≈ 1.76``, the hard one joins at ``2.28``,
    the compliant one releases at ``2.74``, the hard one at ``3.32``; the compliant one acts again on
    ``[4.92, 5.81]``: six kinks.
    """
    from ..lcs import Complementarity, LinearRelationSystem

    A, C, D = (np.array(LCS_DATA[k]) for k in ("A", "C", "D"))
    system = LinearRelationSystem(A, C.T, C, D, Complementarity(), name="passive LCS",
                                  v=lambda t: np.array([0.6 + 0.2 * math.sin(t), 0.8 + 0.3 * math.cos(2.0 * t)]))
    return manufactured_problem(system.operator(), T=T, mu=mu, f=_field, lipschitz=0.8,
                                name="manufactured passive LCS")


def examples() -> list[Problem]:
    """The three examples, freshly built: :func:`moving_box`, :func:`norm_subdifferential`, :func:`complementarity`."""
    return [moving_box(), norm_subdifferential(), complementarity()]


__all__ = ["manufactured_problem", "ManufacturedSolution", "lissajous", "moving_box", "norm_subdifferential",
           "complementarity", "examples"]
