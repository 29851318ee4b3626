"""The catalog's one-point fast paths (a point ``(n,)``, one ``λ``, one ``t``: scalar arithmetic in Python floats)
give the bits, the typed errors and the warnings of the general path they shortcut.

The general path is the batch one: ``member(x[None], ...)[0]`` runs the NumPy row arithmetic the one-point call
ran before (the same operations on the same ``|x|²``, the BLAS dot of the row).  Each comparison is also seen
failing: with a last-bit error planted in the fast path's square root (``_PLANTED``) it finds differences.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import verimono.core.operators as operators
from verimono.core.operators import NormSubdifferential


def _outcome(fn, *args):
    """What a call gives: its result's bytes (dtype, shape) or its error's type and message, and its warnings."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            r = fn(*args)
            got = ("float", np.float64(r).tobytes()) if isinstance(r, float) else \
                ("array", np.asarray(r).dtype.str, np.shape(r), np.asarray(r).tobytes())
        except Exception as exc:     # the typed error is part of the contract
            got = ("error", type(exc).__name__, str(exc))
    return got, sorted({f"{w.category.__name__}: {w.message}" for w in caught})


def _row(fn):
    """``fn`` evaluated as row 0 of a batch of one: the general (NumPy row) path (an error's message names the
    point as the one-point call would: ``[[..]]`` as ``[..]``, the shape ``(1, n)`` as ``(n,)``)."""
    def call(x, *args):
        x = np.asarray(x, dtype=float)
        try:
            got = fn(x[None, :], *args)
        except Exception as exc:
            msg = str(exc).replace("[[", "[").replace("]]", "]").replace(f"(1, {x.shape[-1]})", f"({x.shape[-1]},)")
            raise type(exc)(msg) from None
        return got[0]
    return call


def _points(n: int, rng) -> list:
    """Zero (both signs), subnormal, tiny, huge (|x|² overflows), NaN, ±inf, float32, a list, a strided view, and
    random points over 24 decades."""
    pts = [np.zeros(n), -np.zeros(n), np.full(n, 5e-324), np.full(n, 1e-170), np.full(n, 1e200), np.full(n, -1e160),
           np.full(n, np.nan), np.full(n, np.inf), np.full(n, -np.inf), rng.standard_normal(n).astype(np.float32),
           list(rng.standard_normal(n)), rng.standard_normal(2 * n)[::2]]
    pts += [rng.standard_normal(n) * 10.0 ** rng.integers(-12, 12) for _ in range(8)]
    return pts


_TIMES = (0.0, 0.3, 1.0, 2.5, -0.7, float("nan"), np.float64(0.4))
_STEPS = (1.0, 1e-300, 1e300, np.float64(0.5), 3)
#: refused step sizes (tried at the first points: the refusal comes before any arithmetic)
_BAD_STEPS = (0.0, -1.0, float("nan"), float("inf"))


def _weights():
    """``c`` of every kind the fast path meets or declines: the paper's ``t`` (negative and NaN at some times),
    a float64, an int and a 0-d array returned, constants (zero, huge)."""
    return [("t", lambda t: t), ("float64", lambda t: np.float64(1.0 - t)), ("int", lambda t: 2),
            ("0-d", lambda t: np.array(t)), ("const", 1.5), ("zero", 0.0), ("huge", 1e300)]


def _resolvent_differences(n: int) -> list:
    rng = np.random.default_rng(n)
    out = []
    for label, c in _weights():
        op = NormSubdifferential(c, dim=n)
        one, row = op.resolvent, _row(op.resolvent)
        for i, x in enumerate(_points(n, rng)):
            for t in _TIMES:
                for lam in _STEPS + (_BAD_STEPS if i < 2 else ()):
                    a, b = _outcome(one, x, lam, t), _outcome(row, x, lam, t)
                    # the batch path names a bad λ the same way; only its result is a row of a (1, n) array
                    if a != b:
                        out.append((label, i, t, lam, a, b))
    return out


def _value_differences(n: int) -> list:
    """``value`` against its definition ``float(c(t)) * float(np.linalg.norm(x))`` (checked as ``_weight_at``)."""
    rng = np.random.default_rng(10 + n)
    out = []
    for label, c in _weights():
        op = NormSubdifferential(c, dim=n)

        def reference(x, t, op=op):
            cc = np.asarray(operators._weight_at(op._c, t, op.name, "c(t)"), dtype=float)
            return float(cc) * float(np.linalg.norm(np.asarray(x, dtype=float)))
        for i, x in enumerate(_points(n, rng) + [rng.standard_normal((3, n))]):
            for t in _TIMES:
                a, b = _outcome(op.value, x, t), _outcome(reference, x, t)
                if a != b:
                    out.append((label, i, t, a, b))
    return out


def _planted(monkeypatch):
    """A last-bit error in the fast paths' square root (the general path's ``np.sqrt`` is untouched)."""
    monkeypatch.setattr(operators, "_sqrt", lambda s: math.nextafter(math.sqrt(s), math.inf))


@pytest.mark.parametrize("n", [1, 3])
def test_norm_subdifferential_resolvent_one_point_is_the_row_path(n):
    assert _resolvent_differences(n) == []


@pytest.mark.parametrize("n", [1, 3])
def test_norm_subdifferential_value_is_its_definition(n):
    assert _value_differences(n) == []


def test_the_comparisons_see_a_planted_last_bit_error(monkeypatch):
    _planted(monkeypatch)
    assert len(_resolvent_differences(3)) > 100
    assert len(_value_differences(3)) > 100


def test_a_batch_weight_is_refused_by_value_and_a_one_point_resolvent():
    op = NormSubdifferential(np.array([0.5, 1.0]), dim=2)
    with pytest.raises(NotImplementedError, match="batch"):
        op.value(np.ones(2))
    with pytest.raises(operators.InvalidProblem, match="batch of 2 values"):
        op.resolvent(np.ones(2), 0.5)
    # the batch (B, n) applies c_i to row i: J x = max(1 - λc_i/|x|, 0) x with |x| = √2
    np.testing.assert_allclose(op.resolvent(np.ones((2, 2)), 0.5),
                               [[1 - 0.25 / 2 ** 0.5] * 2, [1 - 0.5 / 2 ** 0.5] * 2], rtol=4 * np.finfo(float).eps)


def _sets():
    """Catalog sets whose one-point projection has a fast path, with the cases it declines: a radius
    per row (refused for one point), a normal whose |a|² underflows or overflows, a centre where d·d overflows, a
    moving radius below 0 (an error, or 0 within round-off)."""
    from verimono.core.sets import Ball, Box, HalfSpace

    return [Ball([0.5, -1.0, 2.0], 1.5), Ball([0.0, 0.0, 0.0], 0.0), Ball([1e300, -1e300, 0.0], 1e300),
            Ball(lambda t: np.array([math.sin(t), 0.0, 1.0]), lambda t: 1.0 - t),
            Ball(np.zeros(3), np.array([0.5, 1.0])),
            HalfSpace([1.0, 2.0, -1.0], 0.5), HalfSpace([1e-170, 1e-170, 0.0], 0.0), HalfSpace([1e200, 1.0, 0.0], -1e300),
            HalfSpace(lambda t: np.array([math.cos(t), math.sin(t), 0.0]), lambda t: t),
            Box(lambda t: np.array([math.sin(t) - 1, -1.0, -np.inf]), lambda t: np.array([math.sin(t) + 1, 1 - t, 2.0]))]


def _set_differences() -> list:
    rng = np.random.default_rng(7)
    out = []
    for S in _sets():
        for i, x in enumerate(_points(3, rng)):
            for t in _TIMES:
                for what, one, row in (("project", S.project, _row(S.project)),
                                       ("contains", S.contains, lambda x, t, S=S: bool(
                                           np.max(np.abs(S.project(x, t) - np.asarray(x, dtype=float)), initial=0.0)
                                           <= operators.tolerance(np.asarray(x, dtype=float))))):
                    a, b = _outcome(one, x, t), _outcome(row, x, t)
                    if a != b:
                        out.append((S.name, i, t, what, a, b))
    return out


def test_catalog_sets_one_point_projection_is_the_row_path():
    assert _set_differences() == []


def test_the_set_comparison_sees_a_planted_last_bit_error(monkeypatch):
    import verimono.core.sets as sets

    monkeypatch.setattr(sets, "_sqrt", lambda s: math.nextafter(math.sqrt(s), math.inf))
    monkeypatch.setattr(sets, "_INF", 1e300)        # and the half-space's guard moved: its overflow warnings go
    assert len(_set_differences()) > 50


def test_tolerance_of_a_python_float_is_that_of_the_same_double():
    """``tolerance(c)`` of a Python float (a weight ``c(t)``) takes ``abs`` directly: the number NumPy's path gives
    for the same double (``np.float64`` goes through ``np.max(np.abs(.))``); -0, NaN, ±inf, subnormals included."""
    from verimono.core.tolerances import tolerance

    values = [0.0, -0.0, 5e-324, -1e-300, 1.0, -2.5, 1e308, -1e308, math.inf, -math.inf, math.nan]
    values += list(np.random.default_rng(3).standard_normal(50) * 10.0 ** np.arange(-25, 25))
    for v in values:
        for other in ((), (np.array([0.5, -3.0]),), (7.0,)):
            a = tolerance(float(v), *other)
            b = tolerance(np.float64(v), *other)
            assert np.float64(a).tobytes() == np.float64(b).tobytes(), (v, other, a, b)
            assert a == a and a >= 1e-16 or math.isnan(v)      # rtol·(1 + max|s|) ≥ rtol > 0 unless NaN won


def test_a_subclass_overriding_c_at_is_called_through_it():
    """The one-point paths read ``c(t)`` themselves only while ``_c_at`` and ``_col`` are the class's own: a subclass
    that overrides ``_c_at`` (here: doubling the weight) gets it in value, resolvent, min_norm and contains."""
    class Doubled(NormSubdifferential):
        def _c_at(self, t):
            return 2.0 * super()._c_at(t)

    op, plain = Doubled(lambda t: t, dim=2), NormSubdifferential(lambda t: 2.0 * t, dim=2)
    x = np.array([3.0, 4.0])
    assert op.value(x, 0.5) == plain.value(x, 0.5) == 5.0
    assert np.array_equal(op.resolvent(x, 1.0, 0.5), plain.resolvent(x, 1.0, 0.5))     # (1 - 1/5) x
    assert np.array_equal(op.min_norm(x, 0.5), plain.min_norm(x, 0.5))                  # x/5
    assert op.contains(x, x / 5.0, 0.5) and not NormSubdifferential(lambda t: t, dim=2).contains(x, x / 5.0, 0.5)


def _log_barrier_reference(op, x, y, t):
    """``LogBarrier.contains`` as written with ``np.any``/``np.all`` (b19eba1): some ``x'`` within tol of ``x`` with
    ``F(x') = -c/x'`` within tol of ``y``."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if np.any(x <= 0.0):
        return False
    c = op._c(t)
    tol = operators.tolerance(-c / x, y)
    with np.errstate(divide="ignore", over="ignore"):
        lo = np.where(x - tol > 0.0, -c / np.maximum(x - tol, operators._TINY), -np.inf)
    return bool(np.all((y >= lo - tol) & (y <= -c / (x + tol) + tol)))


def test_log_barrier_contains_and_min_norm_on_mixed_signs():
    """Points with some coordinates ≤ 0 (outside: ``min_norm`` raises, ``contains`` is False), inside, and ``y`` on,
    near and off ``-c/x``: the ndarray's own ``any``/``all`` decide as ``np.any``/``np.all`` did."""
    op = operators.LogBarrier(0.7, dim=3)
    rng = np.random.default_rng(5)
    for _ in range(200):
        x = rng.standard_normal(3) + 0.8
        for y in (-0.7 / x, -0.7 / x * (1 + 1e-9), -0.7 / x + rng.standard_normal(3) * 1e-3):
            assert op.contains(x, y, 0.0) == _log_barrier_reference(op, x, y, 0.0)
        if (x <= 0.0).any():
            with pytest.raises(operators.OutsideDomain):
                op.min_norm(x)
        else:
            assert np.array_equal(op.min_norm(x), -0.7 / x)
