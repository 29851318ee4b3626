"""Issue 43 (branch units10): ``core._small``'s ``abs_max`` and ``all_finite`` of a small float point, read in
Python floats, are NumPy's ``float(np.abs(v).max())`` and ``bool(np.isfinite(v).all())`` bit for bit — on NaN at
every position, ±inf, ±0.0, subnormals, the extremes, float32, a big-endian array, strided views, and the sizes
around :data:`SMALL` (past it NumPy's own path).  Seen failing on a maximum that lets a later entry replace a NaN
and on ``abs`` dropped (the largest negative entry missed)."""

from __future__ import annotations

import itertools

import numpy as np

from verimono.core._small import ROW_COLUMNS, SMALL, abs_max, all_finite, row_abs_max, row_all, row_finite

_SPECIAL = [0.0, -0.0, 5e-324, -5e-324, 1.0, -2.5, 1.7976931348623157e308, -1.7976931348623157e308, np.inf, -np.inf,
            np.nan, 1e-300, -3.0]


def _arrays():
    rng = np.random.default_rng(11)
    out = [np.array(c) for n in (1, 2, 3) for c in itertools.product(_SPECIAL, repeat=n) if n < 3 or rng.random() < 0.15]
    for n in range(1, SMALL + 3):
        for _ in range(20):
            v = rng.normal(size=n) * 10.0 ** rng.integers(-300, 300)
            if rng.random() < 0.3:
                v[rng.integers(n)] = rng.choice([np.nan, np.inf, -np.inf, -0.0])
            with np.errstate(over="ignore"):      # float32 of 1e300: inf, as it should be
                out += [v, v.astype(np.float32), v.astype(">f8"), np.repeat(v, 2)[::2]]
    return out


def test_abs_max_is_numpys_number():
    for v in _arrays():
        with np.errstate(all="ignore"):
            want = float(np.abs(v).max())
        got = abs_max(v)
        assert type(got) is float and np.float64(got).tobytes() == np.float64(want).tobytes(), v


def test_all_finite_is_numpys_answer():
    for v in _arrays():
        assert all_finite(v) is bool(np.isfinite(v).all()), v


def test_row_abs_max_is_numpys_row_maxima():
    """Every row's largest ``|entry|`` column by column (``n ≤ ROW_COLUMNS``) or by ``max/-min`` (wider): NumPy's
    ``np.abs(X).max(axis=1, initial=0.0)`` as numbers — NaN where a row holds one, 0 for rows of no entries —
    on rows of the special values, random rows over 600 decades, and strided and big-endian layouts."""
    rng = np.random.default_rng(12)
    blocks = [np.array(list(itertools.product(_SPECIAL, repeat=n)), dtype=float).reshape(-1, n) for n in (1, 2, 3)]
    for n in range(0, ROW_COLUMNS + 4):
        X = rng.normal(size=(37, n)) * 10.0 ** rng.integers(-300, 300, size=(37, 1))
        if n:
            X[rng.integers(37, size=5), rng.integers(n, size=5)] = [np.nan, np.inf, -np.inf, -0.0, 0.0]
        blocks += [X, np.asfortranarray(X), X.astype(">f8"), np.repeat(X, 2, axis=0)[::2]]
    for X in blocks:
        with np.errstate(all="ignore"):
            want = np.abs(X).max(axis=1, initial=0.0)
            got = row_abs_max(X)
        assert got.shape == want.shape and np.array_equal(got, want, equal_nan=True), X


def test_row_all_and_row_finite_are_numpys_answers():
    """``M.all(axis=1)`` and ``np.isfinite(X).all(axis=1)`` row by row, every width up to past :data:`ROW_COLUMNS`
    (no entries: ``True``), on random masks, the special values and strided/Fortran layouts."""
    rng = np.random.default_rng(13)
    for n in range(0, ROW_COLUMNS + 4):
        for p in (0.5, 0.9, 1.0):
            M = rng.random((41, n)) < p
            for m in (M, np.asfortranarray(M), np.repeat(M, 2, axis=0)[::2]):
                assert np.array_equal(row_all(m), m.all(axis=1)), m
        X = rng.choice(np.array(_SPECIAL), size=(41, n))
        for x in (X, np.asfortranarray(X), X.astype(">f8")):
            assert np.array_equal(row_finite(x), np.isfinite(x).all(axis=1)), x
