"""NumPy's least squares and singular values on small real matrices without ``np.linalg``'s wrappers.

The one-step, selection and projection problems of a complementarity system are 2×2 to 8×8; on them the wrappers
of ``np.linalg.lstsq`` and ``np.linalg.svd`` (argument conversion, type resolution, result wrapping) cost as much
as LAPACK's work.  Each function here calls the gufunc its NumPy function calls, with the same arguments and the
same floating-point error handling, so its answer is that function's bit for bit and it raises the same
``LinAlgError``; any other input (another dtype, a stacked or empty array) goes to the NumPy function itself.
"""

from __future__ import annotations

import numpy as np

try:    # the gufuncs np.linalg.lstsq / np.linalg.svd call after their argument handling (NumPy 1.x and 2.x)
    try:
        from numpy.linalg import _umath_linalg
        from numpy.linalg._linalg import (_raise_linalgerror_eigenvalues_nonconvergence, _raise_linalgerror_lstsq,
                                          _raise_linalgerror_svd_nonconvergence)
    except ImportError:     # pragma: no cover - NumPy 1.x layout
        from numpy.linalg import _umath_linalg
        from numpy.linalg.linalg import (_raise_linalgerror_eigenvalues_nonconvergence, _raise_linalgerror_lstsq,
                                         _raise_linalgerror_svd_nonconvergence)
except ImportError:     # pragma: no cover - another NumPy layout: the public functions
    _umath_linalg = None

_EPS = float(np.finfo(np.float64).eps)


def _plain(a: np.ndarray) -> bool:
    return _umath_linalg is not None and type(a) is np.ndarray and a.dtype == np.float64


def lstsq_solution(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.linalg.lstsq(a, b, rcond=None)[0]`` for a ``float64`` matrix ``a`` (``m×n``, ``m, n ≥ 1``) and vector
    ``b`` (``m``): the same gufunc, ``rcond = ε·max(m, n)``, the same error state."""
    if not (_plain(a) and _plain(b) and a.ndim == 2 and b.ndim == 1 and a.shape[0] == b.shape[0]
            and 0 not in a.shape):
        return np.linalg.lstsq(a, b, rcond=None)[0]
    m, n = a.shape
    with np.errstate(call=_raise_linalgerror_lstsq, invalid="call", over="ignore", divide="ignore", under="ignore"):
        x = _umath_linalg.lstsq(a, b[:, None], _EPS * max(n, m), signature="ddd->ddid")[0]
    return x[:, 0].copy()


def svd_reduced(a: np.ndarray):
    """``np.linalg.svd(a, full_matrices=False)`` as ``(u, s, vh)`` for a ``float64`` matrix."""
    if not (_plain(a) and a.ndim == 2):
        return tuple(np.linalg.svd(a, full_matrices=False))
    with np.errstate(call=_raise_linalgerror_svd_nonconvergence, invalid="call", over="ignore", divide="ignore",
                     under="ignore"):
        return _umath_linalg.svd_s(a, signature="d->ddd")


def singular_values(a: np.ndarray) -> np.ndarray:
    """``np.linalg.svd(a, compute_uv=False)`` for a ``float64`` matrix."""
    if not (_plain(a) and a.ndim == 2):
        return np.linalg.svd(a, compute_uv=False)
    with np.errstate(call=_raise_linalgerror_svd_nonconvergence, invalid="call", over="ignore", divide="ignore",
                     under="ignore"):
        return _umath_linalg.svd(a, signature="d->d")


def eigvalsh_values(a: np.ndarray) -> np.ndarray:
    """``np.linalg.eigvalsh(a)`` (``UPLO="L"``) for a square ``float64`` matrix: the same gufunc under the same error
    state, without the wrapper (its checks cost more than LAPACK's work on a 2×2; branch units9)."""
    if not (_plain(a) and a.ndim == 2 and a.shape[0] == a.shape[1] and a.size):
        return np.linalg.eigvalsh(a)
    with np.errstate(call=_raise_linalgerror_eigenvalues_nonconvergence, invalid="call", over="ignore",
                     divide="ignore", under="ignore"):
        return _umath_linalg.eigvalsh_lo(a, signature="d->d")


def absmax(a) -> float:
    """``float(np.abs(a).max(initial=0.0))`` — NaN when an entry is NaN, as NumPy's — in Python floats for the
    arrays of at most :data:`SMALL` entries a small LCP or QP is made of (the exact same value: ``abs`` and
    ``max`` round nothing), NumPy's own reduction otherwise."""
    if a.size > SMALL:
        return float(np.abs(a).max(initial=0.0))
    m = 0.0
    for v in a.ravel().tolist():
        v = abs(v)
        if v > m:
            m = v
        elif v != v:
            return float("nan")
    return float(m)


#: arrays up to this many entries are reduced in Python floats by :func:`absmax`
SMALL = 32

__all__ = ["lstsq_solution", "svd_reduced", "singular_values", "absmax"]
