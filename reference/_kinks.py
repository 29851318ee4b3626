"""The kinks of a manufactured solution ``x* = J_{μF(t,·)}(z(t))`` — where the resolvent switches regime and ``x*'``
jumps — and of its input alone (a field only Lipschitz along ``x*``), located to about ``1e-15 T`` on the
examples (:mod:`verimono.reference.manufactured`; tested against the closed forms of the switching times).

The adaptive tabulation of ``∫(y* - f(x*))`` halves the cells where 8-point Gauss–Legendre and 9-point
Gauss–Lobatto disagree: it closes in on every kink, and each local maximum of the halving depth is a candidate
(:func:`depth_maxima`), located where cubics through the function on either side cross (:func:`locate`) and kept
only if its slope jumps there; a kink exactly at a cell edge leaves both cells smooth, so every edge is looked at
too (:func:`kink_at_edge`).
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

#: a run of cells halved at least this often marks a kink candidate (GL8 accepts smooth data of unit size on
#: the first cells or after a halving or two)
KINK_DEPTH = 3


def find_kinks(sol: Any, pieces: list, given: list[float]) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``(kinks of x*, kinks of the input only)``.  A kink is where the refinement closed in (a local maximum of the
    halving depth, at least ``KINK_DEPTH``), located where one-sided cubics through ``x*`` cross and kept only if
    the slope of ``x*`` jumps there (:func:`locate`); where it does not, the same for ``g = y* - f(x*)``: a kink
    of the input ``u`` alone (a field only Lipschitz along ``x*``).  Then every cell edge whose one-sided slopes
    differ (a kink exactly at an edge leaves both cells smooth), located again about the edge.

    Two kinks a short stretch apart (``|z| = μc`` crossed twice in a row) fall in one run of deep cells with a
    shallower dip between them: each is its own local maximum of depth, located with the cubics kept on its
    side of the other (they once shared one run, whose cubics straddled both: no crossing was found and the
    kinks were taken at cell edges, ``4e-6`` off)."""
    T = sol.T
    candidates = depth_maxima(pieces)
    kinks: list[float] = []
    inputs: list[float] = []
    for i, (a, b) in enumerate(candidates):
        lo = 0.5 * (candidates[i - 1][1] + a) if i > 0 else 0.0
        hi = 0.5 * (b + candidates[i + 1][0]) if i + 1 < len(candidates) else T
        k = locate(sol, a, b, lo, hi)
        if k is not None:
            kinks.append(k)
        elif a <= lo or b >= hi:     # no room to extrapolate from both sides: the refinement's centre
            kinks.append(0.5 * (a + b))
        else:
            k = locate(sol, a, b, lo, hi, of=sol._integrand)
            if k is not None:
                inputs.append(k)
    starts = sol._starts
    for j in range(1, len(starts)):
        t = starts[j]
        if any(abs(t - k) <= 1e-5 * T for k in kinks + inputs):
            continue
        of_x, of_g = kink_at_edge(sol, t)
        if of_x or of_g:
            right = starts[j + 1] if j + 1 < len(starts) else T
            w = 0.25 * min(t - starts[j - 1], right - t)
            k = locate(sol, t - 1e-3 * w, t + 1e-3 * w, t - w, t + w, of=None if of_x else sol._integrand)
            (kinks if of_x else inputs).append(t if k is None else k)
    return tuple(sorted(set(kinks) | set(given))), tuple(sorted(inputs))

def kink_at_edge(sol: Any, t: float) -> tuple[bool, bool]:
    """Whether the slope of ``x*``, and that of ``g = y* - f(x*)``, jump at ``t``: the one-sided secants over
    ``ε = 1e-6 T`` differ by more than ``1e-3 (1 + Lip)`` (a smooth function moves them by ``ε |''|``); a jump of
    ``x*`` itself raises."""
    e = 1e-6 * sol.T
    (gl, xl, _), (gm, xm, _), (gr, xr, _) = sol._g(t - e), sol._g(t), sol._g(t + e)
    of_x = bool(np.linalg.norm((xr - xm) - (xm - xl)) / e > 1e-3 * (1.0 + sol.lipschitz_x))
    of_g = bool(np.linalg.norm((gr - gm) - (gm - gl)) / e > 1e-3 * (1.0 + sol.lipschitz_x + sol.lipschitz_y))
    if of_x:
        sol._check_continuous(t - 1e-12 * sol.T, t + 1e-12 * sol.T)
    return of_x, of_g

def locate(sol: Any, a: float, b: float, lo: float, hi: float, of: Callable | None = None) -> float | None:
    """The kink of ``x*`` (or of the function ``of``) in ``[a, b]`` (free of kinks on ``[lo, a]`` and ``[b, hi]``):
    the crossing of the cubics through it at four points either side, re-centred on it and narrowed until the
    bracket is ``1e-11 T``; ``None`` when the one-sided slopes agree (a smooth stretch refined for its
    curvature).

    The slopes are compared once, on a stencil ``1e-4 T`` wide (less where the neighbours leave less room):
    there a cubic's truncation moves a slope by about ``w³ |x*⁽⁴⁾| ≈ 1e-10`` and rounding by ``eps |x*|/w ≈ 1e-12``.
    On the refinement's own cells, ``1e-10 T`` wide where a field's kink drove it that deep, rounding alone moved
    a slope by ``1e-6`` and a smooth ``x*`` looked kinked; on a stencil a tenth of the room wide, truncation did."""
    T = sol.T
    fn = sol._xs if of is None else of
    lip = sol.lipschitz_x if of is None else sol.lipschitz_y + sol.lipschitz_x
    c = 0.5 * (a + b)
    half = min(max(0.5 * (b - a), 1e-4 * T), 0.25 * (c - lo), 0.25 * (hi - c))
    if half <= 0.0:
        return None
    a, b = c - half, c + half
    k = None
    for it in range(12):
        w = 0.5 * (b - a)
        if a - 3.0 * w < lo or b + 3.0 * w > hi:
            w = min((a - lo) / 3.0, (hi - b) / 3.0)
            if w <= 0.0:
                return k
        m = 0.5 * (a + b)
        sl = np.array([a - j * w for j in range(4)])
        sr = np.array([b + j * w for j in range(4)])
        left = np.polyfit((sl - m) / w, np.array([fn(t) for t in sl]), 3)     # (4, n) coefficients
        right = np.polyfit((sr - m) / w, np.array([fn(t) for t in sr]), 3)
        delta = right - left
        j = int(np.argmax(np.abs(delta[-2])))                # the largest jump of slope Δ'(0)
        roots = np.roots(delta[:, j])
        roots = roots[np.abs(roots.imag) <= 1e-9 * (1.0 + np.abs(roots.real))].real
        half = 0.5 * (b - a) / w + 1.0
        roots = roots[np.abs(roots) <= half]
        if roots.size == 0:
            return k
        r = float(roots[np.argmin(np.abs(roots))])
        if it == 0:
            jump = np.array([np.polyval(np.polyder(delta[:, i]), r) for i in range(delta.shape[1])]) / w
            if np.linalg.norm(jump) <= 1e-6 * (1.0 + lip):
                return None
        k = m + r * w
        if b - a <= 1e-11 * T:
            return k
        eps = max((b - a) / 64.0, 1e-12 * T)
        a, b = max(k - eps, lo), min(k + eps, hi)
    return k


def depth_maxima(pieces: list) -> list[tuple[float, float]]:
    """The stretches ``(a, b)`` of the adaptive partition where the halving depth (at least ``KINK_DEPTH``) has a local
    maximum: consecutive cells of one depth whose neighbours are shallower — where the refinement closed in on a
    kink (or on a curvature it resolved, which :func:`locate` tells apart)."""
    depth = [p[4] for p in pieces]
    out, i = [], 0
    while i < len(pieces):
        j = i
        while j + 1 < len(pieces) and depth[j + 1] == depth[i]:
            j += 1
        before = depth[i - 1] if i > 0 else -1
        after = depth[j + 1] if j + 1 < len(pieces) else -1
        if depth[i] >= KINK_DEPTH and before < depth[i] and after < depth[i]:
            out.append((pieces[i][0], pieces[j][1]))
        i = j + 1
    return out


__all__ = ["find_kinks", "locate", "kink_at_edge", "depth_maxima", "KINK_DEPTH"]
