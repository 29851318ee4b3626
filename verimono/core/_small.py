"""``max |v_i|`` and "every entry finite" of a small float point in Python floats (issue 43, branch units10).

The operator laws read both of every point they see (``tolerance``, ``members.norm``, ``members.point``, the
search's ``|x|`` range): ~100,000 calls in the operator_laws stage, at R^1–R^4, where NumPy's per-call cost
(``np.abs`` then ``ndarray.max``'s wrapper and reduction, ~1.5 µs) is the whole of it.  For a 1-D float64 or
float32 array of at most :data:`SMALL` entries the same numbers come from the entries as Python floats (each the
exact double of the entry): ``abs`` is exact, the maximum is a selection (no rounding), NaN propagates as
``ndarray.max`` propagates it, and ``-0.0`` gives ``0.0`` as ``np.abs`` does.  Any other array takes NumPy's path."""

from __future__ import annotations

import math

import numpy as np

#: at most this many entries are read in Python floats
SMALL = 8
_NAN = math.nan
_INF = math.inf


def abs_max(v: np.ndarray) -> float:
    """``float(np.abs(v).max())`` of a non-empty array ``v``."""
    if v.ndim == 1 and v.size <= SMALL and v.dtype.char in "df":
        m, nan = 0.0, False
        for e in v.tolist():
            e = abs(e)
            if e > m:
                m = e
            elif e != e:
                nan = True
        return _NAN if nan else m
    return float(np.abs(v).max())


def all_finite(v: np.ndarray) -> bool:
    """``bool(np.isfinite(v).all())`` of an array ``v`` of a real dtype."""
    if v.ndim == 1 and v.size <= SMALL and v.dtype.char in "df":
        for e in v.tolist():
            if not -_INF < e < _INF:       # NaN fails both
                return False
        return True
    return bool(np.isfinite(v).all())


#: rows of at most this many entries get their maxima column by column (:func:`row_abs_max`)
ROW_COLUMNS = 4


def row_abs_max(X: np.ndarray) -> np.ndarray:
    """``np.abs(X).max(axis=1, initial=0.0)`` of a 2-D array ``X`` (the largest ``|X_ij|`` of every row, 0 for a row
    of no entries, NaN where a row holds one).  NumPy reduces along a short last axis one row at a time: at
    ``(1000, 3)`` that reduction costs ~40–80 µs against ~6 µs for the same selection made column by column —
    ``np.maximum`` of the columns of ``|X|``, elementwise over all rows at once — so rows of at most
    :data:`ROW_COLUMNS` entries take that path (wider rows ``max(max X_i, -min X_i, 0)``, without a copy).  The
    numbers are the same: a maximum is a selection (no rounding), ``np.maximum`` propagates NaN as the reduction
    does, and ``|X| ≥ 0`` makes the initial 0 a no-op (a row of ``-0.0`` may give ``-0.0`` for ``0.0`` on the wide
    path: equal as numbers)."""
    k, n = X.shape
    if n == 0:
        return np.zeros(k)
    if n > ROW_COLUMNS:      # max(max, -min, 0): the same numbers, without a |X| copy of a wide array
        return np.maximum(np.maximum(X.max(axis=1), -X.min(axis=1)), 0.0)
    a = np.abs(X)
    out = a[:, 0].copy()
    for j in range(1, n):
        np.maximum(out, a[:, j], out=out)
    return out


def row_all(M: np.ndarray) -> np.ndarray:
    """``M.all(axis=1)`` of a 2-D boolean array (``True`` for a row of no entries): the columns' ``&`` for rows of at
    most :data:`ROW_COLUMNS` entries (the short-axis reduction's cost, as in :func:`row_abs_max`: 38 µs at
    ``(1000, 3)`` against 6 µs), the reduction otherwise.  The same booleans."""
    k, n = M.shape
    if n == 0 or n > ROW_COLUMNS:
        return M.all(axis=1)
    out = M[:, 0].copy()
    for j in range(1, n):
        np.logical_and(out, M[:, j], out=out)
    return out


def row_finite(X: np.ndarray) -> np.ndarray:
    """Whether every entry of each row of the 2-D array ``X`` is finite (``np.isfinite(X).all(axis=1)``)."""
    return row_all(np.isfinite(X))


__all__ = ["abs_max", "all_finite", "row_abs_max", "row_all", "row_finite", "SMALL", "ROW_COLUMNS"]
