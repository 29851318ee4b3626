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
    """``fn`` evaluated as row 0 of a batch of one: the general (NumPy row) path."""
    def call(x, *args):
        got = fn(np.asarray(x, dtype=float)[None, :], *args)
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
