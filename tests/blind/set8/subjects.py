"""Blind set 8: planted violations of the paper's laws, and lawful controls, of kinds new against sets 1 and 7.

Written without reading ``verimono/checks/``: from the paper, README.md, the list of laws in docs/checks.md and
docs/paper.md, and the public API (``vm.operator_from_resolvent``, ``vm.operator_from_prox``, a stepper
``stepper(problem, t_grid)``).  Of the earlier blind sets only the names of their kinds were read.

Each :class:`Entry` has ``build()`` (the subject as a user hands it to ``vm.check_operator`` /
``vm.check_stepper``), the law of the paper it breaks (``label``), the smallest input showing it
(``smallest``), what the bug is (``bug``) and, for a control, the plant it is the lawful twin of (``twin``): the
same code with the faulty branch's arithmetic made right, so a check failing both is a false alarm.  Every
plant's bug is the kind a user writes into a real resolvent or stepper: a tie in a sort, a reciprocal that
overflows, a cache with the wrong key, a batch returned in another order, an unrolled loop's remainder, ...
"""

from __future__ import annotations

import dataclasses
from typing import Any, Callable

import numpy as np

import verimono as vm

RES = "prop:maxmon-resolvent-Yosida"


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


def _tol(*arrays, tol=None):
    if tol is not None:
        return float(tol)
    s = 1.0 + max((float(np.max(np.abs(a), initial=0.0)) for a in arrays), default=0.0)
    return 1e-9 * s


def _f(x):
    return np.asarray(x, dtype=float)


# ----------------------------------------------------------------------------------------------------
# sets: projections and declared normal cones (contains)
# ----------------------------------------------------------------------------------------------------

def proj_l1_ball(x, r=1.0, unique=False):
    """Projection onto {|x|_1 <= r} (Duchi et al.): sort |x| decreasing, the threshold θ from the cumulative sums.
    ``unique=True``: the sort goes through ``np.unique``, which drops tied magnitudes (the bug)."""
    x = _f(x)
    a = np.abs(x)
    if a.sum() <= r:
        return x.copy()
    u = np.unique(a)[::-1] if unique else np.sort(a)[::-1]
    css = np.cumsum(u)
    j = np.arange(1, u.size + 1)
    idx = np.nonzero(u - (css - r) / j > 0)[0]
    rho = idx[-1] if idx.size else 0       # j = 1 always qualifies (u_1 - (u_1 - r) = r); rounding can hide it
    theta = (css[rho] - r) / (rho + 1.0)
    return np.sign(x) * np.maximum(a - theta, 0.0)


def l1_ball_contains(x, y, t=0.0, tol=None):
    """y ∈ N_{|·|_1 ≤ 1}(x): x in the ball; inside y = 0; on the sphere y = μ s, s ∈ ∂|x|_1, μ ≥ 0."""
    x, y = _f(x), _f(y)
    tol = _tol(x, y, tol=tol)
    s = np.abs(x).sum()
    if s > 1.0 + tol:
        return False
    if s < 1.0 - tol:
        return bool(np.max(np.abs(y), initial=0.0) <= tol)
    mu = float(np.max(np.abs(y), initial=0.0))
    nz = np.abs(x) > tol
    return bool(np.all(np.abs(y[nz] - mu * np.sign(x[nz])) <= tol) and np.all(np.abs(y[~nz]) <= mu + tol))


def proj_ball(x, r=1.0):
    x = _f(x)
    n = np.linalg.norm(x)
    return x.copy() if n <= r else x * (r / n)


def ball_contains(x, y, t=0.0, tol=None, signed=True):
    """y ∈ N_B(x), B the unit ball: inside y = 0; on the sphere y = μx, μ ≥ 0.  ``signed=False`` (the bug) tests only
    that y is parallel to x: an inward normal is accepted too, a graph that is not monotone."""
    x, y = _f(x), _f(y)
    tol = _tol(x, y, tol=tol)
    nx, ny = np.linalg.norm(x), np.linalg.norm(y)
    if nx > 1.0 + tol:
        return False
    if nx < 1.0 - tol:
        return bool(ny <= tol)
    d = float(y @ x)
    if not signed:
        d = abs(d)
    return bool(abs(d - ny * nx) <= tol * (1.0 + ny))


def box_contains(x, y, t=0.0, tol=None, lo=-1.0, hi=1.0, mode="coordinates"):
    """y ∈ N_[lo,hi]^n(x).  ``mode="coordinates"``: each coordinate at its own face (lawful); ``"one face"``: only the
    first active coordinate may carry a normal (a corner's cone lost); ``"interior"``: y = 0 only (a monotone graph
    that is not maximal: the faces' normals missing)."""
    x, y = _f(x), _f(y)
    tol = _tol(x, y, tol=tol)
    if np.any(x > hi + tol) or np.any(x < lo - tol):
        return False
    up, down = x >= hi - tol, x <= lo + tol
    if mode == "interior":
        return bool(np.max(np.abs(y), initial=0.0) <= tol)
    if mode == "one face":
        active = np.nonzero(up | down)[0]
        free = np.ones(x.size, bool)
        if active.size:
            i = active[0]
            free[i] = False
            ok = y[i] >= -tol if up[i] else y[i] <= tol
            if not ok:
                return False
        return bool(np.all(np.abs(y[free]) <= tol))
    # a coordinate within tol of both faces (a large tol) may take either face's normal: "or", not "and"
    ok = (up & (y >= -tol)) | (down & (y <= tol)) | (np.abs(y) <= tol)
    return bool(np.all(ok))


# ----------------------------------------------------------------------------------------------------
# operators
# ----------------------------------------------------------------------------------------------------

def _l1_ball_build(unique, name):
    def J(x, lam, t=0.0):
        return proj_l1_ball(x, unique=unique)
    return vm.operator_from_resolvent(J, 3, name=name, contains=l1_ball_contains,
                                      project_domain=lambda x, t=0.0: proj_l1_ball(x))


def _ball_rescale_build(reciprocal, name):
    """Projection onto the unit ball of R^3, written to avoid overflow in |x|: scale by s = max|x_i| first.
    ``reciprocal=True`` multiplies by 1/s, which is +inf when s < 2^-1024 (an all-subnormal x): NaN out."""
    def J(x, lam, t=0.0):
        x = _f(x)
        s = float(np.max(np.abs(x), initial=0.0))
        if s == 0.0:
            return x.copy()
        y = x * (1.0 / s) if reciprocal else x / s
        ny = float(np.linalg.norm(y))
        if s * ny <= 1.0:
            return x.copy()
        return y / ny
    return vm.operator_from_resolvent(J, 3, name=name, contains=ball_contains,
                                      project_domain=lambda x, t=0.0: proj_ball(x))


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


def _soft_cache_build(rounded, name):
    """Soft thresholding (the resolvent of ∂|x|_1) behind a memo.  ``rounded=True`` keys it by x rounded to 6
    decimals: a point within 5e-7 of one seen before gets that one's value."""
    cache: dict = {}

    def J(x, lam, t=0.0):
        x = _f(x)
        key = ((np.round(x, 6) if rounded else x).tobytes(), float(lam), float(t))
        hit = cache.get(key)
        if hit is None:
            if len(cache) > 4096:
                cache.clear()
            hit = cache[key] = _soft(x, lam)
        return hit.copy()
    return vm.operator_from_resolvent(J, 3, name=name, contains=l1_contains, min_norm=l1_min_norm)


def _A_t(t):
    return np.array([[1.0 + t, 2.0], [-2.0, 1.0]])


def _linear_td_build(key_t, name):
    """F(t, x) = A(t)x, A(t) = [[1 + t, 2], [-2, 1]] (monotone for t ≥ -1), the inverse of I + λA(t) cached.
    ``key_t=False`` (the bug) keys the cache by λ alone: a repeated λ at a new t reuses the stale time's matrix."""
    state: dict = {}

    def J(x, lam, t=0.0):
        key = (float(lam), float(t)) if key_t else float(lam)
        if state.get("key") != key:
            state["key"] = key
            state["inv"] = np.linalg.inv(np.eye(2) + float(lam) * _A_t(float(t)))
        return state["inv"] @ _f(x)

    def contains(x, y, t=0.0, tol=None):
        x, y = _f(x), _f(y)
        r = y - _A_t(t) @ x
        return bool(np.max(np.abs(r)) <= _tol(x, y, tol=tol) * 4)
    return vm.operator_from_resolvent(J, 2, name=name, contains=contains,
                                      min_norm=lambda x, t=0.0: _A_t(t) @ _f(x))


def _box_build(mode, name):
    return vm.operator_from_resolvent(lambda x, lam, t=0.0: np.clip(_f(x), -1.0, 1.0), 3, name=name,
                                      contains=lambda x, y, t=0.0, tol=None: box_contains(x, y, t, tol, mode=mode),
                                      project_domain=lambda x, t=0.0: np.clip(_f(x), -1.0, 1.0))


_A_SHIFT = np.array([2.0, 0.5, -3.0])


def _box_shift_build(faces, name):
    """F(x) = (x - a) + N_[-1,1]^3(x), a = (2, 0.5, -3): J_λx = clip((x + λa)/(1 + λ)).  Its minimal section is
    x - a off the faces and, on a face, the least element of a half-line: max(x_i - a_i, 0) at x_i = 1,
    min(x_i - a_i, 0) at x_i = -1.  ``faces=False`` (the bug) returns x - a everywhere."""
    a = _A_SHIFT

    def J(x, lam, t=0.0):
        return np.clip((_f(x) + lam * a) / (1.0 + lam), -1.0, 1.0)

    def min_norm(x, t=0.0):
        x = _f(x)
        if np.any(np.abs(x) > 1.0 + 1e-12):
            raise vm.OutsideDomain(f"{x} is outside [-1, 1]^3")
        v = x - a
        if faces:
            v = np.where(x >= 1.0, np.maximum(v, 0.0), np.where(x <= -1.0, np.minimum(v, 0.0), v))
        return v

    def contains(x, y, t=0.0, tol=None):
        x, y = _f(x), _f(y)
        return box_contains(x, y - (x - a), t, _tol(x, y, tol=tol))
    return vm.operator_from_resolvent(J, 3, name=name, min_norm=min_norm, contains=contains,
                                      project_domain=lambda x, t=0.0: np.clip(_f(x), -1.0, 1.0))


def _batch_order_build(restore, name):
    """A batched soft thresholding (rows (B, n), steps and times (B,)) that groups the rows by step through a stable
    argsort.  ``restore=False`` (the bug) returns the rows in the sorted order: right whenever a batch has one step."""
    def J(X, lams, ts):
        X, lams = _f(X), _f(lams)
        order = np.argsort(lams, kind="stable")
        out_sorted = _soft(X[order], lams[order][:, None])
        if not restore:
            return out_sorted
        out = np.empty_like(out_sorted)
        out[order] = out_sorted
        return out
    return vm.operator_from_resolvent(J, 3, name=name, contains=l1_contains, min_norm=l1_min_norm, batched=True)


_A_SKEW = np.array([[1.0, 3.0], [-3.0, 1.0]])


def _integer_lambda_build(power, name):
    """F(x) = Ax, A = [[1, 3], [-3, 1]].  ``power=True`` (the bug): for an integer λ = k ≤ 64 the resolvent is the
    k-th power of J_1 (a semigroup property the resolvents do not have: J_1^k ≠ J_k for A ≠ 0)."""
    def J(x, lam, t=0.0):
        x = _f(x)
        lam = float(lam)
        if power and lam.is_integer() and 1.0 < lam <= 64.0:
            z = x
            M = np.eye(2) + _A_SKEW
            for _ in range(int(lam)):
                z = np.linalg.solve(M, z)
            return z
        return np.linalg.solve(np.eye(2) + lam * _A_SKEW, x)

    def contains(x, y, t=0.0, tol=None):
        x, y = _f(x), _f(y)
        return bool(np.max(np.abs(y - _A_SKEW @ x)) <= 4 * _tol(x, y, tol=tol))
    return vm.operator_from_resolvent(J, 2, name=name, contains=contains, min_norm=lambda x, t=0.0: _A_SKEW @ _f(x))


_C_LIN = np.array([1.0, -2.0, 0.5])


def _box_value_build(indicator, name):
    """g(x) = <c, x> + ι_[-1,1]^3(x): prox_{λg}(x) = clip(x - λc).  ``indicator=False`` (the bug): the value forgets
    the indicator, so outside the box g is finite and the prox is not the minimiser of g + |· - x|²/(2λ)."""
    def prox(x, lam):
        return np.clip(_f(x) - lam * _C_LIN, -1.0, 1.0)

    def value(x):
        x = _f(x)
        if indicator and np.any(np.abs(x) > 1.0):
            return np.inf
        return float(_C_LIN @ x)
    return vm.operator_from_prox(prox, value=value, shape=3, name=name)


_A_HS, _B_HS = np.array([3.0, 4.0]), 1.0


def _halfspace_build(normalised, name):
    """N_H, H = {3x_1 + 4x_2 ≤ 1}.  ``contains`` writes y = μa with μ = <y, a>/|a|²; ``normalised=False`` (the bug)
    forgets the |a|² = 25, so only normals with μ = 1 are accepted."""
    a, b = _A_HS, _B_HS

    def proj(x, t=0.0):
        x = _f(x)
        return x - max(0.0, float(a @ x) - b) / float(a @ a) * a

    def contains(x, y, t=0.0, tol=None):
        x, y = _f(x), _f(y)
        tol = _tol(x, y, tol=tol)
        g = float(a @ x) - b
        if g > tol * 5:
            return False
        if g < -tol * 5:
            return bool(np.max(np.abs(y)) <= tol)
        mu = float(y @ a) / (float(a @ a) if normalised else 1.0)
        return bool(mu >= -tol and np.max(np.abs(y - mu * a)) <= tol)
    return vm.operator_from_resolvent(lambda x, lam, t=0.0: proj(x), 2, name=name, contains=contains,
                                      project_domain=proj)


def proj_simplex(x, off_by_one=False):
    """Projection onto {x ≥ 0, Σx = 1}: θ = (Σ_{j≤ρ} u_j - 1)/ρ; ``off_by_one`` divides by ρ + 1 (0- vs 1-based ρ)."""
    x = _f(x)
    u = np.sort(x)[::-1]
    css = np.cumsum(u)
    j = np.arange(1, x.size + 1)
    idx = np.nonzero(u - (css - 1.0) / j > 0)[0]
    rho = (idx[-1] if idx.size else 0) + 1        # 1-based; j = 1 always qualifies, rounding can hide it
    theta = (css[rho - 1] - 1.0) / (rho + 1.0 if off_by_one else rho)
    return np.maximum(x - theta, 0.0)


def simplex_contains(x, y, t=0.0, tol=None):
    """y ∈ N_Δ(x): x ∈ Δ, y = μ1 + ν with ν ≤ 0, ν_i = 0 where x_i > 0."""
    x, y = _f(x), _f(y)
    tol = _tol(x, y, tol=tol)
    if np.any(x < -tol) or abs(x.sum() - 1.0) > tol * x.size:
        return False
    pos = x > tol
    mu = float(np.max(y[pos])) if pos.any() else float(np.max(y))
    return bool(np.all(np.abs(y[pos] - mu) <= tol) and np.all(y[~pos] <= mu + tol))


def _simplex_build(off_by_one, name):
    return vm.operator_from_resolvent(lambda x, lam, t=0.0: proj_simplex(x, off_by_one), 3, name=name,
                                      contains=simplex_contains, project_domain=lambda x, t=0.0: proj_simplex(x))


_A_DC = np.array([[2.0, 1.0], [-1.0, 2.0]])


def _downcast_build(dtype, name):
    """F(x) = Ax, A = [[2, 1], [-1, 2]]; for max|x| > 1e4 the solve is done "for speed" in ``dtype`` and cast back:
    float32 (the bug) loses 7 digits of a float64 subject's resolvent; float64 (the control) is the same branch."""
    def J(x, lam, t=0.0):
        x = _f(x)
        M = np.eye(2) + float(lam) * _A_DC
        if np.max(np.abs(x), initial=0.0) > 1e4:
            return np.linalg.solve(M.astype(dtype), x.astype(dtype)).astype(np.float64)
        return np.linalg.solve(M, x)

    def contains(x, y, t=0.0, tol=None):
        x, y = _f(x), _f(y)
        return bool(np.max(np.abs(y - _A_DC @ x)) <= 4 * _tol(x, y, tol=tol))
    return vm.operator_from_resolvent(J, 2, name=name, contains=contains, min_norm=lambda x, t=0.0: _A_DC @ _f(x))


def _ball_signless_build():
    return vm.operator_from_resolvent(lambda x, lam, t=0.0: proj_ball(x), 3, name="ball contains |<y, x>|",
                                      contains=lambda x, y, t=0.0, tol=None: ball_contains(x, y, t, tol, signed=False),
                                      project_domain=lambda x, t=0.0: proj_ball(x))


# ----------------------------------------------------------------------------------------------------
# steppers: the paper's scheme x_{k+1} = J_{h F(t_{k+1})}(x_k + h f(x_k) + ∫u) and its planted variants
# ----------------------------------------------------------------------------------------------------

def _z(problem, x, h, dU, k):
    z = x + (h * _f(problem.f(x)) if problem.f is not None else 0.0)
    if dU is not None:
        z = z + dU[k - 1]
    return z


def _incr(problem, t):
    return problem.input_increments(t)


def proximal(problem, t_grid):
    t = _f(t_grid)
    dU = _incr(problem, t)
    x = [_f(problem.x0).copy()]
    for k in range(1, t.size):
        h = t[k] - t[k - 1]
        x.append(_f(problem.operator.resolvent(_z(problem, x[-1], h, dU, k), h, t[k])))
    return np.array(x)


def _merge_factory(ratio):
    """Cells shorter than ``ratio`` times the previous one are merged with the next (one step across both, the
    skipped node filled by linear interpolation) — a common guard against tiny steps.  ratio 0: never merged."""
    def stepper(problem, t_grid):
        t = _f(t_grid)
        dU = _incr(problem, t)
        K = t.size - 1
        x = [None] * (K + 1)
        x[0] = _f(problem.x0).copy()
        k = 1
        while k <= K:
            h = t[k] - t[k - 1]
            if 2 <= k < K and h < ratio * (t[k - 1] - t[k - 2]):
                H = t[k + 1] - t[k - 1]
                z = x[k - 1] + (H * _f(problem.f(x[k - 1])) if problem.f is not None else 0.0)
                if dU is not None:
                    z = z + dU[k - 1] + dU[k]
                x[k + 1] = _f(problem.operator.resolvent(z, H, t[k + 1]))
                w = h / H
                x[k] = (1 - w) * x[k - 1] + w * x[k + 1]
                k += 2
                continue
            x[k] = _f(problem.operator.resolvent(_z(problem, x[k - 1], h, dU, k), h, t[k]))
            k += 1
        return np.array(x)
    stepper.__name__ = f"merge_short_cells_{ratio:g}"
    return stepper


def _grid_round_factory(in_place):
    """Times "cleaned" to 14 decimals first: ``in_place=True`` (the bug) writes the rounding into the caller's grid."""
    def stepper(problem, t_grid):
        if in_place:
            np.round(t_grid, 14, out=t_grid)
            t = t_grid
        else:
            t = np.round(_f(t_grid), 14)
        return proximal(problem, t)
    stepper.__name__ = "rounds_grid_in_place" if in_place else "rounds_grid_copy"
    return stepper


def input_reversed_n_ge_5(problem, t_grid):
    """A "vectorised" path for n ≥ 5 that takes the input increments with the coordinates reversed."""
    t = _f(t_grid)
    dU = _incr(problem, t)
    if dU is not None and np.ndim(problem.x0) == 1 and np.size(problem.x0) >= 5:
        dU = np.asarray(dU)[:, ::-1]
    x = [_f(problem.x0).copy()]
    for k in range(1, t.size):
        h = t[k] - t[k - 1]
        x.append(_f(problem.operator.resolvent(_z(problem, x[-1], h, dU, k), h, t[k])))
    return np.array(x)


def safety_clip_3(problem, t_grid):
    """The scheme with a "safety" clip of every state to [-3, 3]^n."""
    return np.clip(proximal(problem, t_grid), -3.0, 3.0)


def _relaxed_factory(omega):
    """x_{k+1} = x_k + ω(J(z_k) - x_k): ω = 1.02 over-relaxes (the bug), ω = 1 is the scheme."""
    def stepper(problem, t_grid):
        t = _f(t_grid)
        dU = _incr(problem, t)
        x = [_f(problem.x0).copy()]
        for k in range(1, t.size):
            h = t[k] - t[k - 1]
            p = _f(problem.operator.resolvent(_z(problem, x[-1], h, dU, k), h, t[k]))
            x.append(x[-1] + omega * (p - x[-1]))
        return np.array(x)
    stepper.__name__ = f"relaxed_{omega:g}"
    return stepper


def _memo_factory(full_key):
    """The resolvent memoised within one run (repeated z at rest); ``full_key=False`` (the bug) keys it by z alone,
    so a point at rest keeps the value of an earlier (h, t)."""
    def stepper(problem, t_grid):
        t = _f(t_grid)
        dU = _incr(problem, t)
        x = [_f(problem.x0).copy()]
        memo: dict = {}
        for k in range(1, t.size):
            h = t[k] - t[k - 1]
            z = _z(problem, x[-1], h, dU, k)
            key = (z.tobytes(), float(h), float(t[k])) if full_key else z.tobytes()
            if key not in memo:
                memo.clear()
                memo[key] = _f(problem.operator.resolvent(z, h, t[k]))
            x.append(memo[key].copy())
        return np.array(x)
    stepper.__name__ = "memo_z_h_t" if full_key else "memo_z_only"
    return stepper


def _unrolled_factory(project_remainder):
    """The loop unrolled by two cells; an odd number of cells leaves one, which the bug steps without the resolvent."""
    def stepper(problem, t_grid):
        t = _f(t_grid)
        dU = _incr(problem, t)
        K = t.size - 1
        x = [_f(problem.x0).copy()]
        k = 1
        while k + 1 <= K:
            for kk in (k, k + 1):
                h = t[kk] - t[kk - 1]
                x.append(_f(problem.operator.resolvent(_z(problem, x[-1], h, dU, kk), h, t[kk])))
            k += 2
        if k == K:
            h = t[K] - t[K - 1]
            z = _z(problem, x[-1], h, dU, K)
            x.append(_f(problem.operator.resolvent(z, h, t[K])) if project_remainder else z)
        return np.array(x)
    stepper.__name__ = "unrolled_remainder_projected" if project_remainder else "unrolled_remainder_unprojected"
    return stepper


def normalised_time(problem, t_grid):
    """The operator taken at t/T (a scheme written for T = 1)."""
    t = _f(t_grid)
    dU = _incr(problem, t)
    x = [_f(problem.x0).copy()]
    for k in range(1, t.size):
        h = t[k] - t[k - 1]
        x.append(_f(problem.operator.resolvent(_z(problem, x[-1], h, dU, k), h, t[k] / t[-1])))
    return np.array(x)


def memo_installed_on_operator(problem, t_grid):
    """Installs a memo of the resolvent on the problem's operator object (keyed by z rounded to 4 decimals) "for
    speed": it changes the operator the caller holds and returns values of nearby points."""
    op = problem.operator
    if not getattr(op, "_blind8_memo", False):
        orig = op.resolvent
        cache: dict = {}

        def memo(z, lam, t=0.0):
            key = (np.round(_f(z), 4).tobytes(), float(lam), float(t))
            if key not in cache:
                cache[key] = _f(orig(z, lam, t))
            return cache[key].copy()
        try:
            op.resolvent = memo
            op._blind8_memo = True
        except (AttributeError, TypeError):
            pass
    return proximal(problem, t_grid)


def lagged_field_above_512(problem, t_grid):
    """For more than 512 cells the field is "pipelined": f at the state of the step before (x_{k-1} for step k+1)."""
    t = _f(t_grid)
    dU = _incr(problem, t)
    K = t.size - 1
    x = [_f(problem.x0).copy()]
    for k in range(1, K + 1):
        h = t[k] - t[k - 1]
        src = x[-2] if (K > 512 and k >= 2) else x[-1]
        z = x[-1] + (h * _f(problem.f(src)) if problem.f is not None else 0.0)
        if dU is not None:
            z = z + dU[k - 1]
        x.append(_f(problem.operator.resolvent(z, h, t[k])))
    return np.array(x)


def _sweep_factory(jacobi):
    """z = x + h f(x) coordinate by coordinate: Gauss–Seidel (the bug) evaluates f at the partly updated z."""
    def stepper(problem, t_grid):
        t = _f(t_grid)
        dU = _incr(problem, t)
        x = [_f(problem.x0).copy()]
        for k in range(1, t.size):
            h = t[k] - t[k - 1]
            xk = x[-1]
            z = xk.copy()
            if problem.f is not None:
                fx = _f(problem.f(xk)) if jacobi else None
                for i in range(z.size):
                    fi = fx if jacobi else _f(problem.f(z))
                    z.flat[i] = xk.flat[i] + h * fi.flat[i]
            if dU is not None:
                z = z + dU[k - 1]
            x.append(_f(problem.operator.resolvent(z, h, t[k])))
        return np.array(x)
    stepper.__name__ = "jacobi_field" if jacobi else "gauss_seidel_field"
    return stepper


# ----------------------------------------------------------------------------------------------------
# the entries
# ----------------------------------------------------------------------------------------------------

ENTRIES: list[Entry] = [
    # operators: plants
    Entry("l1_ball_unique_sort_ties", "operator", f"{RES} i/v (J_λx ∈ cl dom F, Y_λx ∈ F(J_λx))", False,
          lambda: _l1_ball_build(True, "l1 ball, np.unique sort"), "x = (2, 2, 0): J = (1, 1, 0), |J|_1 = 2",
          "projection onto the l1 ball sorting |x| with np.unique: tied magnitudes collapse, θ too small"),
    Entry("ball_reciprocal_scale_subnormal", "operator", f"{RES} i (dom J_λ = R^n, single-valued)", False,
          lambda: _ball_rescale_build(True, "ball, x·(1/max|x|)"), "x = (5e-324, 0, 0): J = (nan, nan, nan)",
          "overflow-safe ball projection multiplying by 1/max|x_i|, +inf for an all-subnormal x"),
    Entry("soft_memo_rounded_key", "operator", f"{RES} ii/v (J_λ a function of x; Y_λx ∈ F(J_λx))", False,
          lambda: _soft_cache_build(True, "soft threshold, memo on round(x, 6)"),
          "x1 = (1, 0, 0) then x2 = (1 + 4e-7, 0, 0), λ = 1e-6: J(x2) = J(x1), Y_λx2 off by 0.4",
          "a memo keyed by x rounded to 6 decimals returns a neighbour's resolvent"),
    Entry("linear_td_inverse_cached_by_lam", "operator", f"{RES} v at F(t,·) (Y_λx ∈ F(t, J_λx))", False,
          lambda: _linear_td_build(False, "A(t)x, inverse cached by λ"),
          "J_1 at t = 0 then at t = 1, x = (1, 0): the second uses A(0)",
          "(I + λA(t))^{-1} cached by λ alone: a repeated λ at a new t is evaluated at the stale t"),
    Entry("box_contains_interior_only", "operator", f"{RES} v / (A1) maximality (Y_λx ∈ F(J_λx))", False,
          lambda: _box_build("interior", "box, contains only y = 0"),
          "x = (2, 0, 0), λ = 1: Y = (1, 0, 0) ∉ declared F((1, 0, 0)) = {0}",
          "the declared normal cone of [-1, 1]^3 is {0} everywhere: monotone, not maximal (the faces' normals lost)"),
    Entry("box_contains_one_face", "operator", f"{RES} v (Y_λx ∈ F(J_λx)) at a corner", False,
          lambda: _box_build("one face", "box, contains one active face"),
          "x = (2, 2, 0), λ = 1: Y = (1, 1, 0) refused at the corner (1, 1, 0)",
          "the membership lets only the first active coordinate carry a normal: a corner's cone is a ray"),
    Entry("box_shift_min_norm_faces", "operator", "minimal section F^0 = proj(0, F(x)) (least norm)", False,
          lambda: _box_shift_build(False, "(x - a) + N_box, min_norm x - a"),
          "x = (1, 0, 0): F^0 = (0, -0.5, 3), returned (-1, -0.5, 3)",
          "F^0 of (x - a) + N_[-1,1]^3 forgets the half-line on a face"),
    Entry("batch_rows_sorted_by_step", "operator", f"{RES} ii/v (J_λ at each row's own λ)", False,
          lambda: _batch_order_build(False, "batched soft threshold, rows sorted by λ"),
          "rows (3, 0, 0), (0, 3, 0) at λ = 2, 1: rows come back swapped",
          "a batched resolvent grouping rows by step with argsort and never undoing the permutation"),
    Entry("linear_integer_lambda_power", "operator", f"{RES} v (Y_λx = (x - J_λx)/λ ∈ F(J_λx)) at integer λ", False,
          lambda: _integer_lambda_build(True, "Ax, integer λ as J_1^k"),
          "x = (1, 0), λ = 2: J_1^2 x ≠ (I + 2A)^{-1}x",
          "an integer step k computed as k applications of J_1 (the resolvents are not a semigroup)"),
    Entry("box_value_forgets_indicator", "operator", "prox: p minimises g(z) + |z - x|²/(2λ) (g = <c,·> + ι_box)", False,
          lambda: _box_value_build(False, "linear + box, value without indicator"),
          "x = (0, 0, 0), λ = 1, z = x - λc = (-1, 2, -0.5) beats p = (-1, 1, -0.5)",
          "the function value omits the box's indicator (+inf outside)"),
    Entry("halfspace_contains_unnormalised", "operator", f"{RES} v (Y_λx ∈ N_H(J_λx))", False,
          lambda: _halfspace_build(False, "half-space, μ = <y, a>"),
          "x = (1, 0), λ = 1: Y = (2/25)(3, 4) refused (μ = <y,a> = 2 instead of 2/25)",
          "the membership's multiplier μ = <y, a> without dividing by |a|² = 25"),
    Entry("ball_contains_signless", "operator", "(A1) graph of F monotone (the declared membership)", False,
          _ball_signless_build, "(1,0,0) with y = (-1,0,0) and (0,0,0) with y = 0: <Δx, Δy> = -1 < 0",
          "the ball's normal cone accepts inward normals (|<y, x>| = |y||x|)"),
    Entry("simplex_theta_off_by_one", "operator", f"{RES} i/v (J_λx ∈ cl dom F = Δ)", False,
          lambda: _simplex_build(True, "simplex, θ/(ρ+1)"), "x = (1, 1, 1): J = (0.5, 0.5, 0.5), Σ = 1.5",
          "the simplex projection's threshold divides by ρ + 1 (a 0- vs 1-based index)"),
    Entry("linear_float32_above_1e4", "operator", f"{RES} v (Y_λx ∈ F(J_λx)) at large |x|", False,
          lambda: _downcast_build(np.float32, "Ax, float32 above 1e4"),
          "x = (12345.678, 0.1), λ = 1: J off by ~1e-4 (float32: relative 6e-8)",
          "for max|x| > 1e4 the solve runs in float32 and is cast back to float64"),
    # steppers: plants
    Entry("merges_short_cells", "stepper", "eq:iteration (x_{k+1} = J_{h F(t_{k+1})}(x_k + h f(x_k) + ∫u) at every node)",
          False, lambda: (_merge_factory(0.25), None), "a random partition with h_k < h_{k-1}/4",
          "a cell shorter than a quarter of the previous one is merged with the next, its node interpolated"),
    Entry("rounds_grid_in_place", "stepper", "eq:iteration / issue 42 (the stepper never writes into its grid)", False,
          lambda: (_grid_round_factory(True), None), "any grid with a time not a multiple of 1e-14",
          "np.round(t_grid, 14, out=t_grid): the caller's partition rewritten"),
    Entry("input_reversed_n_ge_5", "stepper", "eq:iteration with ∫u (Section 6, l:extinput)", False,
          lambda: (input_reversed_n_ge_5, None), "n = 5, an input acting on coordinate 1 only",
          "for n ≥ 5 the input increments are taken with the coordinates reversed"),
    Entry("safety_clip_3", "stepper", "eq:iteration (no projection besides J)", False,
          lambda: (safety_clip_3, None), "x0 = (4,), F = 0: x_0 = 3",
          "every state clipped to [-3, 3]^n"),
    Entry("overrelaxed_1_02", "stepper", "eq:iteration (x_{k+1} = J(z_k))", False,
          lambda: (_relaxed_factory(1.02), None), "any active step: x_1 = x_0 + 1.02(J - x_0)",
          "an over-relaxed step x + 1.02(J(z) - x)"),
    Entry("memo_z_only", "stepper", "eq:iteration (F(t_{k+1}), h_{k+1} at each step)", False,
          lambda: (_memo_factory(False), None), "a state at rest inside a moving domain until the boundary reaches it",
          "the resolvent memoised by z alone: a state at rest keeps the value at an earlier t"),
    Entry("unrolled_remainder_unprojected", "stepper", "eq:iteration (x_K = J(z_{K-1}))", False,
          lambda: (_unrolled_factory(False), None), "a partition with an odd number of cells, the last step active",
          "the loop unrolled by two; an odd last cell is stepped without the resolvent"),
    Entry("normalised_time", "stepper", "eq:iteration (F(t_{k+1}, ·))", False,
          lambda: (normalised_time, None), "a time-dependent operator on [0, T], T ≠ 1",
          "the operator evaluated at t/T"),
    Entry("memo_installed_on_operator", "stepper", "eq:iteration / the problem is the caller's", False,
          lambda: (memo_installed_on_operator, None), "any problem: z and z + 1e-5 share a resolvent value",
          "a memo of the resolvent keyed by z rounded to 4 decimals installed on the caller's operator object"),
    Entry("lagged_field_above_512", "stepper", "eq:iteration (f(x_k))", False,
          lambda: (lagged_field_above_512, None), "a problem with f on a grid of more than 512 cells",
          "above 512 cells the field is evaluated at the previous state"),
    Entry("gauss_seidel_field", "stepper", "eq:iteration (f(x_k))", False,
          lambda: (_sweep_factory(False), None), "n = 2, f coupled (f(x) = (x_2, -x_1))",
          "z = x + h f(x) updated coordinate by coordinate with f at the partly updated z"),
    # controls
    Entry("ctrl_l1_ball_sort", "operator", f"{RES} i/v", True, lambda: _l1_ball_build(False, "l1 ball, np.sort"),
          "x = (2, 2, 0): J = (0.5, 0.5, 0)", "np.sort keeps the ties", twin="l1_ball_unique_sort_ties"),
    Entry("ctrl_ball_divide_scale", "operator", f"{RES} i", True, lambda: _ball_rescale_build(False, "ball, x/max|x|"),
          "x = (5e-324, 0, 0): J = x", "divides by s instead of multiplying by 1/s", twin="ball_reciprocal_scale_subnormal"),
    Entry("ctrl_soft_memo_exact_key", "operator", f"{RES} ii/v", True,
          lambda: _soft_cache_build(False, "soft threshold, memo on x"), "-", "the memo keyed by x's bytes",
          twin="soft_memo_rounded_key"),
    Entry("ctrl_linear_td_cache_lam_t", "operator", f"{RES} v", True,
          lambda: _linear_td_build(True, "A(t)x, inverse cached by (λ, t)"), "-", "cache keyed by (λ, t)",
          twin="linear_td_inverse_cached_by_lam"),
    Entry("ctrl_box_contains_coordinates", "operator", f"{RES} v", True,
          lambda: _box_build("coordinates", "box, contains per coordinate"), "-", "each coordinate at its own face",
          twin="box_contains_one_face"),
    Entry("ctrl_box_shift_min_norm", "operator", "minimal section", True,
          lambda: _box_shift_build(True, "(x - a) + N_box, min_norm on faces"), "-", "the half-lines on the faces",
          twin="box_shift_min_norm_faces"),
    Entry("ctrl_batch_rows_restored", "operator", f"{RES} ii/v", True,
          lambda: _batch_order_build(True, "batched soft threshold, order restored"), "-", "out[order] = sorted rows",
          twin="batch_rows_sorted_by_step"),
    Entry("ctrl_linear_integer_lambda_solve", "operator", f"{RES} v", True,
          lambda: _integer_lambda_build(False, "Ax, every λ solved"), "-", "(I + λA)^{-1}x for every λ",
          twin="linear_integer_lambda_power"),
    Entry("ctrl_halfspace_contains_normalised", "operator", f"{RES} v", True,
          lambda: _halfspace_build(True, "half-space, μ = <y, a>/|a|²"), "-", "μ = <y, a>/|a|²",
          twin="halfspace_contains_unnormalised"),
    Entry("ctrl_box_value_indicator", "operator", "prox minimiser", True,
          lambda: _box_value_build(True, "linear + box, value with indicator"), "-", "+inf outside the box",
          twin="box_value_forgets_indicator"),
    Entry("ctrl_linear_float64_above_1e4", "operator", f"{RES} v", True,
          lambda: _downcast_build(np.float64, "Ax, float64 above 1e4"), "-", "the same branch in float64",
          twin="linear_float32_above_1e4"),
    Entry("ctrl_relaxed_1", "stepper", "eq:iteration", True, lambda: (_relaxed_factory(1.0), None), "-",
          "x + 1.0(J(z) - x)", twin="overrelaxed_1_02"),
    Entry("ctrl_memo_z_h_t", "stepper", "eq:iteration", True, lambda: (_memo_factory(True), None), "-",
          "the memo keyed by (z, h, t)", twin="memo_z_only"),
    Entry("ctrl_unrolled_remainder_projected", "stepper", "eq:iteration", True,
          lambda: (_unrolled_factory(True), None), "-", "the odd cell stepped with the resolvent",
          twin="unrolled_remainder_unprojected"),
    Entry("ctrl_rounds_grid_copy", "stepper", "eq:iteration / issue 42", True,
          lambda: (_grid_round_factory(False), None), "-", "rounds a copy of the grid", twin="rounds_grid_in_place"),
    Entry("ctrl_jacobi_field", "stepper", "eq:iteration", True, lambda: (_sweep_factory(True), None), "-",
          "f evaluated once at x_k", twin="gauss_seidel_field"),
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


def _refused(ok):
    return 1.0 if ok else 2.0      # a membership the law needs: accepted ≤ 1, refused > 1


def _op_witness(name):
    e_op = BY_NAME[name].build
    if name in ("l1_ball_unique_sort_ties", "ctrl_l1_ball_sort"):
        return lambda: max(0.0, np.abs(e_op().resolvent(np.array([2.0, 2.0, 0.0]), 1.0)).sum() - 1.0) / EQ
    if name in ("ball_reciprocal_scale_subnormal", "ctrl_ball_divide_scale"):
        x = np.array([5e-324, 0.0, 0.0])

        def w():
            with np.errstate(all="ignore"):           # the plant's own overflow: its NaN is the witness
                return _eq(e_op().resolvent(x, 1.0), x)
        return w
    if name in ("soft_memo_rounded_key", "ctrl_soft_memo_exact_key"):
        def w():
            op = e_op()
            x1, x2, lam = np.array([1.0, 0, 0]), np.array([1.0 + 4e-7, 0, 0]), 1e-6
            op.resolvent(x1, lam)
            y = (x2 - op.resolvent(x2, lam)) / lam           # Y_λx2 must be in ∂|·|_1(J): (1, 0, 0)
            return _eq(y, l1_min_norm(_soft(x2, lam)), 1.0) * EQ / 1e-6     # Y's rounding at λ = 1e-6: 1e-16/1e-6
        return w
    if name in ("linear_td_inverse_cached_by_lam", "ctrl_linear_td_cache_lam_t"):
        def w():
            op, x = e_op(), np.array([1.0, 0.0])
            op.resolvent(x, 1.0, 0.0)
            return _eq(op.resolvent(x, 1.0, 1.0), np.linalg.solve(np.eye(2) + _A_t(1.0), x))
        return w
    if name in ("box_contains_interior_only", "box_contains_one_face", "ctrl_box_contains_coordinates"):
        x = np.array([2.0, 0.0, 0.0]) if name == "box_contains_interior_only" else np.array([2.0, 2.0, 0.0])

        def w():
            op = e_op()
            j = op.resolvent(x, 1.0)
            return _refused(op.contains(j, x - j))
        return w
    if name in ("box_shift_min_norm_faces", "ctrl_box_shift_min_norm"):
        return lambda: _eq(e_op().min_norm(np.array([1.0, 0.0, 0.0])), [0.0, -0.5, 3.0], 3.0)
    if name in ("batch_rows_sorted_by_step", "ctrl_batch_rows_restored"):
        def w():
            op = e_op()
            X, lams = np.array([[3.0, 0, 0], [0, 3.0, 0]]), np.array([2.0, 1.0])
            return _eq(op.resolvent_batch(X, lams, np.zeros(2), pad=False), _soft(X, lams[:, None]), 3.0)
        return w
    if name in ("linear_integer_lambda_power", "ctrl_linear_integer_lambda_solve"):
        x = np.array([1.0, 0.0])
        return lambda: _eq(e_op().resolvent(x, 2.0), np.linalg.solve(np.eye(2) + 2.0 * _A_SKEW, x))
    if name in ("box_value_forgets_indicator", "ctrl_box_value_indicator"):
        def w():
            op, x, lam = e_op(), np.zeros(3), 1.0
            p = op.resolvent(x, lam)
            z = x - lam * _C_LIN                         # the unconstrained minimiser of <c, z> + |z - x|²/2
            obj = lambda v: op.value(v) + float((v - x) @ (v - x)) / (2 * lam)
            return max(0.0, obj(p) - obj(z)) / EQ       # > 1: z beats the prox of the declared g
        return w
    if name in ("halfspace_contains_unnormalised", "ctrl_halfspace_contains_normalised"):
        def w():
            op, x = e_op(), np.array([1.0, 0.0])
            j = op.resolvent(x, 1.0)
            return _refused(op.contains(j, x - j))
        return w
    if name == "ball_contains_signless":
        def w():
            op = e_op()
            a, ya, b, yb = np.array([1.0, 0, 0]), np.array([-1.0, 0, 0]), np.zeros(3), np.zeros(3)
            if not (op.contains(a, ya) and op.contains(b, yb)):
                return 0.0
            return 1.0 + max(0.0, -float((a - b) @ (ya - yb)))     # monotone: <Δx, Δy> ≥ 0
        return w
    if name == "simplex_theta_off_by_one":
        return lambda: abs(e_op().resolvent(np.ones(3), 1.0).sum() - 1.0) / EQ
    if name in ("linear_float32_above_1e4", "ctrl_linear_float64_above_1e4"):
        x = np.array([12345.678, 0.1])
        return lambda: _eq(e_op().resolvent(x, 1.0), np.linalg.solve(np.eye(2) + _A_DC, x), 1.3e4) * EQ / 1e-12
    raise KeyError(name)


class _HalfSpace:
    """N of the moving half-space {x_1 ≥ t - 1/2} in R^n: J = the projection, at any step."""
    def __init__(self, speed=1.0):
        self.speed = speed

    def resolvent(self, z, lam, t=0.0):
        z = _f(z).copy()
        z[0] = max(z[0], self.speed * t - 0.5)
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


_STEP_CASES = {
    "merges_short_cells": (lambda: _P(_HalfSpace(), [-1.0, 0.5], 2.0, f=lambda x: -x), [0, 0.4, 0.8, 0.85, 1.2, 2.0]),
    "input_reversed_n_ge_5": (lambda: _P(_Zero(), np.zeros(5), U=lambda t: np.array([t, 0, 0, 0, 0.0])),
                              np.linspace(0, 1, 5)),
    "safety_clip_3": (lambda: _P(_Zero(), [4.0]), np.linspace(0, 1, 3)),
    "overrelaxed_1_02": (lambda: _P(_HalfSpace(), [-1.0, 0.0]), np.linspace(0, 1, 5)),
    "memo_z_only": (lambda: _P(_HalfSpace(), [0.0, 0.0]), np.linspace(0, 1, 9)),
    "unrolled_remainder_unprojected": (lambda: _P(_HalfSpace(), [-1.0, 0.0]), np.linspace(0, 1, 4)),
    "normalised_time": (lambda: _P(_HalfSpace(), [-1.0, 0.0], 2.0), np.linspace(0, 2, 5)),
    "lagged_field_above_512": (lambda: _P(_Zero(), [1.0], f=lambda x: -x), np.linspace(0, 1, 601)),
    "gauss_seidel_field": (lambda: _P(_Zero(), [1.0, 0.0], f=lambda x: np.array([x[1], -x[0]])), np.linspace(0, 1, 3)),
}


def _step_witness(name):
    """The stepper's states against the scheme's (``proximal``) at the smallest input; a control runs its plant's case."""
    e = BY_NAME[name]
    case = e.twin if e.lawful else name
    if case == "rounds_grid_in_place":
        def w():
            stepper = e.build()[0]
            t = np.array([0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0])
            before = t.copy()
            stepper(_P(_HalfSpace(), [-1.0, 0.0]), t)
            return 0.0 if np.array_equal(t, before) else 2.0          # the caller's grid must be unchanged
        return w
    if case == "memo_installed_on_operator":
        def w():
            op = _HalfSpace()
            memo_installed_on_operator(_P(op, [-1.0, 0.0]), np.linspace(0, 1, 3))
            z = np.array([-1.0, 0.0])
            op.resolvent(z, 0.5, 1.0)
            z2 = z + np.array([0.0, 3e-5])
            return _eq(op.resolvent(z2, 0.5, 1.0), _HalfSpace().resolvent(z2, 0.5, 1.0))
        return w
    make, grid = _STEP_CASES[case]

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
