"""Issue 43 items 1 and 3 (branch units10): ``prox_minimiser``'s Powell without scipy's wrappers
(:mod:`verimono.checks._powell`) evaluates the points ``scipy.optimize.minimize(method="Powell")`` evaluates, in the
same order, and returns its ``x`` and ``fun`` — bit for bit, on the functions the law minimises (``λg(z) + |z -
x|²/2`` with ``g`` smooth, a kinked norm, an ℓ1 norm, a barrier) and on the paths that rarely run: a flat function
(no valid bracket), ``maxfev`` reached, an unbounded one, NaN.  Seen failing on a variant that moves one constant in
its last digit (Brent's golden section ``0.3819660`` → ``0.3819661``) and on one without the start's copy."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from verimono.checks import _powell


def _phis():
    """``(name, Φ, x0, n)``: Φ as the law makes it (a float per call) and a few that reach the rare paths."""
    rng = np.random.default_rng(7)
    out = []
    for n in (1, 2, 3, 4):
        x = rng.normal(size=n) * 3.0
        c = np.abs(rng.normal(size=n)) + 0.1
        lam = float(np.exp(rng.uniform(-3.0, 2.0)))

        def l1(z, x=x, c=c, lam=lam):
            w = z - x
            return lam * float(np.add.reduce(c * np.abs(z))) + 0.5 * float(w @ w)

        def tnorm(z, x=x, lam=lam):
            w = z - x
            return lam * 1.7 * float(np.sqrt(z @ z)) + 0.5 * float(w @ w)

        def smooth(z, x=x, lam=lam):
            w = z - x
            return lam * float(np.sum(np.cosh(z) - 1.0)) + 0.5 * float(w @ w)

        p = np.sign(x) * np.maximum(np.abs(x) - lam * c, 0.0)      # l1's prox: the law's start at p
        out += [(f"l1 n={n}", l1, p, n), (f"l1 from x n={n}", l1, x.copy(), n),
                (f"norm n={n}", tnorm, x * 0.5, n), (f"smooth n={n}", smooth, x.copy(), n)]
    out += [("barrier", lambda z: float(-np.log(z[0]) + 0.5 * (z[0] - 2.0) ** 2) if z[0] > 0 else 1e300,
             np.array([0.5]), 1),
            ("flat", lambda z: 1.0, np.array([0.3, -0.2]), 2),
            ("unbounded", lambda z: -float(z.sum()), np.array([0.0, 1.0]), 2),
            ("nan", lambda z: float("nan") if z[0] > 1.5 else float((z @ z)), np.array([1.0, 1.0]), 2),
            ("int start", lambda z: float(((z - 0.25) ** 2).sum()), np.array([1, 2, 3]), 3)]
    return out


def _traced(fn):
    seen = []

    def f(z):
        seen.append(np.array(z, copy=True).tobytes())
        return fn(z)
    return f, seen


def _differs(name, fn, x0, n, lean=_powell.powell):
    opts = {"xtol": 1e-10 * (1.0 + float(np.max(np.abs(x0), initial=0.0))), "ftol": 1e-14, "maxfev": 200 * n}
    fs, seen_s = _traced(fn)
    with np.errstate(all="ignore"):
        res = minimize(fs, x0, method="Powell", options=opts)
    fl, seen_l = _traced(fn)
    with np.errstate(all="ignore"):
        fun, x = lean(fl, x0, opts["xtol"], opts["ftol"], opts["maxfev"])
    same = (seen_s == seen_l and np.asarray(x).tobytes() == np.asarray(res.x).tobytes()
            and np.asarray(fun).tobytes() == np.asarray(res.fun).tobytes() and len(seen_l) == res.nfev)
    return not same, len(seen_s)


@pytest.mark.parametrize("case", _phis(), ids=lambda c: c[0])
def test_lean_powell_evaluates_scipys_points_and_returns_its_result(case):
    differs, evaluations = _differs(*case)
    assert not differs
    assert evaluations >= 3


def test_a_last_digit_moved_in_brent_is_seen(monkeypatch):
    """The comparison sees a golden-section constant moved in its last digit."""
    monkeypatch.setattr(_powell, "_CG", 0.3819661)
    assert any(_differs(*case)[0] for case in _phis()[:8])


def test_the_start_is_handed_to_the_function_as_a_copy():
    """``func`` may write into its argument (scipy hands each call a copy): the start point stays Powell's."""
    def writes(z):
        v = float(((z - 1.0) ** 2).sum())
        z[:] = 1e9
        return v
    fun, x = _powell.powell(writes, np.array([0.0, 3.0]), 1e-10, 1e-14, 400)
    res = minimize(writes, np.array([0.0, 3.0]), method="Powell",
                   options={"xtol": 1e-10, "ftol": 1e-14, "maxfev": 400})
    assert x.tobytes() == res.x.tobytes() and fun == res.fun
    assert np.allclose(x, 1.0, atol=1e-6)
