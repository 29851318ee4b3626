"""Row arithmetic of the catalog's fast per-step kernels (operators and sets).

Row-wise inner products and norms are computed as the BLAS ``dot`` of each row, so a batch ``(B, n)``
and its rows one by one give bit-identical results; the short aliases avoid attribute look-ups in the
per-step loop.
"""

from __future__ import annotations

import math

import numpy as np

from ._validate import bad_lam
from .errors import InvalidProblem

_ar = np.add.reduce
_mx, _mn = np.maximum, np.minimum
_sqrt = math.sqrt
#: the smallest positive double: ``max(r, _TINY) == r`` for every ``r > 0``, and ``0/_TINY == 0``
_TINY = float(np.finfo(float).smallest_subnormal)


if hasattr(np, "vecdot"):  # numpy >= 2
    def dot_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Row-wise inner products over the last axis: the BLAS ``dot`` of each row, i.e. exactly
        ``a_row.dot(b_row)`` for every row whatever the batch shape (batch ≡ separate, bit for bit)."""
        return np.vecdot(a, b)
else:  # pragma: no cover - numpy 1.x: a stack of (1, n) @ (n, 1) products, one BLAS dot per row
    def dot_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        a, b = np.broadcast_arrays(a, b)
        return np.matmul(a[..., None, :], b[..., :, None])[..., 0, 0]


def _norm(x: np.ndarray) -> np.ndarray:
    """Euclidean norm over the last axis, keeping it (works for (n,) and (B, n)).

    Each row's squared norm is the BLAS dot of the row with itself (:func:`dot_rows`), exactly the
    ``x.dot(x)`` of the single-point kernels, so a batch and its rows one by one give identical norms.
    """
    return np.sqrt(dot_rows(x, x))[..., None]

_INF = math.inf


def times_of(t, x: np.ndarray, who: str) -> np.ndarray | None:
    """``t`` as a time per row of ``x`` when it is an array of shape ``(B,)`` (``x`` then ``(B, n)``), else
    ``None`` (one time for every row: the ordinary call).  A one-point call (``x`` of shape ``(n,)``) with a
    length-1 array ``t`` is the ordinary call too, as it was before times per row existed (``t`` broadcasts)."""
    if type(t) is not np.ndarray or t.ndim != 1 or (t.shape[0] == 1 and np.ndim(x) == 1):
        return None
    if np.ndim(x) != 2 or np.shape(x)[0] != t.shape[0]:
        raise InvalidProblem(f"{who}: a time per row needs points of shape ({t.shape[0]}, n), got {np.shape(x)}")
    return t.astype(float, copy=False)


def per_row(fn, x: np.ndarray, ts: np.ndarray) -> np.ndarray:
    """``fn(x_i, t_i)`` of every row, stacked: what a member that does not take a time per row is called as."""
    return np.array([np.asarray(fn(xi, ti), dtype=float) for xi, ti in zip(x, ts.tolist())]).reshape(np.shape(x))


def steps_of(lam, x: np.ndarray, who: str) -> np.ndarray | None:
    """``lam`` as a step size per row of ``x`` when it is an array of shape ``(B,)`` (``x`` then ``(B, n)``), each
    checked ``0 < λ < ∞`` as a separate call checks its own (the first bad one named, as that call would), else
    ``None`` (one step for every row: the ordinary call; so is a one-point call with a length-1 array ``lam``, as
    for :func:`times_of`)."""
    if type(lam) is not np.ndarray or lam.ndim != 1 or (lam.shape[0] == 1 and np.ndim(x) == 1):
        return None
    if np.ndim(x) != 2 or np.shape(x)[0] != lam.shape[0]:
        raise InvalidProblem(f"{who}: a step size per row needs points of shape ({lam.shape[0]}, n), got {np.shape(x)}")
    ls = lam.astype(float, copy=False)
    good = (ls > 0.0) & (ls < _INF)        # NaN fails both
    if not good.all():
        raise bad_lam(ls.tolist()[int(np.argmin(good))], who)
    return ls


def per_row_steps(fn, x: np.ndarray, ls: np.ndarray, t) -> np.ndarray:
    """``fn(x_i, λ_i, t_i)`` of every row (``t`` one time for all rows, or ``(B,)`` a time per row), stacked: what a
    member that does not take a step size per row is called as (a float ``λ`` and a float ``t`` each call)."""
    ts = t.tolist() if type(t) is np.ndarray and t.ndim == 1 else [t] * len(ls)
    return np.array([np.asarray(fn(xi, li, ti), dtype=float)
                     for xi, li, ti in zip(x, ls.tolist(), ts)]).reshape(np.shape(x))


__all__ = ["dot_rows"]
