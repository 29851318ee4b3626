"""Powell's method without ``scipy.optimize.minimize``'s wrappers, for :func:`verimono.checks.prox_laws`'s
independent minimiser: the same points evaluated in the same order and the same result, bit for bit.

A line-for-line copy of SciPy 1.17.1's unbounded ``_minimize_powell`` (``_linesearch_powell``,
``_recover_from_bracket_error``, ``_minimize_scalar_brent``, ``Brent.optimize``, ``bracket``): the same float
operations on the same operands, the same stopping rules, the same ``maxfev`` count.  The line search's step
lengths are Python floats where SciPy's ``bracket`` makes NumPy scalars (``np.asarray([0.0, 1.0])``): the same
IEEE double operations (``+ - * /``, ``abs``, comparisons; no division here can be by zero: ``bracket``'s
denominator is at least ``2e-21`` in magnitude or NaN, Brent's parabolic step divides by ``tmp2 > 0`` only), so
the same numbers, without NumPy's scalar dispatch and its overflow warnings.  What is left out is what costs per call and changes
no number: the wrapper's copy of each point (every point handed to ``func`` here is a fresh array or a copy), its
``np.isscalar`` test of a float, the closures ``myfunc``/``function_wrapper``, an ``OptimizeResult`` and a success
message per line search, the option checks, callbacks and bounds (not used).  On the operator-law units it was
40–66% of the law's time (docs/speed.md, genops).  ``tests/checks/test_powell.py`` compares it with SciPy's
``minimize(method="Powell")``: every evaluated point, ``x``, ``fun`` and ``nfev``."""

# The code below is adapted from SciPy 1.17.1 (scipy/optimize/_optimize.py), distributed under SciPy's license:
#
# Copyright (c) 2001-2002 Enthought, Inc. 2003, SciPy Developers.
# All rights reserved.
#
# Redistribution and use in source and binary forms, with or without
# modification, are permitted provided that the following conditions
# are met:
#
# 1. Redistributions of source code must retain the above copyright
#    notice, this list of conditions and the following disclaimer.
#
# 2. Redistributions in binary form must reproduce the above
#    copyright notice, this list of conditions and the following
#    disclaimer in the documentation and/or other materials provided
#    with the distribution.
#
# 3. Neither the name of the copyright holder nor the names of its
#    contributors may be used to endorse or promote products derived
#    from this software without specific prior written permission.
#
# THIS SOFTWARE IS PROVIDED BY THE COPYRIGHT HOLDERS AND CONTRIBUTORS
# "AS IS" AND ANY EXPRESS OR IMPLIED WARRANTIES, INCLUDING, BUT NOT
# LIMITED TO, THE IMPLIED WARRANTIES OF MERCHANTABILITY AND FITNESS FOR
# A PARTICULAR PURPOSE ARE DISCLAIMED. IN NO EVENT SHALL THE COPYRIGHT
# OWNER OR CONTRIBUTORS BE LIABLE FOR ANY DIRECT, INDIRECT, INCIDENTAL,
# SPECIAL, EXEMPLARY, OR CONSEQUENTIAL DAMAGES (INCLUDING, BUT NOT
# LIMITED TO, PROCUREMENT OF SUBSTITUTE GOODS OR SERVICES; LOSS OF USE,
# DATA, OR PROFITS; OR BUSINESS INTERRUPTION) HOWEVER CAUSED AND ON ANY
# THEORY OF LIABILITY, WHETHER IN CONTRACT, STRICT LIABILITY, OR TORT
# (INCLUDING NEGLIGENCE OR OTHERWISE) ARISING IN ANY WAY OUT OF THE USE
# OF THIS SOFTWARE, EVEN IF ADVISED OF THE POSSIBILITY OF SUCH DAMAGE.

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

_GOLD = 1.618034            # bracket's golden ratio, as SciPy writes it
_VERYSMALL = 1e-21
_GROW_LIMIT = 110.0
_BRACKET_MAXITER = 1000
_CG = 0.3819660             # Brent's golden section
_MINTOL = 1.0e-11
_BRENT_MAXITER = 500


class _MaxFev(Exception):
    """``maxfev`` evaluations made (SciPy's ``_MaxFuncCallError``): Powell stops where it is."""


class _NoBracket(Exception):
    """``bracket`` found no valid bracket (SciPy's ``BracketError``), with its last three points."""

    def __init__(self, data: tuple) -> None:
        super().__init__()
        self.data = data


def powell(func: Callable[[np.ndarray], Any], x0: Any, xtol: float, ftol: float, maxfev: int
           ) -> tuple[Any, np.ndarray]:
    """``(fun, x)`` of ``scipy.optimize.minimize(func, x0, method="Powell", options={"xtol": xtol, "ftol": ftol,
    "maxfev": maxfev})`` (no bounds, no callback), for a 1-D float ``x0``.  ``func`` gets a point of its own at
    every call."""
    x = np.asarray(x0).flatten()
    if x.dtype.kind in "iu":        # minimize's integer start made float (np.typecodes["AllInteger"])
        x = np.asarray(x, dtype=float)
    n = len(x)
    maxfun = maxfev
    maxiter = n * 1000 if maxfun == np.inf else np.inf
    calls = [0]

    def f(z):
        if calls[0] >= maxfun:
            raise _MaxFev
        calls[0] += 1
        fz = func(z)
        if type(fz) is not float and not np.isscalar(fz):
            try:
                fz = np.asarray(fz).item()
            except (TypeError, ValueError) as e:
                raise ValueError("The user-provided objective function must return a scalar value.") from e
        return fz

    tol = xtol * 100
    if tol < 0:
        raise ValueError(f'tolerance should be >= 0, got {tol!r}')
    direc = np.eye(n, dtype=float)
    fval = f(x.copy())
    x1 = x.copy()
    it = 0
    while True:
        try:
            fx = fval
            bigind = 0
            delta = 0.0
            for i in range(n):
                fx2 = fval
                fval, x, _ = _line(f, x, direc[i], tol, fval)
                if (fx2 - fval) > delta:
                    delta = fx2 - fval
                    bigind = i
            it += 1
            bnd = ftol * (abs(fx) + abs(fval)) + 1e-20
            if 2.0 * (fx - fval) <= bnd:
                break
            if calls[0] >= maxfun:
                break
            if it >= maxiter:
                break
            if math.isnan(fx) and math.isnan(fval):
                break
            direc1 = x - x1
            x1 = x.copy()
            x2 = x + direc1              # x + min(lmax, 1)·direc1 with lmax = 1 (no bounds): 1·d is d
            fx2 = f(x2)
            if fx > fx2:
                t = 2.0 * (fx + fx2 - 2.0 * fval)
                temp = (fx - fval - delta)
                t *= temp * temp
                temp = fx - fx2
                t -= delta * temp * temp
                if t < 0.0:
                    fval, x, direc1 = _line(f, x, direc1, tol, fval)
                    if direc1.any():
                        direc[bigind] = direc[-1]
                        direc[-1] = direc1
        except _MaxFev:
            break
    return fval, x


def _line(f, p: np.ndarray, xi: np.ndarray, tol: float, fval):
    """SciPy's unbounded ``_linesearch_powell``: Brent along ``xi`` from ``p`` (its bracket from 0 and 1)."""
    if not xi.any():
        return fval, p, xi

    def along(alpha):
        return f(p + alpha * xi)
    try:
        alpha, fret = _brent(along, tol)
    except _NoBracket as e:       # _recover_from_bracket_error: the best of the last three points
        xa, xb, xc, fa, fb, fc = e.data
        xs, fs = [xa, xb, xc], [fa, fb, fc]
        if np.any(np.isnan([xs, fs])):
            alpha, fret = np.nan, np.nan
        else:
            imin = np.argmin(fs)
            alpha, fret = xs[imin], fs[imin]
    xi = alpha * xi
    return fret, p + xi, xi


def _brent(func, tol: float):
    """``Brent.optimize`` after ``bracket(func)``: ``(xmin, fval)``."""
    xa, xb, xc, fa, fb, fc = _bracket(func)
    x = w = v = xb
    fw = fv = fx = fb
    if xa < xc:
        a, b = xa, xc
    else:
        a, b = xc, xa
    deltax = 0.0
    it = 0
    while it < _BRENT_MAXITER:
        tol1 = tol * abs(x) + _MINTOL
        tol2 = 2.0 * tol1
        xmid = 0.5 * (a + b)
        if abs(x - xmid) < (tol2 - 0.5 * (b - a)):
            break
        if abs(deltax) <= tol1:
            if x >= xmid:
                deltax = a - x
            else:
                deltax = b - x
            rat = _CG * deltax
        else:
            tmp1 = (x - w) * (fx - fv)
            tmp2 = (x - v) * (fx - fw)
            p = (x - v) * tmp2 - (x - w) * tmp1
            tmp2 = 2.0 * (tmp2 - tmp1)
            if tmp2 > 0.0:
                p = -p
            tmp2 = abs(tmp2)
            dx_temp = deltax
            deltax = rat
            if (p > tmp2 * (a - x)) and (p < tmp2 * (b - x)) and (abs(p) < abs(0.5 * tmp2 * dx_temp)):
                rat = p * 1.0 / tmp2
                u = x + rat
                if (u - a) < tol2 or (b - u) < tol2:
                    if xmid - x >= 0:
                        rat = tol1
                    else:
                        rat = -tol1
            else:
                if x >= xmid:
                    deltax = a - x
                else:
                    deltax = b - x
                rat = _CG * deltax
        if abs(rat) < tol1:
            if rat >= 0:
                u = x + tol1
            else:
                u = x - tol1
        else:
            u = x + rat
        fu = func(u)
        if fu > fx:
            if u < x:
                a = u
            else:
                b = u
            if (fu <= fw) or (w == x):
                v = w
                w = u
                fv = fw
                fw = fu
            elif (fu <= fv) or (v == x) or (v == w):
                v = u
                fv = fu
        else:
            if u >= x:
                a = x
            else:
                b = x
            v = w
            w = x
            x = u
            fv = fw
            fw = fx
            fx = fu
        it += 1
    return x, fx


def _bracket(func):
    """SciPy's ``bracket(func)`` (``xa = 0``, ``xb = 1``, ``grow_limit = 110``, ``maxiter = 1000``)."""
    xa, xb = 0.0, 1.0
    fa = func(xa)
    fb = func(xb)
    if fa < fb:
        xa, xb = xb, xa
        fa, fb = fb, fa
    xc = xb + _GOLD * (xb - xa)
    fc = func(xc)
    it = 0
    while fc < fb:
        tmp1 = (xb - xa) * (fb - fc)
        tmp2 = (xb - xc) * (fb - fa)
        val = tmp2 - tmp1
        if abs(val) < _VERYSMALL:
            denom = 2.0 * _VERYSMALL
        else:
            denom = 2.0 * val
        w = xb - ((xb - xc) * tmp2 - (xb - xa) * tmp1) / denom
        wlim = xb + _GROW_LIMIT * (xc - xb)
        if it > _BRACKET_MAXITER:
            raise RuntimeError("No valid bracket was found before the iteration limit was reached. Consider trying "
                               "different initial points or increasing `maxiter`.")
        it += 1
        if (w - xc) * (xb - w) > 0.0:
            fw = func(w)
            if fw < fc:
                xa = xb
                xb = w
                fa = fb
                fb = fw
                break
            elif fw > fb:
                xc = w
                fc = fw
                break
            w = xc + _GOLD * (xc - xb)
            fw = func(w)
        elif (w - wlim) * (wlim - xc) >= 0.0:
            w = wlim
            fw = func(w)
        elif (w - wlim) * (xc - w) > 0.0:
            fw = func(w)
            if fw < fc:
                xb = xc
                xc = w
                w = xc + _GOLD * (xc - xb)
                fb = fc
                fc = fw
                fw = func(w)
        else:
            w = xc + _GOLD * (xc - xb)
            fw = func(w)
        xa = xb
        xb = xc
        xc = w
        fa = fb
        fb = fc
        fc = fw
    cond1 = (fb < fc and fb <= fa) or (fb < fa and fb <= fc)
    cond2 = (xa < xb < xc or xc < xb < xa)
    cond3 = math.isfinite(xa) and math.isfinite(xb) and math.isfinite(xc)
    if not (cond1 and cond2 and cond3):
        raise _NoBracket((xa, xb, xc, fa, fb, fc))
    return xa, xb, xc, fa, fb, fc
