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


__all__ = ["abs_max", "all_finite", "SMALL"]
