"""Blind set 9: planted violations of the paper's laws, and lawful controls, of kinds new against sets 1, 7 and 8.

Written without reading ``verimono/checks/`` nor ``verimono/core/tolerances.py``: from the paper, README.md,
docs/checks.md, docs/paper.md, docs/precision.md and the public API (``vm.operator_from_resolvent``,
``vm.operator_from_prox``, a stepper ``stepper(problem, t_grid)``).  Of the earlier blind sets only the names and
one-line bugs of their entries were read.  The kinds here: a step clamped above ``λ = 10^3``; a Taylor series below
``λ = 10^-2``; a fast path at integer times reading a table shifted by one knot; interleaved bounds reshaped in
the wrong order; a returned scratch buffer overwritten by the next call; an inner conjugate-gradient solve stopped
at a relative residual ``10^-6``; proximal maps of non-convex penalties (hard and firm thresholding); a linear
resolvent symmetrised (its skew part dropped); a block soft threshold forgetting a ragged last group; a soft
threshold in blocks of 8 whose scalar tail (coordinates 8, 9) forgets λ; the prox of a smoothed function (Huber)
declared with the value of the original (``|·|_1``); a box's value with strict bounds (``+inf`` on the faces the
prox lands on); odd coordinates clipped from above only; a soft threshold computed in place on a writeable
float64 input.  Steppers that integrate internally on their own
uniform grid and interpolate, refill a 256-cell input buffer only once, record the predictor at integer times,
take ``f`` after the input, freeze ``f`` at ``x0``, accumulate the input increments, sub-step cells above 0.1,
project ``x0`` first, extrapolate (Richardson), alias the predictor to the stored state (an in-place ``+=``),
multiply ``∫u`` by ``h`` once more, step ``f`` with Adams–Bashforth 2, or write the final state into
``problem.x0`` "to resume from it".

Each :class:`Entry` has ``build()`` (the subject as a user hands it to ``vm.check_operator`` /
``vm.check_stepper``), the law of the paper it breaks (``label``), the smallest input showing it
(``smallest``), what the bug is (``bug``) and, for a control, the plant it is the lawful twin of (``twin``): the
same code with the faulty arithmetic made right, so a check failing both is a false alarm.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Callable

import numpy as np

import verimono as vm

RES = "prop:maxmon-resolvent-Yosida"
ITER = "eq:iteration"


@dataclasses.dataclass(frozen=True)
class Entry:
    name: str
    kind: str              # "operator" | "stepper"
    label: str             # the paper's statement the plant breaks (a control obeys it)
    lawful: bool           # False: plant, True: control
    build: Callable[[], Any]
    smallest: str
    bug: str
    twin: str | None = None
    witness: Callable[[], float] | None = None     # plain NumPy: the law's ratio at ``smallest`` (> 1: violated)


def _f(x):
    return np.asarray(x, dtype=float)


def _tol(*arrays, tol=None):
    if tol is not None:
        return float(tol)
    s = 1.0 + max((float(np.max(np.abs(a), initial=0.0)) for a in arrays), default=0.0)
    return 1e-9 * s


def _soft(x, lam):
    x = _f(x)
    return np.sign(x) * np.maximum(np.abs(x) - lam, 0.0)


def l1_min_norm(x, t=0.0):
    return np.sign(_f(x))


def l1_contains(x, y, t=0.0, tol=None):
    """y ∈ ∂|x|_1: y_i = sign x_i where x_i ≠ 0, |y_i| ≤ 1 where x_i = 0."""
    x, y = _f(x), _f(y)
    tol = _tol(x, y, tol=tol)
    nz = np.abs(x) > tol
    return bool(np.all(np.abs(y[nz] - np.sign(x[nz])) <= tol) and np.all(np.abs(y[~nz]) <= 1.0 + tol))


def box_contains(x, y, lo, hi, tol=None):
    """y ∈ N_[lo,hi](x), coordinate by coordinate (a coordinate within tol of a face may carry that face's normal)."""
    x, y = _f(x), _f(y)
    tol = _tol(x, y, tol=tol)
    if np.any(x > hi + tol) or np.any(x < lo - tol):
        return False
    up, down = x >= hi - tol, x <= lo + tol
    return bool(np.all((up & (y >= -tol)) | (down & (y <= tol)) | (np.abs(y) <= tol)))


def ball_contains(x, y, c, tol=None):
    """y ∈ N_B(x), B the unit ball centred at c: inside y = 0; on the sphere y = μ(x - c), μ ≥ 0."""
    x, y = _f(x), _f(y)
    tol = _tol(x, y, tol=tol)
    d = x - c
    nd, ny = float(np.linalg.norm(d)), float(np.linalg.norm(y))
    if nd > 1.0 + tol:
        return False
    if nd < 1.0 - tol:
        return bool(ny <= tol)
    return bool(float(y @ d) >= ny * nd - tol * (1.0 + ny))


def proj_ball(x, c):
    d = _f(x) - c
    n = float(np.linalg.norm(d))
    return c + (d.copy() if n <= 1.0 else d / n)


def _linear_members(A):
    def contains(x, y, t=0.0, tol=None):
        x, y = _f(x), _f(y)
        return bool(np.max(np.abs(y - A @ x)) <= 4 * _tol(x, y, tol=tol))
    return dict(contains=contains, min_norm=lambda x, t=0.0: A @ _f(x))


# ----------------------------------------------------------------------------------------------------
# operators
# ----------------------------------------------------------------------------------------------------

_A_ROT = np.array([[1.0, 2.0], [-2.0, 1.0]])


def _clamped_build(cap, name):
    """F(x) = Ax, A = [[1, 2], [-2, 1]]: J_λ = (I + λA)^{-1}.  The step is clamped to ``cap`` "to keep I + λA
    well conditioned": ``cap = 1e3`` (the bug) is a different resolvent for every λ > 10^3; ``cap = inf`` none."""
    def J(x, lam, t=0.0):
        return np.linalg.solve(np.eye(2) + min(float(lam), cap) * _A_ROT, _f(x))
    return vm.operator_from_resolvent(J, 2, name=name, **_linear_members(_A_ROT))


def _series_build(below, name):
    """F = ∂g, g = |x|²/2: prox_λg(x) = x/(1 + λ).  Below ``λ < below`` it is the series x(1 - λ + λ²), truncated
    after λ²: relative error λ³ in J and λ² in the Yosida approximation.  ``below = 1e-2`` (the bug) is off by up
    to 10^-4 in Y_λ; ``below = 1e-6`` (the control) only where λ³ is under a float64 ulp."""
    def prox(x, lam):
        x, lam = _f(x), float(lam)
        if lam < below:
            return x * (1.0 - lam + lam * lam)
        return x / (1.0 + lam)
    return vm.operator_from_prox(prox, value=lambda x: 0.5 * float(_f(x) @ _f(x)), shape=3, name=name)


def _centre(t):
    t = np.asarray(t, dtype=float)
    return 0.5 * np.stack([np.cos(t), np.sin(t)], axis=-1)


_KNOTS_OK = _centre(np.arange(0.0, 65.0))       # c(0), c(1), ..., c(64)
_KNOTS_SHIFTED = _centre(np.arange(1.0, 66.0))  # c(1), ..., c(65): built from arange(1, N + 1)


def _knots_build(table, name):
    """N_{B(c(t), 1)}, c(t) = (cos t, sin t)/2: J = the projection.  At integer times 1 ≤ t ≤ 64 the centre is read
    from a precomputed table of the knots ("fast path"); the plant's table was built from ``arange(1, N + 1)``, so
    at t = k it holds c(k + 1).  Away from integer t both compute c(t)."""
    def c_of(t):
        t = float(t)
        if t.is_integer() and 1.0 <= t <= 64.0:
            return table[int(t)]
        return _centre(t)

    def J(x, lam, t=0.0):
        return proj_ball(x, c_of(t))
    return vm.operator_from_resolvent(J, 2, name=name, project_domain=lambda x, t=0.0: proj_ball(x, _centre(t)),
                                      contains=lambda x, y, t=0.0, tol=None: ball_contains(x, y, _centre(t), tol))


_BOUNDS = np.array([-3.0, -2.0, -1.0, 0.0, 1.0, 2.0])     # interleaved (lo_0, hi_0, lo_1, hi_1, lo_2, hi_2)
_LO, _HI = _BOUNDS.reshape(3, 2).T                          # (-3, -1, 1), (-2, 0, 2)


def _bounds_build(row_major, name):
    """N of the box [lo, hi] ⊂ R^3 whose bounds come interleaved (lo_0, hi_0, lo_1, ...).  ``row_major=True`` (the
    bug) reads them with ``reshape(2, 3)``: another box, (-3, -2, -1)..(0, 1, 2), still a valid one."""
    lo, hi = _BOUNDS.reshape(2, 3) if row_major else _BOUNDS.reshape(3, 2).T

    def J(x, lam, t=0.0):
        return np.clip(_f(x), lo, hi)
    return vm.operator_from_resolvent(J, 3, name=name, project_domain=lambda x, t=0.0: np.clip(_f(x), _LO, _HI),
                                      contains=lambda x, y, t=0.0, tol=None: box_contains(x, y, _LO, _HI, tol))


def _buffer_build(copy, name):
    """N_[-1,1]^3 with the projection written into a preallocated output buffer (no allocation per call).
    ``copy=False`` (the bug) returns the buffer itself: the next call overwrites the value the caller holds."""
    buf = np.empty(3)

    def J(x, lam, t=0.0):
        np.clip(_f(x), -1.0, 1.0, out=buf)
        return buf.copy() if copy else buf
    lo, hi = -np.ones(3), np.ones(3)
    return vm.operator_from_resolvent(J, 3, name=name, project_domain=lambda x, t=0.0: np.clip(_f(x), -1.0, 1.0),
                                      contains=lambda x, y, t=0.0, tol=None: box_contains(x, y, lo, hi, tol))


_S_SPD = np.array([[2.0, 1.0, 0.0], [1.0, 2.0, 1.0], [0.0, 1.0, 2.0]])   # symmetric, eigenvalues 2 - √2, 2, 2 + √2


def _cg(M, b, rtol, maxiter=50):
    z = np.zeros_like(b)
    r = b.copy()
    p = r.copy()
    rr = float(r @ r)
    stop = (rtol * float(np.linalg.norm(b))) ** 2
    for _ in range(maxiter):
        if rr <= stop or rr == 0.0:
            break
        Mp = M @ p
        alpha = rr / float(p @ Mp)
        z = z + alpha * p
        r = r - alpha * Mp
        rr_new = float(r @ r)
        p = r + (rr_new / rr) * p
        rr = rr_new
    return z


def _cg_build(rtol, name):
    """F(x) = Sx, S symmetric positive definite: J_λx solves (I + λS)z = x.  ``rtol > 0`` (the bug: 1e-6, a common
    default) stops conjugate gradients at that relative residual; the control (``rtol = 0``) solves directly."""
    def J(x, lam, t=0.0):
        x = _f(x)
        M = np.eye(3) + float(lam) * _S_SPD
        return _cg(M, x, rtol) if rtol > 0 else np.linalg.solve(M, x)
    return vm.operator_from_resolvent(J, 3, name=name, **_linear_members(_S_SPD))


def _hard_build():
    """Hard thresholding x·1{|x| > √(2λ)}, the proximal map of the non-convex λ|x|_0, handed over as a prox."""
    def prox(x, lam):
        x = _f(x)
        return np.where(np.abs(x) > math.sqrt(2.0 * float(lam)), x, 0.0)
    return vm.operator_from_prox(prox, value=lambda x: float(np.count_nonzero(_f(x))), shape=3,
                                 name="hard threshold (prox of |x|_0)")


def _firm_build(gamma=3.0):
    """Firm thresholding (the proximal map of the non-convex minimax concave penalty, γ = 3): 0 for |x| ≤ λ,
    sign(x)(|x| - λ)γ/(γ - 1) for λ < |x| ≤ γλ, x beyond: continuous, slope 3/2 in the middle band."""
    def prox(x, lam):
        x, lam = _f(x), float(lam)
        a = np.abs(x)
        mid = np.sign(x) * (a - lam) * gamma / (gamma - 1.0)
        return np.where(a <= lam, 0.0, np.where(a <= gamma * lam, mid, x))
    return vm.operator_from_prox(prox, shape=3, name="firm threshold (prox of MCP)")


_A_SK = np.array([[1.0, 3.0], [-3.0, 1.0]])


def _symmetrised_build(symmetrise, name):
    """F(x) = Ax, A = [[1, 3], [-3, 1]].  ``symmetrise=True`` (the bug) factors I + λ(A + Aᵀ)/2 "for a symmetric
    solver": the skew part dropped, J_λ = x/(1 + λ), still firmly nonexpansive but the resolvent of I, not of A."""
    M = 0.5 * (_A_SK + _A_SK.T) if symmetrise else _A_SK

    def J(x, lam, t=0.0):
        return np.linalg.solve(np.eye(2) + float(lam) * M, _f(x))
    return vm.operator_from_resolvent(J, 2, name=name, **_linear_members(_A_SK))


_GROUPS5 = [slice(0, 2), slice(2, 4), slice(4, 5)]


def _group_norm(v):
    return float(np.hypot(v[0], v[1])) if v.size == 2 else float(abs(v[0]))


def _group_build(ragged, name):
    """F = ∂g, g(x) = Σ_groups |x_G|, groups (0, 1), (2, 3), (4) of R^5: block soft thresholding.
    ``ragged=False`` (the bug) loops over ``n // 2`` pairs: the lone last coordinate is returned unchanged."""
    n = 5

    def J(x, lam, t=0.0):
        x, lam = _f(x), float(lam)
        out = x.copy()
        ngroups = (n + 1) // 2 if ragged else n // 2
        for g in _GROUPS5[:ngroups]:
            v = x[g]
            nv = _group_norm(v)
            out[g] = 0.0 if nv <= lam else v - (lam / nv) * v
        return out

    def min_norm(x, t=0.0):
        x = _f(x)
        out = np.zeros(n)
        for g in _GROUPS5:
            nv = _group_norm(x[g])
            if nv > 0:
                out[g] = x[g] / nv
        return out

    def contains(x, y, t=0.0, tol=None):
        x, y = _f(x), _f(y)
        tol = _tol(x, y, tol=tol)
        for g in _GROUPS5:
            nv, ny = _group_norm(x[g]), _group_norm(y[g])
            if nv > tol:
                if np.max(np.abs(y[g] - x[g] / nv)) > tol:
                    return False
            elif ny > 1.0 + tol:
                return False
        return True
    return vm.operator_from_resolvent(J, n, name=name, min_norm=min_norm, contains=contains)


def _simd_build(tail_lam, name):
    """F = ∂|·|_1 on R^10: soft thresholding written as blocks of 8 coordinates ("SIMD lanes") and a scalar tail.
    ``tail_lam=False`` (the bug) thresholds the tail (coordinates 8, 9) at 1 instead of λ: wrong only there, and
    only for λ ≠ 1."""
    n, W = 10, 8

    def J(x, lam, t=0.0):
        x, lam = _f(x), float(lam)
        out = np.empty(n)
        head = (n // W) * W
        for b in range(0, head, W):
            out[b:b + W] = _soft(x[b:b + W], lam)
        for i in range(head, n):
            out[i] = _soft(x[i:i + 1], lam if tail_lam else 1.0)[0]
        return out
    return vm.operator_from_resolvent(J, n, name=name, contains=l1_contains, min_norm=l1_min_norm)


def _huber_build(mu, name):
    """Declared g = |x|_1; prox of λ·Huber_μ (x μ/(μ + λ) for |x| ≤ μ + λ, x - λ sign x beyond).  ``mu = 0.1`` (the
    bug) is the prox of the smoothed function; ``mu = 0`` (the control) the same code is soft thresholding."""
    def prox(x, lam):
        x, lam = _f(x), float(lam)
        a = np.abs(x)
        return np.where(a <= mu + lam, x * (mu / (mu + lam)), x - lam * np.sign(x))
    return vm.operator_from_prox(prox, value=lambda x: float(np.abs(_f(x)).sum()), shape=3, name=name)


def _strict_box_build(strict, name):
    """g = ι_[-1,1]^3, prox = clip.  ``strict=True`` (the bug) writes the value with strict inequalities: +inf on
    the faces, where every prox of an outside point lands."""
    def value(x):
        a = np.abs(_f(x))
        inside = np.all(a < 1.0) if strict else np.all(a <= 1.0)
        return 0.0 if inside else np.inf
    return vm.operator_from_prox(lambda x: np.clip(_f(x), -1.0, 1.0), value=value, shape=3, name=name, step=False)


def _odd_build(both, name):
    """N_[-1,1]^4 with the clip written per parity: even coordinates ``np.clip``, odd ones ``np.minimum(·, 1)``
    (the bug: their lower face forgotten) or ``np.clip`` too (the control)."""
    lo, hi = -np.ones(4), np.ones(4)

    def J(x, lam, t=0.0):
        out = _f(x).copy()
        out[0::2] = np.clip(out[0::2], -1.0, 1.0)
        out[1::2] = np.clip(out[1::2], -1.0, 1.0) if both else np.minimum(out[1::2], 1.0)
        return out
    return vm.operator_from_resolvent(J, 4, name=name, project_domain=lambda x, t=0.0: np.clip(_f(x), -1.0, 1.0),
                                      contains=lambda x, y, t=0.0, tol=None: box_contains(x, y, lo, hi, tol))


def _in_place_build(copy, name):
    """Soft thresholding (the resolvent of ∂|·|_1) computed in place "to save an allocation" when the input is a
    writeable float64 array (a copy otherwise): ``copy=False`` (the bug) overwrites the caller's x with J_λx;
    read-only and integer inputs get the right answer and stay unchanged."""
    def J(x, lam, t=0.0):
        x = np.asarray(x)
        if x.dtype == np.float64 and x.flags.writeable:
            out = x.copy() if copy else x
            np.copysign(np.maximum(np.abs(out) - float(lam), 0.0), out, out=out)
            return out
        return _soft(x, float(lam))
    return vm.operator_from_resolvent(J, 3, name=name, contains=l1_contains, min_norm=l1_min_norm)


# ----------------------------------------------------------------------------------------------------
# steppers: the paper's scheme x_{k+1} = J_{h F(t_{k+1})}(x_k + h f(x_k) + ∫u) and its planted variants
# ----------------------------------------------------------------------------------------------------

def _field(problem, x):
    return _f(problem.f(x)) if problem.f is not None else 0.0


def _z(problem, x, h, dU, k):
    z = x + h * _field(problem, x)
    if dU is not None:
        z = z + dU[k - 1]
    return z


def _J(problem, z, h, t):
    return _f(problem.operator.resolvent(z, h, t))


def proximal(problem, t_grid):
    t = _f(t_grid)
    dU = problem.input_increments(t)
    x = [_f(problem.x0).copy()]
    for k in range(1, t.size):
        h = t[k] - t[k - 1]
        x.append(_J(problem, _z(problem, x[-1], h, dU, k), h, t[k]))
    return np.array(x)


def internal_grid_interpolated(problem, t_grid):
    """Steps on its own uniform grid (cells ≤ 0.01, at least as many as the caller's) and returns the states
    interpolated linearly at the caller's nodes, as a dense-output integrator does."""
    t = _f(t_grid)
    K = t.size - 1
    M = max(K, int(math.ceil((t[-1] - t[0]) / 0.01)))
    s = np.linspace(t[0], t[-1], M + 1)
    xs = proximal(problem, s)
    flat = xs.reshape(M + 1, -1)
    out = np.stack([np.interp(t, s, flat[:, i]) for i in range(flat.shape[1])], axis=1)
    out[0] = flat[0]
    return out.reshape((K + 1,) + xs.shape[1:])


def _ring_factory(refill):
    """The input increments read through a 256-cell buffer filled chunk by chunk; ``refill=False`` (the bug) fills
    it once, so from cell 257 on the increments of cells 1, 2, ... are used again."""
    W = 256

    def stepper(problem, t_grid):
        t = _f(t_grid)
        x = [_f(problem.x0).copy()]
        buf, start = problem.input_increments(t[:W + 1]), 0
        for k in range(1, t.size):
            h = t[k] - t[k - 1]
            if refill and buf is not None and k - 1 >= start + W:
                start = k - 1
                buf = problem.input_increments(t[start:start + W + 1])
            z = x[-1] + h * _field(problem, x[-1])
            if buf is not None:
                z = z + buf[(k - 1 - start) % W]
            x.append(_J(problem, z, h, t[k]))
        return np.array(x)
    stepper.__name__ = "ring_buffer_refilled" if refill else "ring_buffer_filled_once"
    return stepper


def _checkpoint_factory(record_state):
    """The scheme with a checkpoint hook at integer times: ``record_state=False`` (the bug) stores the predictor
    z_k there instead of the state J(z_k) (the recursion itself continues from J(z_k))."""
    def stepper(problem, t_grid):
        t = _f(t_grid)
        dU = problem.input_increments(t)
        x = [_f(problem.x0).copy()]
        out = [x[0]]
        for k in range(1, t.size):
            h = t[k] - t[k - 1]
            z = _z(problem, x[-1], h, dU, k)
            x.append(_J(problem, z, h, t[k]))
            out.append(z if (not record_state and float(t[k]).is_integer()) else x[-1])
        return np.array(out)
    stepper.__name__ = "checkpoint_records_state" if record_state else "checkpoint_records_predictor"
    return stepper


def _field_input_factory(after):
    """z = x + ∫u + h f(·): ``after=True`` (the bug) evaluates f at x + ∫u, the control at x."""
    def stepper(problem, t_grid):
        t = _f(t_grid)
        dU = problem.input_increments(t)
        x = [_f(problem.x0).copy()]
        for k in range(1, t.size):
            h = t[k] - t[k - 1]
            w = x[-1] + (dU[k - 1] if dU is not None else 0.0)
            x.append(_J(problem, w + h * _field(problem, w if after else x[-1]), h, t[k]))
        return np.array(x)
    stepper.__name__ = "field_after_input" if after else "field_before_input"
    return stepper


def field_frozen_at_x0(problem, t_grid):
    """f evaluated once, at x0 ("the field varies slowly"), and used on every cell."""
    t = _f(t_grid)
    dU = problem.input_increments(t)
    x = [_f(problem.x0).copy()]
    f0 = _field(problem, x[0])
    for k in range(1, t.size):
        h = t[k] - t[k - 1]
        z = x[-1] + h * f0 + (dU[k - 1] if dU is not None else 0.0)
        x.append(_J(problem, z, h, t[k]))
    return np.array(x)


def _cumulative_factory(cumulative):
    """The input term read from an array of increments; ``cumulative=True`` (the bug) takes ``np.cumsum`` of them,
    ∫_{t_0}^{t_{k+1}} u instead of ∫_{t_k}^{t_{k+1}} u."""
    def stepper(problem, t_grid):
        t = _f(t_grid)
        dU = problem.input_increments(t)
        if dU is not None and cumulative:
            dU = np.cumsum(np.asarray(dU, dtype=float), axis=0)
        x = [_f(problem.x0).copy()]
        for k in range(1, t.size):
            h = t[k] - t[k - 1]
            x.append(_J(problem, _z(problem, x[-1], h, dU, k), h, t[k]))
        return np.array(x)
    stepper.__name__ = "input_cumulative" if cumulative else "input_per_cell"
    return stepper


def substeps_above_0_1(problem, t_grid):
    """A cell longer than 0.1 is crossed in ⌈h/0.1⌉ equal sub-steps of the scheme ("stability guard"); only the
    node's state is returned."""
    t = _f(t_grid)
    x = [_f(problem.x0).copy()]
    for k in range(1, t.size):
        h = t[k] - t[k - 1]
        m = max(1, int(math.ceil(h / 0.1 - 1e-12)))
        s = np.linspace(t[k - 1], t[k], m + 1) if m > 1 else t[k - 1:k + 1]
        dU = problem.input_increments(s)
        y = x[-1]
        for j in range(1, s.size):
            hj = s[j] - s[j - 1]
            y = _J(problem, _z(problem, y, hj, dU, j), hj, s[j])
        x.append(y)
    return np.array(x)


def x0_projected_first(problem, t_grid):
    """The initial state made "feasible" first: x_0 := J_{1·F(t_0)}(x0), then the scheme from it."""
    t = _f(t_grid)
    dU = problem.input_increments(t)
    x = [_J(problem, _f(problem.x0).copy(), 1.0, t[0])]
    for k in range(1, t.size):
        h = t[k] - t[k - 1]
        x.append(_J(problem, _z(problem, x[-1], h, dU, k), h, t[k]))
    return np.array(x)


def _richardson_factory(weight):
    """Per cell one step of h and two of h/2; returns x_{h/2} + w(x_{h/2} - x_h).  ``w = 1`` (the bug: Richardson
    extrapolation, 2x_{h/2} - x_h, leaves the domain and the scheme); ``w = 0`` with the coarse step the control:
    the same code returning x_h."""
    def stepper(problem, t_grid):
        t = _f(t_grid)
        dU = problem.input_increments(t)
        x = [_f(problem.x0).copy()]
        for k in range(1, t.size):
            h = t[k] - t[k - 1]
            coarse = _J(problem, _z(problem, x[-1], h, dU, k), h, t[k])
            if weight == 0:
                x.append(coarse)
                continue
            s = np.array([t[k - 1], t[k - 1] + h / 2, t[k]])
            dUh = problem.input_increments(s)
            y = x[-1]
            for j in (1, 2):
                hj = s[j] - s[j - 1]
                y = _J(problem, _z(problem, y, hj, dUh, j), hj, s[j])
            x.append(y + weight * (y - coarse))
        return np.array(x)
    stepper.__name__ = "richardson_extrapolated" if weight else "richardson_coarse_only"
    return stepper


def _alias_factory(copy):
    """The predictor built in place, ``z = x[-1]; z += h f(z); z += ∫u``.  Without ``copy`` (the bug) z *is* the
    stored state x_k, so the trajectory returns z_k at node k (the recursion itself is right)."""
    def stepper(problem, t_grid):
        t = _f(t_grid)
        dU = problem.input_increments(t)
        x = [_f(problem.x0).copy()]
        for k in range(1, t.size):
            h = t[k] - t[k - 1]
            z = x[-1].copy() if copy else x[-1]
            z += h * _field(problem, z)
            if dU is not None:
                z += dU[k - 1]
            x.append(_J(problem, z, h, t[k]))
        return np.array(x)
    stepper.__name__ = "inplace_predictor_copied" if copy else "inplace_predictor_aliases_state"
    return stepper


def _input_h_factory(times_h):
    """z = x + h f(x) + ∫u; ``times_h=True`` (the bug) writes z = x + h(f(x) + ∫u), taking the increment for u."""
    def stepper(problem, t_grid):
        t = _f(t_grid)
        dU = problem.input_increments(t)
        x = [_f(problem.x0).copy()]
        for k in range(1, t.size):
            h = t[k] - t[k - 1]
            inc = dU[k - 1] if dU is not None else 0.0
            z = x[-1] + h * (_field(problem, x[-1]) + inc) if times_h else x[-1] + h * _field(problem, x[-1]) + inc
            x.append(_J(problem, z, h, t[k]))
        return np.array(x)
    stepper.__name__ = "input_increment_times_h" if times_h else "input_increment_once"
    return stepper


def _ab_factory(w_now, w_prev):
    """z = x_k + h(w_now f(x_k) + w_prev f(x_{k-1})) (first cell: f(x_0)); (3/2, -1/2) is Adams–Bashforth 2 (the
    bug: not the scheme), (1, 0) the scheme itself through the same code."""
    def stepper(problem, t_grid):
        t = _f(t_grid)
        dU = problem.input_increments(t)
        x = [_f(problem.x0).copy()]
        f_prev = None
        for k in range(1, t.size):
            h = t[k] - t[k - 1]
            f_now = _field(problem, x[-1])
            drift = f_now if f_prev is None else w_now * f_now + w_prev * f_prev
            z = x[-1] + h * drift + (dU[k - 1] if dU is not None else 0.0)
            x.append(_J(problem, z, h, t[k]))
            f_prev = f_now
        return np.array(x)
    stepper.__name__ = "field_adams_bashforth_2" if w_prev else "field_adams_bashforth_1"
    return stepper


def _resume_factory(into_problem):
    """The scheme, remembering its final state "to resume from it": ``into_problem=True`` (the bug) writes it into
    ``problem.x0`` in place, so the caller's problem now starts elsewhere; the control keeps it on the stepper."""
    def stepper(problem, t_grid):
        x = proximal(problem, t_grid)
        if into_problem:
            problem.x0[...] = x[-1]
        else:
            stepper.resume = x[-1].copy()
        return x
    stepper.__name__ = "resume_into_problem_x0" if into_problem else "resume_on_stepper"
    return stepper


# ----------------------------------------------------------------------------------------------------
# the entries
# ----------------------------------------------------------------------------------------------------

ENTRIES: list[Entry] = [
    # operators: plants
    Entry("linear_lambda_clamped_1e3", "operator", f"{RES} v (Y_λx ∈ F(J_λx)) at λ > 10^3", False,
          lambda: _clamped_build(1e3, "Ax, λ clamped to 1e3"), "x = (1, 0), λ = 10^4: J = (I + 10^3 A)^{-1}x",
          "the step clamped to 10^3 before the solve"),
    Entry("quadratic_series_small_lambda", "operator", f"{RES} v (Y_λx ∈ ∂g(J_λx) = {{J_λx}}) at λ < 10^-2", False,
          lambda: _series_build(1e-2, "x/(1+λ), series below 1e-2"),
          "x = (1, 0, 0), λ = 10^-3: Y_λx - J_λx = -10^-6", "x/(1 + λ) as the series 1 - λ + λ² below λ = 10^-2"),
    Entry("ball_knot_table_shifted", "operator", f"{RES} i at F(t,·) (J_λx ∈ cl dom F(t))", False,
          lambda: _knots_build(_KNOTS_SHIFTED, "moving ball, knot table from arange(1, N+1)"),
          "x = (-3, 0), t = 1: J = proj onto B(c(2), 1), 1.47 from c(1)",
          "integer times read the centre from a knot table shifted by one knot"),
    Entry("box_bounds_reshaped_row_major", "operator", f"{RES} i (J_λx ∈ cl dom F = [lo, hi])", False,
          lambda: _bounds_build(True, "box, interleaved bounds reshape(2, n)"),
          "x = (5, 5, 5): J = (0, 1, 2), the box's hi = (-2, 0, 2)",
          "interleaved bounds (lo_0, hi_0, lo_1, ...) read with reshape(2, n) instead of reshape(n, 2).T"),
    Entry("box_returns_shared_buffer", "operator", f"{RES} i/ii (J_λ a function of x)", False,
          lambda: _buffer_build(False, "box, returns its output buffer"),
          "J(2, 0, 0) held, then J(0, 0, 0): the held value becomes (0, 0, 0)",
          "the projection written into a preallocated buffer and the buffer itself returned"),
    Entry("linear_cg_rtol_1e_6", "operator", f"{RES} v (Y_λx = (x - J_λx)/λ ∈ F(J_λx))", False,
          lambda: _cg_build(1e-6, "Sx, CG to rtol 1e-6"),
          "x = (1, 0, 0), λ = 10^-7: one CG step, J off by 10^-7 (Y off by O(1))",
          "the inner conjugate-gradient solve stopped at relative residual 10^-6"),
    Entry("hard_threshold_as_prox", "operator", f"{RES} ii (J_λ firmly nonexpansive; F = ∂g, g convex)", False,
          _hard_build, "x1 = (1.5, 0, 0), x2 = (1.4, 0, 0), λ = 1: |ΔJ| = 1.5 > |Δx| = 0.1",
          "hard thresholding, the prox of the non-convex |x|_0"),
    Entry("firm_threshold_as_prox", "operator", f"{RES} ii (J_λ nonexpansive)", False,
          _firm_build, "x1 = (1.5, 0, 0), x2 = (2, 0, 0), λ = 1: |ΔJ| = 0.75 > |Δx| = 0.5",
          "firm thresholding (the MCP's prox, slope 3/2 in its middle band)"),
    Entry("linear_skew_dropped", "operator", f"{RES} v (Y_λx ∈ F(J_λx) = {{AJ_λx}})", False,
          lambda: _symmetrised_build(True, "Ax, solved with (A + Aᵀ)/2"), "x = (1, 0), λ = 1: J = (0.5, 0), AJ ≠ Y",
          "the resolvent of the symmetric part of A: the skew part dropped"),
    Entry("group_shrink_ragged_group_lost", "operator", f"{RES} i/v (Y_λx ∈ ∂g(J_λx))", False,
          lambda: _group_build(False, "group soft threshold, n // 2 groups"),
          "x = (0, 0, 0, 0, 2), λ = 1: J_4 = 2, not 1",
          "block soft thresholding over pairs; the ragged last group (one coordinate) never thresholded"),
    Entry("soft_simd_tail_step_forgotten", "operator", f"{RES} v (Y_λx ∈ ∂|·|_1(J_λx)) in coordinates 8, 9", False,
          lambda: _simd_build(False, "soft threshold n=10, tail at step 1"),
          "x = 3e_8, λ = 2: J_8 = 2, not 1", "blocks of 8 coordinates at λ, the scalar tail (n > 8) at 1"),
    Entry("huber_prox_for_l1_value", "operator", "prox: p minimises g(z) + |z - x|²/(2λ) (g = |·|_1)", False,
          lambda: _huber_build(0.1, "l1 value, Huber(0.1) prox"),
          "x = (0.05, 0, 0), λ = 1: p = 0.0045, objective 0.0056 > 0.00125 at z = 0",
          "the prox of the Huber smoothing (μ = 0.1) declared as the prox of |·|_1"),
    Entry("box_value_strict_bounds", "operator", "prox: p = prox_λg(x) ∈ dom g, p minimises g + |· - x|²/(2λ)", False,
          lambda: _strict_box_build(True, "box indicator, strict bounds"),
          "x = (2, 0, 0): p = (1, 0, 0), g(p) = +inf", "the indicator's value written with |x_i| < 1: +inf on the faces"),
    Entry("box_odd_lower_face_lost", "operator", f"{RES} i (J_λx ∈ cl dom F = [-1, 1]^4)", False,
          lambda: _odd_build(False, "box, odd coordinates min(·, 1)"),
          "x = (0, -2, 0, 0): J_1 = -2", "odd coordinates clipped from above only"),
    Entry("soft_in_place_when_writeable", "operator", f"{RES} ii (J_λ a function of x; the caller's x unchanged)",
          False, lambda: _in_place_build(False, "soft threshold, in place when writeable"),
          "x = (3, 0, 0), λ = 1: x becomes (2, 0, 0)", "the resolvent computed in place on a writeable float64 input"),
    # steppers: plants
    Entry("internal_grid_interpolated", "stepper", f"{ITER} on the caller's partition", False,
          lambda: (internal_grid_interpolated, None), "F = 0, f(x) = -x, x0 = 1, t = (0, 0.25, ..., 1)",
          "steps on its own uniform grid (cells ≤ 0.01) and interpolates at the caller's nodes"),
    Entry("ring_buffer_filled_once", "stepper", f"{ITER} with ∫u (Section 6, l:extinput) for K > 256", False,
          lambda: (_ring_factory(False), None), "F = 0, u(t) = 2t, K = 300 cells on [0, 1]",
          "a 256-cell buffer of input increments filled once: cell 257 on reuses cells 1, 2, ..."),
    Entry("checkpoint_records_predictor", "stepper", f"{ITER} (x_k = J(z_{{k-1}})) at integer t_k", False,
          lambda: (_checkpoint_factory(False), None), "moving half-space x_1 ≥ t - 1/2, x0 = (-1, 0), t = (0, 0.5, 1)",
          "at integer times the returned state is the predictor z, not J(z)"),
    Entry("field_after_input", "stepper", f"{ITER} (f(x_k))", False,
          lambda: (_field_input_factory(True), None), "F = 0, f(x) = -x, u = 1, x0 = 0, t = (0, 0.5, 1)",
          "f evaluated at x_k + ∫u instead of x_k"),
    Entry("field_frozen_at_x0", "stepper", f"{ITER} (f(x_k))", False,
          lambda: (field_frozen_at_x0, None), "F = 0, f(x) = -x, x0 = 1, t = (0, 0.5, 1)",
          "f evaluated once at x0 and reused on every cell"),
    Entry("input_cumulative", "stepper", f"{ITER} with ∫_{{t_k}}^{{t_{{k+1}}}} u", False,
          lambda: (_cumulative_factory(True), None), "F = 0, u = 1, x0 = 0, t = (0, 0.5, 1)",
          "the input increments summed cumulatively (∫ from t_0)"),
    Entry("substeps_above_0_1", "stepper", f"{ITER} on the caller's partition (one resolvent per cell)", False,
          lambda: (substeps_above_0_1, None), "F = 0, f(x) = -x, x0 = 1, t = (0, 0.5, 1)",
          "cells longer than 0.1 crossed in ⌈h/0.1⌉ sub-steps"),
    Entry("x0_projected_first", "stepper", f"{ITER} (x_0 = x0)", False,
          lambda: (x0_projected_first, None), "moving half-space x_1 ≥ t - 1/2, x0 = (-1, 0): x_0 = (-0.5, 0)",
          "x0 replaced by J_{1·F(t_0)}(x0) before stepping"),
    Entry("richardson_extrapolated", "stepper", f"{ITER} (x_{{k+1}} = J(z_k) ∈ cl dom F(t_{{k+1}}))", False,
          lambda: (_richardson_factory(1.0), None), "F = 0, f(x) = -x, x0 = 1, t = (0, 0.5, 1)",
          "each state extrapolated 2x_{h/2} - x_h from a step of h and two of h/2"),
    Entry("inplace_predictor_aliases_state", "stepper", f"{ITER} (the returned x_k are the states)", False,
          lambda: (_alias_factory(False), None), "F = 0, f(x) = -x, x0 = 1, t = (0, 0.5, 1): x_1 returned as z_1",
          "z = x[-1]; z += h f(z): the stored state overwritten by the predictor"),
    Entry("input_increment_times_h", "stepper", f"{ITER} with ∫u (Section 6)", False,
          lambda: (_input_h_factory(True), None), "F = 0, u = 1, x0 = 0, t = (0, 0.5, 1)",
          "z = x + h(f(x) + ∫u): the increment multiplied by h once more"),
    Entry("field_adams_bashforth_2", "stepper", f"{ITER} (f(x_k) only)", False,
          lambda: (_ab_factory(1.5, -0.5), None), "F = 0, f(x) = -x, x0 = 1, t = (0, 0.5, 1, 1.5)",
          "the drift stepped with Adams–Bashforth 2 (3/2 f(x_k) - 1/2 f(x_{k-1}))"),
    Entry("resume_into_problem_x0", "stepper", f"{ITER} (x_0 = x0 of the caller's problem, unchanged)", False,
          lambda: (_resume_factory(True), None), "F = 0, f(x) = -x, x0 = 1: a second call starts at x_K",
          "the final state written into problem.x0 in place"),
    # controls
    Entry("ctrl_linear_lambda_unclamped", "operator", f"{RES} v", True,
          lambda: _clamped_build(np.inf, "Ax, λ unclamped"), "-", "no clamp", twin="linear_lambda_clamped_1e3"),
    Entry("ctrl_quadratic_series_1e_6", "operator", f"{RES} v", True,
          lambda: _series_build(1e-6, "x/(1+λ), series below 1e-6"), "-",
          "the series only where λ³ is below an ulp", twin="quadratic_series_small_lambda"),
    Entry("ctrl_ball_knot_table", "operator", f"{RES} i at F(t,·)", True,
          lambda: _knots_build(_KNOTS_OK, "moving ball, knot table from arange(0, N+1)"), "-",
          "the table built from arange(0, N + 1)", twin="ball_knot_table_shifted"),
    Entry("ctrl_box_bounds_reshaped", "operator", f"{RES} i", True,
          lambda: _bounds_build(False, "box, interleaved bounds reshape(n, 2).T"), "-", "reshape(n, 2).T",
          twin="box_bounds_reshaped_row_major"),
    Entry("ctrl_box_buffer_copied", "operator", f"{RES} i/ii", True,
          lambda: _buffer_build(True, "box, output buffer copied"), "-", "returns a copy of the buffer",
          twin="box_returns_shared_buffer"),
    Entry("ctrl_linear_direct_solve", "operator", f"{RES} v", True,
          lambda: _cg_build(0.0, "Sx, direct solve"), "-", "np.linalg.solve", twin="linear_cg_rtol_1e_6"),
    Entry("ctrl_linear_skew_kept", "operator", f"{RES} v", True,
          lambda: _symmetrised_build(False, "Ax, solved with A"), "-", "I + λA itself", twin="linear_skew_dropped"),
    Entry("ctrl_group_shrink_all_groups", "operator", f"{RES} i/v", True,
          lambda: _group_build(True, "group soft threshold, (n + 1) // 2 groups"), "-", "every group thresholded",
          twin="group_shrink_ragged_group_lost"),
    Entry("ctrl_soft_simd_tail_step", "operator", f"{RES} v", True,
          lambda: _simd_build(True, "soft threshold n=10, tail at step λ"), "-", "the tail at λ",
          twin="soft_simd_tail_step_forgotten"),
    Entry("ctrl_soft_prox_for_l1_value", "operator", "prox minimiser", True,
          lambda: _huber_build(0.0, "l1 value, Huber(0) = soft prox"), "-", "μ = 0: soft thresholding",
          twin="huber_prox_for_l1_value"),
    Entry("ctrl_box_value_closed", "operator", "prox minimiser", True,
          lambda: _strict_box_build(False, "box indicator, closed bounds"), "-", "|x_i| ≤ 1",
          twin="box_value_strict_bounds"),
    Entry("ctrl_box_odd_clipped", "operator", f"{RES} i", True,
          lambda: _odd_build(True, "box, odd coordinates clipped"), "-", "np.clip on both parities",
          twin="box_odd_lower_face_lost"),
    Entry("ctrl_soft_copy_when_writeable", "operator", f"{RES} ii", True,
          lambda: _in_place_build(True, "soft threshold, on a copy"), "-", "out = x.copy()",
          twin="soft_in_place_when_writeable"),
    Entry("ctrl_resume_on_stepper", "stepper", ITER, True, lambda: (_resume_factory(False), None), "-",
          "the final state kept on the stepper", twin="resume_into_problem_x0"),
    Entry("ctrl_ring_buffer_refilled", "stepper", ITER, True, lambda: (_ring_factory(True), None), "-",
          "the buffer refilled every 256 cells", twin="ring_buffer_filled_once"),
    Entry("ctrl_checkpoint_records_state", "stepper", ITER, True, lambda: (_checkpoint_factory(True), None), "-",
          "the state J(z) recorded", twin="checkpoint_records_predictor"),
    Entry("ctrl_field_before_input", "stepper", ITER, True, lambda: (_field_input_factory(False), None), "-",
          "f at x_k", twin="field_after_input"),
    Entry("ctrl_input_per_cell", "stepper", ITER, True, lambda: (_cumulative_factory(False), None), "-",
          "the increments per cell", twin="input_cumulative"),
    Entry("ctrl_richardson_coarse_only", "stepper", ITER, True, lambda: (_richardson_factory(0.0), None), "-",
          "weight 0: the coarse step", twin="richardson_extrapolated"),
    Entry("ctrl_inplace_predictor_copied", "stepper", ITER, True, lambda: (_alias_factory(True), None), "-",
          "z = x[-1].copy()", twin="inplace_predictor_aliases_state"),
    Entry("ctrl_input_increment_once", "stepper", ITER, True, lambda: (_input_h_factory(False), None), "-",
          "z = x + h f(x) + ∫u", twin="input_increment_times_h"),
    Entry("ctrl_field_adams_bashforth_1", "stepper", ITER, True, lambda: (_ab_factory(1.0, 0.0), None), "-",
          "weights (1, 0)", twin="field_adams_bashforth_2"),
]


# ----------------------------------------------------------------------------------------------------
# witnesses: each entry's law evaluated at its smallest input in plain NumPy (verimono only builds the subject)
# ----------------------------------------------------------------------------------------------------

EQ = 1e-9      # relative slack of an equality (round-off is ~1e-15)


def _eq(a, b, scale=1.0):
    a, b = _f(a), _f(b)
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        return np.inf
    return float(np.max(np.abs(a - b), initial=0.0)) / (EQ * (1.0 + abs(scale)))


def _outside(p, lo, hi):
    """The box's membership of a resolvent value, as a ratio: its largest excursion over EQ."""
    p = _f(p)
    return float(max(np.max(p - hi), np.max(lo - p), 0.0)) / EQ


def _firm_ratio(J, x1, x2, lam):
    """|ΔJ|² / <ΔJ, Δx> (≤ 1: firmly nonexpansive)."""
    d, dj = x1 - x2, _f(J(x1, lam)) - _f(J(x2, lam))
    num = float(dj @ dj)
    den = float(dj @ d)
    return num / den if den > 0 else (np.inf if num > 0 else 0.0)


def _op_witness(name):
    e = BY_NAME[name]
    case = e.twin if e.lawful else name
    build = e.build
    if case == "linear_lambda_clamped_1e3":
        x, lam = np.array([1.0, 0.0]), 1e4
        return lambda: _eq(build().resolvent(x, lam), np.linalg.solve(np.eye(2) + lam * _A_ROT, x))
    if case == "quadratic_series_small_lambda":
        def w():
            x, lam = np.array([1.0, 0.0, 0.0]), 1e-3
            j = build().resolvent(x, lam)
            return _eq((x - j) / lam, j)          # Y_λx = J_λx; Y's own round-off is eps/λ ≈ 2e-13
        return w
    if case == "ball_knot_table_shifted":
        def w():
            j = build().resolvent(np.array([-3.0, 0.0]), 1.0, 1.0)
            return max(0.0, float(np.linalg.norm(j - _centre(1.0))) - 1.0) / EQ
        return w
    if case == "box_bounds_reshaped_row_major":
        return lambda: _outside(build().resolvent(np.array([5.0, 5.0, 5.0]), 1.0), _LO, _HI)
    if case == "box_returns_shared_buffer":
        def w():
            op = build()
            j1 = op.resolvent(np.array([2.0, 0.0, 0.0]), 1.0)
            op.resolvent(np.zeros(3), 1.0)
            return _eq(j1, [1.0, 0.0, 0.0])
        return w
    if case == "linear_cg_rtol_1e_6":
        x, lam = np.array([1.0, 0.0, 0.0]), 1e-7
        return lambda: _eq(build().resolvent(x, lam), np.linalg.solve(np.eye(3) + lam * _S_SPD, x))
    if case == "hard_threshold_as_prox":
        return lambda: _firm_ratio(build().resolvent, np.array([1.5, 0, 0.0]), np.array([1.4, 0, 0.0]), 1.0)
    if case == "firm_threshold_as_prox":
        return lambda: _firm_ratio(build().resolvent, np.array([1.5, 0, 0.0]), np.array([2.0, 0, 0.0]), 1.0)
    if case == "linear_skew_dropped":
        def w():
            x, lam = np.array([1.0, 0.0]), 1.0
            j = build().resolvent(x, lam)
            return _eq((x - j) / lam, _A_SK @ j, 3.0)
        return w
    if case == "group_shrink_ragged_group_lost":
        return lambda: _eq(build().resolvent(np.array([0, 0, 0, 0, 2.0]), 1.0), [0, 0, 0, 0, 1.0], 2.0)
    if case == "soft_simd_tail_step_forgotten":
        def w():
            x = np.zeros(10)
            x[8] = 3.0
            return _eq(build().resolvent(x, 2.0), _soft(x, 2.0), 3.0)
        return w
    if case == "huber_prox_for_l1_value":
        def w():
            op, x, lam = build(), np.array([0.05, 0.0, 0.0]), 1.0
            p = op.resolvent(x, lam)
            obj = lambda v: op.value(v) + float((v - x) @ (v - x)) / (2 * lam)
            best = min(obj(np.zeros(3)), obj(_soft(x, lam)))      # the l1 prox is soft thresholding
            return max(0.0, obj(p) - best) / EQ
        return w
    if case == "box_value_strict_bounds":
        def w():
            op = build()
            p = op.resolvent(np.array([2.0, 0.0, 0.0]), 1.0)
            return 1.0 if np.isfinite(op.value(p)) else 2.0          # p ∈ dom g: accepted ≤ 1, refused > 1
        return w
    if case == "box_odd_lower_face_lost":
        return lambda: _outside(build().resolvent(np.array([0.0, -2.0, 0.0, 0.0]), 1.0), -np.ones(4), np.ones(4))
    if case == "soft_in_place_when_writeable":
        def w():
            x = np.array([3.0, 0.0, 0.0])
            build().resolvent(x, 1.0)
            return _eq(x, [3.0, 0.0, 0.0], 3.0)
        return w
    raise KeyError(name)


class _HalfSpace:
    """N of the moving half-space {x_1 ≥ t - 1/2} in R^n: J = the projection, at any step."""
    def resolvent(self, z, lam, t=0.0):
        z = _f(z).copy()
        z[0] = max(z[0], t - 0.5)
        return z


class _Zero:
    def resolvent(self, z, lam, t=0.0):
        return _f(z).copy()


class _P:
    """A duck-typed problem: what the steppers read (operator, x0, f, input_increments, T)."""
    def __init__(self, operator, x0, T=1.0, f=None, U=None):
        self.operator, self.x0, self.T, self.f, self._U = operator, _f(x0), T, f, U
        self.dim = self.x0.size

    def input_increments(self, t):
        if self._U is None:
            return None
        t = _f(t)
        return np.array([self._U(b) - self._U(a) for a, b in zip(t[:-1], t[1:])])


def _decay():
    return _P(_Zero(), [1.0], f=lambda x: -x)


def _unit_input():
    return _P(_Zero(), [0.0], U=lambda t: np.array([t]))


_STEP_CASES = {
    "internal_grid_interpolated": (_decay, np.linspace(0, 1, 5)),
    "ring_buffer_filled_once": (lambda: _P(_Zero(), [0.0], U=lambda t: np.array([t * t])), np.linspace(0, 1, 301)),
    "checkpoint_records_predictor": (lambda: _P(_HalfSpace(), [-1.0, 0.0]), np.array([0.0, 0.5, 1.0])),
    "field_after_input": (lambda: _P(_Zero(), [0.0], f=lambda x: -x, U=lambda t: np.array([t])),
                          np.array([0.0, 0.5, 1.0])),
    "field_frozen_at_x0": (_decay, np.array([0.0, 0.5, 1.0])),
    "input_cumulative": (_unit_input, np.array([0.0, 0.5, 1.0])),
    "substeps_above_0_1": (_decay, np.array([0.0, 0.5, 1.0])),
    "x0_projected_first": (lambda: _P(_HalfSpace(), [-1.0, 0.0]), np.array([0.0, 0.5, 1.0])),
    "richardson_extrapolated": (_decay, np.array([0.0, 0.5, 1.0])),
    "inplace_predictor_aliases_state": (_decay, np.array([0.0, 0.5, 1.0])),
    "input_increment_times_h": (_unit_input, np.array([0.0, 0.5, 1.0])),
    "field_adams_bashforth_2": (_decay, np.array([0.0, 0.5, 1.0, 1.5])),
}


def _step_witness(name):
    """The stepper's states against the scheme's (``proximal``) at the smallest input; a control runs its plant's case."""
    e = BY_NAME[name]
    if (e.twin if e.lawful else name) == "resume_into_problem_x0":
        def w2():
            stepper, problem, grid = e.build()[0], _decay(), np.array([0.0, 0.5, 1.0])
            first = stepper(problem, grid)
            return _eq(stepper(problem, grid), first)          # the same problem, the same trajectory
        return w2
    make, grid = _STEP_CASES[e.twin if e.lawful else name]

    def w():
        stepper = e.build()[0]
        got = stepper(make(), np.array(grid, dtype=float))
        want = proximal(make(), np.array(grid, dtype=float))
        return _eq(got, want, float(np.max(np.abs(want))))
    return w


BY_NAME = {e.name: e for e in ENTRIES}
ENTRIES = [dataclasses.replace(e, witness=(_op_witness(e.name) if e.kind == "operator" else _step_witness(e.name)))
           for e in ENTRIES]
BY_NAME = {e.name: e for e in ENTRIES}
