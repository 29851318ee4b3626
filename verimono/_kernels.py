"""Shared arithmetic of the catalog's fast per-step kernels (operators and sets).

Row-wise inner products and norms are computed as the BLAS ``dot`` of each row, so a batch ``(B, n)``
and its rows one by one give bit-identical results; the short aliases avoid attribute look-ups in the
per-step loop.
"""

from __future__ import annotations

import math

import numpy as np

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


def bad_lam(lam: object, who: str) -> InvalidProblem:
    """The error for a step size ``λ`` that is not a finite positive number (``J_λ`` is defined for
    ``λ > 0`` only: ``λ = 0`` is the identity, whose Yosida value ``0/0`` is NaN, and ``λ < 0`` inverts a
    non-monotone ``I + λF``)."""
    return InvalidProblem(f"{who}: the step size λ must be a finite number > 0, got {lam!r}")


def check_lam(lam: object, who: str) -> float:
    """``lam`` as a float after checking ``0 < λ < ∞`` (:func:`bad_lam` otherwise)."""
    if isinstance(lam, complex) or isinstance(lam, np.complexfloating):
        raise bad_lam(lam, who)
    try:
        v = float(lam)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise bad_lam(lam, who) from None
    if not 0.0 < v < _INF:
        raise bad_lam(lam, who)
    return v


def real_array(x: object, what: str = "point") -> np.ndarray:
    """``x`` as a float64 array; :class:`InvalidProblem` for complex values (``np.asarray(z, float)`` would
    silently drop the imaginary part) or non-numeric ones.  A float64 array is returned as it is."""
    if type(x) is np.ndarray and x.dtype == np.float64:
        return x
    a = np.asarray(x)
    if a.dtype.kind == "c":
        raise InvalidProblem(f"{what} must be real, got complex values {x!r:.80}")
    try:
        return a.astype(float, copy=False)
    except (TypeError, ValueError) as exc:
        raise InvalidProblem(f"{what} must be numeric: {exc}") from None


def finite_point(x: object, what: str) -> np.ndarray:
    """:func:`real_array` and every entry finite (a projection of a NaN point has no meaning)."""
    a = real_array(x, what)
    if not np.isfinite(a).all():
        raise InvalidProblem(f"{what} must be finite, got {np.array2string(a, threshold=8)}")
    return a


def bad_param(owner: str, what: str, value: object, t: float, need: str, cls: type = InvalidProblem) -> Exception:
    """The error for a time-dependent parameter invalid at time ``t`` (the failing ``t`` in the message)."""
    v = np.array2string(np.asarray(value), threshold=8) if not isinstance(value, float) else f"{value:g}"
    return cls(f"{owner}: {what} = {v} at t = {t!r}: {need}")


def batch_column(p: np.ndarray, x: np.ndarray, what: str) -> np.ndarray:
    """A per-operator scalar parameter ``p`` shaped to broadcast against the rows of ``x``.

    A scalar is returned as is; a batch ``(B,)`` — one value per operator of a batch — applies row by row
    and needs points of shape ``(B, n)``: anything else would broadcast silently (``(B,)`` against a
    point ``(n,)`` with ``B = n`` mixes operators and coordinates), so it is an :class:`InvalidProblem`.
    """
    if p.ndim == 0:
        return p
    if x.ndim != 2 or x.shape[0] != p.shape[0]:
        raise InvalidProblem(f"{what} is a batch of {p.shape[0]} values (one per operator): it applies to "
                             f"points of shape ({p.shape[0]}, n), got a point of shape {x.shape}")
    return p[:, None]
