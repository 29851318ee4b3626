"""A design's samples as one block of arrays: points ``x1, x2`` ``(B, n)``, step sizes ``λ, μ, ν`` and times ``t``
``(B,)``, one input form — the list of :class:`~verimono.checks.engine.samples.Sample` it stands for, made lazily.

A list the search knows in advance (a coordinate's design, the step decades) is evaluated first by the law's
vectorised form over all its rows at once (:meth:`verimono.checks.engine.search._Search.evaluate_many`,
:class:`verimono.checks.engine.batches.Rows`), which reads the block's arrays as they are; only a row the law's own
evaluator must see (one the form did not accept, the worst, the failing one, the record's counterexample) is made a
:class:`Sample` — ``block[i]``, built once and kept, so the same row is the same object every time it is asked for.
A sample made from a block is field for field the sample the one-point code makes (:func:`~.samples.with_field` of
the design's start): the same float64 numbers (a Python ``float`` of each), its points a row of the block's arrays
or, where the design moves no point, the start's own arrays.  A block is a read-only sequence of samples:
``len``, indexing, slicing (a block over the same arrays and the same made samples) and iteration (which makes
every sample: the one-point path's cost).
"""

from __future__ import annotations

from typing import Any, Iterator, Sequence

import numpy as np

from .samples import Sample


#: the fields a block's rows share when every field is the row's own (:meth:`SampleBlock.drawn`)
_PLAIN = Sample(np.zeros(0), np.zeros(0), 1.0, 1.0, 1.0, 0.0)


def stack_fields(samples: Sequence[Sample]) -> tuple[np.ndarray, ...]:
    """``x1``, ``x2`` ``(B, n)`` and ``λ, μ, ν, t`` ``(B,)`` of a list of samples, stacked row by row: ``np.array`` of
    the points (not ``np.stack``: ~4x its cost per row here, the same numbers; a ragged list raises alike) and the
    four numbers of every sample in one pass (the same float64s as one array per field)."""
    x1 = np.array([s.x1 for s in samples], dtype=float)
    x2 = np.array([s.x2 for s in samples], dtype=float)
    if len(samples):
        lam, mu, nu, t = np.array([(s.lam, s.mu, s.nu, s.t) for s in samples], dtype=float).T.copy()
    else:
        lam, mu, nu, t = (np.zeros(0) for _ in range(4))
    return x1, x2, lam, mu, nu, t


class SampleBlock:
    """Samples ``(x1[i], x2[i], lam[i], mu[i], nu[i], t[i])``, ``i < B``, in ``form`` (module docstring).

    ``proto`` is the sample whose fields every row shares but those named in ``varies``: a made row is ``proto``'s
    fields (the same objects) with those set from its row — a point as a view of row ``i`` of ``x1``, ``x2``, a
    number as a Python ``float`` (``owned``: a point as a copy of its row, an array of its own, as the seeded draws
    give each sample: their arrays are shared by every law of a battery).  A design over ``λ, μ, ν`` or ``t`` varies that field only (``x1``, ``x2`` are
    then ``proto``'s broadcast to ``(B, n)``, read-only views; its rows keep ``proto``'s own point arrays)."""

    __slots__ = ("x1", "x2", "lam", "mu", "nu", "t", "form", "proto", "varies", "owned", "_made", "_off", "_len")

    def __init__(self, proto: Sample, x1: np.ndarray, x2: np.ndarray, lam: np.ndarray, mu: np.ndarray,
                 nu: np.ndarray, t: np.ndarray, varies: tuple = ("x1", "x2", "lam", "mu", "nu", "t"),
                 made: dict | None = None, off: int = 0, owned: bool = False) -> None:
        self.x1, self.x2, self.lam, self.mu, self.nu, self.t = x1, x2, lam, mu, nu, t
        self.proto, self.form, self.varies, self.owned = proto, proto.form, varies, owned
        self._made = {} if made is None else made       # absolute row -> its Sample (shared by slices)
        self._off, self._len = off, int(lam.shape[0])

    # -- construction -------------------------------------------------------------------------------------------
    @classmethod
    def along(cls, s: Sample, name: str, values: Sequence[float]) -> "SampleBlock":
        """The samples ``with_field(s, name, float(v))`` for ``v`` in ``values`` (``name``: ``lam``, ``mu``, ``nu``
        or ``t``): ``s``'s points in every row."""
        B = len(values)
        col = {k: np.full(B, float(getattr(s, k))) for k in ("lam", "mu", "nu", "t")}
        col[name] = np.array([float(v) for v in values], dtype=float)
        x1 = np.broadcast_to(np.asarray(s.x1, dtype=float), (B,) + np.shape(s.x1))
        x2 = np.broadcast_to(np.asarray(s.x2, dtype=float), (B,) + np.shape(s.x2))
        return cls(s, x1, x2, col["lam"], col["mu"], col["nu"], col["t"], varies=(name,))

    @classmethod
    def rows(cls, s: Sample, X1: np.ndarray, X2: np.ndarray) -> "SampleBlock":
        """The samples with ``s``'s step sizes, time and form and points the rows of ``X1``, ``X2`` ``(B, n)``."""
        B = X1.shape[0]
        return cls(s, X1, X2, np.full(B, float(s.lam)), np.full(B, float(s.mu)), np.full(B, float(s.nu)),
                   np.full(B, float(s.t)), varies=("x1", "x2"))

    @classmethod
    def drawn(cls, X1: np.ndarray, X2: np.ndarray, steps: np.ndarray, t: np.ndarray) -> "SampleBlock":
        """The samples ``Sample(X1[i].copy(), X2[i].copy(), *steps[i], t[i])`` of seeded draws ``(X1, X2, steps, t)``
        (:mod:`.sweep`), contiguous; the arrays are read as they are (read-only: the draws are cached)."""
        return cls(_PLAIN, X1, X2, steps[:, 0], steps[:, 1], steps[:, 2], t, owned=True)

    @classmethod
    def stacked(cls, samples: Sequence[Sample]) -> "SampleBlock":
        """A block of the given samples (their fields stacked, :func:`stack_fields`); ``block[i]`` is ``samples[i]``
        itself.  Its form is the first sample's (the caller gives samples of one form)."""
        return cls(samples[0] if len(samples) else _PLAIN, *stack_fields(samples), made=dict(enumerate(samples)))

    @staticmethod
    def joined(parts: Sequence["SampleBlock"]) -> "SampleBlock":
        """One block of the rows of ``parts``, in order, for a vectorised pass over all of them: read as arrays only
        (the search makes a row's sample from its part, never from this block)."""
        cat = lambda a: np.concatenate([getattr(p, a) for p in parts])     # noqa: E731
        return SampleBlock(parts[0].proto, cat("x1"), cat("x2"), cat("lam"), cat("mu"), cat("nu"), cat("t"))

    # -- the sequence of samples ------------------------------------------------------------------------------
    def __len__(self) -> int:
        return self._len

    def __bool__(self) -> bool:
        return self._len > 0

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            lo, hi, step = i.indices(self._len)
            if step != 1:
                return [self[k] for k in range(lo, hi, step)]
            hi = max(lo, hi)
            return SampleBlock(self.proto, self.x1[lo:hi], self.x2[lo:hi], self.lam[lo:hi], self.mu[lo:hi],
                               self.nu[lo:hi], self.t[lo:hi], self.varies, self._made, self._off + lo, self.owned)
        i = int(i)
        if i < 0:
            i += self._len
        if not 0 <= i < self._len:
            raise IndexError(i)
        got = self._made.get(self._off + i)
        if got is None:
            got = self._made[self._off + i] = self._make(i)
        return got

    def __iter__(self) -> Iterator[Sample]:
        return (self[i] for i in range(self._len))

    def _make(self, i: int) -> Sample:
        """Row ``i`` as a :class:`Sample`: ``proto``'s fields with this row's (the fields of ``with_field``)."""
        out = object.__new__(Sample)
        d = out.__dict__
        d.update(self.proto.__dict__)
        for k in self.varies:
            if k in ("x1", "x2"):
                d[k] = getattr(self, k)[i].copy() if self.owned else getattr(self, k)[i]
            else:
                d[k] = getattr(self, k)[i].item()
        return out

    def __repr__(self) -> str:
        return f"SampleBlock({self._len} rows of n = {self.x1.shape[-1] if self.x1.ndim == 2 else 0}, form={self.form!r})"


def make_sample(x1: np.ndarray, x2: np.ndarray, lam: float, mu: float, nu: float, t: float) -> Sample:
    """``Sample(x1, x2, lam, mu, nu, t)``, the ``make`` of the seeded lists (:func:`.sweep.edge_draws`,
    :func:`.sweep.sweep_samples`, :func:`.scales.scale_samples`); its ``block`` (:meth:`SampleBlock.drawn`) tells
    them to answer their rows as one block instead of a list."""
    return Sample(x1, x2, lam, mu, nu, t)


make_sample.block = SampleBlock.drawn       # type: ignore[attr-defined]

__all__ = ["SampleBlock", "make_sample", "stack_fields"]
