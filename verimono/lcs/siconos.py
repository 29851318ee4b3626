"""Readers for Siconos reference data, and where those data live.

The data ship with the package in ``verimono/data/siconos`` (:data:`PACKAGED_DATA`; their source, files
and conversion are in ``PROVENANCE.md`` there, the systems in ``CASES.md``).  A data folder holds
``siconos/refs/NAME.ref`` (or ``NAME.ref.gz``) and ``siconos/lcp/*.dat``, or is that ``siconos`` folder.

* ``.ref`` trajectories: an optional header line ``"N ncols"``, then ``N`` rows of numbers
  (row ``k`` is ``t = k h``).
* ``.dat`` LCP test problems of Siconos numerics: ``n``; the storage type (0 dense, 1 sparse block);
  the matrix sizes; the matrix; then ``q`` (``n`` values), optionally followed by comments.
  Dense matrices repeat the sizes and are stored **column-major**; sparse-block matrices follow
  ``SBM_write_in_file``: number of blocks, block rows/columns, cumulative block sizes, the CSR-like
  ``index1``/``index2`` arrays, then each block as its index followed by its entries, column-major.
"""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np

from ..core.errors import InvalidProblem

#: the data folder shipped with verimono (holds ``siconos/``): the default of ``verimono run``'s siconos stage
PACKAGED_DATA = Path(__file__).resolve().parents[1] / "data"


def siconos_root(data_dir) -> Path:
    """The folder holding ``refs/`` and ``lcp/`` in ``data_dir`` (``data_dir/siconos`` or ``data_dir``
    itself); :class:`FileNotFoundError` naming the expected layout when neither holds them."""
    data_dir = Path(data_dir)
    for root in (data_dir / "siconos", data_dir):
        if (root / "refs").is_dir() and (root / "lcp").is_dir():
            return root
    raise FileNotFoundError(f"{data_dir} holds no Siconos reference data (expected siconos/refs/*.ref[.gz] "
                            "and siconos/lcp/*.dat, as in verimono/data)")


def ref_path(root, name: str) -> Path:
    """``root/refs/name``, or its gzipped copy ``name.gz`` when only that exists (``root``: a
    :func:`siconos_root`)."""
    path = Path(root) / "refs" / name
    gz = path.with_name(path.name + ".gz")
    return gz if not path.exists() and gz.exists() else path


def _read_text(path) -> str:
    """The text of ``path``, decompressed when its name ends in ``.gz``."""
    path = Path(path)
    if path.suffix == ".gz":
        with gzip.open(path, "rt", encoding="utf-8") as f:
            return f.read()
    return path.read_text()


def read_ref(path) -> np.ndarray:
    """Rows of a Siconos ``.ref`` file (or ``.ref.gz``) as an array ``(N, ncols)``; the header
    ``"N ncols"`` is checked."""
    lines = [ln.split() for ln in _read_text(path).splitlines() if ln.strip()]
    if not lines:
        raise InvalidProblem(f"{path} is empty")
    header = None
    if len(lines[0]) == 2 and len(lines) > 1 and len(lines[1]) != 2:
        header = (int(lines[0][0]), int(lines[0][1]))
        lines = lines[1:]
    data = np.array([[float(v) for v in ln] for ln in lines])
    if header is not None and data.shape != header:
        raise InvalidProblem(f"{path}: header says {header} but the file holds {data.shape}")
    return data


class _Tokens:
    def __init__(self, text: str, where) -> None:
        self.t, self.i, self.where = text.split(), 0, where

    def next(self, kind=float):
        if self.i >= len(self.t):
            raise InvalidProblem(f"{self.where}: unexpected end of file")
        v = self.t[self.i]
        self.i += 1
        try:
            return kind(v)
        except ValueError:
            raise InvalidProblem(f"{self.where}: expected a {kind.__name__}, got {v!r}") from None

    def many(self, k, kind=float):
        return [self.next(kind) for _ in range(k)]


def read_lcp(path) -> tuple[np.ndarray, np.ndarray]:
    """``(M, q)`` of a Siconos numerics LCP ``.dat`` file, or ``.dat.gz`` (dense column-major or sparse-block
    storage)."""
    tok = _Tokens(_read_text(path), path)
    n = tok.next(int)
    storage = tok.next(int)
    size0, size1 = tok.next(int), tok.next(int)
    if (size0, size1) != (n, n):
        raise InvalidProblem(f"{path}: matrix is {size0}x{size1} for an LCP of size {n}")
    if storage == 0:
        if tuple(tok.many(2, int)) != (n, n):
            raise InvalidProblem(f"{path}: dense block sizes disagree with n = {n}")
        M = np.array(tok.many(n * n)).reshape(n, n).T  # each text line is a column
    elif storage == 1:
        M = _read_sbm(tok, n)
    else:
        raise InvalidProblem(f"{path}: unknown storage type {storage} (expected 0 dense or 1 sparse block)")
    q = np.array(tok.many(n))
    return M, q


def _read_sbm(tok: _Tokens, n: int) -> np.ndarray:
    M = np.zeros((n, n))
    nbblocks = tok.next(int)
    if nbblocks == 0:
        return M
    nb0, nb1 = tok.next(int), tok.next(int)
    rows_end = tok.many(nb0, int)   # cumulative block sizes
    cols_end = tok.many(nb1, int)
    filled1, filled2 = tok.next(int), tok.next(int)
    index1 = tok.many(filled1, int)
    index2 = tok.many(filled2, int)
    if rows_end[-1] != n or cols_end[-1] != n or filled2 != nbblocks:
        raise InvalidProblem(f"{tok.where}: inconsistent sparse-block structure")
    for bi in range(filled1 - 1):
        r0 = 0 if bi == 0 else rows_end[bi - 1]
        for j in range(index1[bi], index1[bi + 1]):
            if tok.next(int) != j:
                raise InvalidProblem(f"{tok.where}: block {j} is out of order")
            bj = index2[j]
            c0 = 0 if bj == 0 else cols_end[bj - 1]
            nr, nc = rows_end[bi] - r0, cols_end[bj] - c0
            M[r0:r0 + nr, c0:c0 + nc] = np.array(tok.many(nr * nc)).reshape(nc, nr).T
    return M


__all__ = ["PACKAGED_DATA", "siconos_root", "ref_path", "read_ref", "read_lcp"]
