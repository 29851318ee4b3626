"""Batched evaluation of a batched subject: a prox (or resolvent) declared ``batched=True`` maps points
``(B, n)`` with steps and times ``(B,)`` at once (``jax.vmap``, ``torch.vmap``, vectorised NumPy), so the
search hands it the points of a whole list of samples in a few calls instead of one call per point.

Before a phase of the search that knows its samples in advance — the NumPy draws and the scale sweep
(:mod:`verimono.checks.search`) — :func:`prefetched` evaluates ``J_λ``, ``J_μ``, ``J_ν`` at ``x1`` and ``x2``
of every sample, at the sample's time, by :meth:`resolvent_batch` in batches of **varied sizes**
(:func:`batch_sizes`: 1, 2, 3, ... up to the largest, odd ones included, every divisor of the dimension — the
width of an image whose prox broadcasts a per-row step against it — and the rest in one batch), unpadded, so
that a prox wrong or raising at one batch size meets it.  A declared batched call that raises is a failure
of the subject (:class:`_BatchFailure`, reported by the search with the batch size), never a fall-back to
single rows.  The laws then call ``op.resolvent`` as always; a call at a prefetched ``(x, λ, t)`` gets the
batched value **once** — a second call at the same point evaluates the prox again (a batch of one), so
``resolvent_single_valued`` compares the batched value with a single call (a prox whose batched and single
results differ at some batch size, or that is not deterministic, is caught), and an input-mutating prox
still meets its own input.  Points the laws derive from other values (``J_μ(J_λ x)``, perturbations) are
evaluated one call each.  The hypothesis phase draws its samples one at a time: there each sample's points
are evaluated as they come (a batch of one).
"""

from __future__ import annotations

import contextlib
from typing import Any, Iterator, Sequence

import numpy as np

from ...core.arrays import MAX_BATCH
from ...core.arrays import prefetch_key as key

#: the leading batch sizes, every one (then the divisors of the dimension, then the rest in one batch)
SMALL_BATCHES = 8


class _BatchFailure(Exception):
    """A declared batched call raised: a failure of the subject, with the batch size and the first sample
    whose points the batch held."""

    def __init__(self, exc: BaseException, size: int, sample: Any, sizes: list[int]) -> None:
        super().__init__(f"the batched resolvent raised {type(exc).__name__}: {exc} on a batch of {size} row(s) "
                         f"(batch sizes tried: {sizes}); it is declared batched=True, so every batch size must "
                         "work")
        self.exc, self.size, self.sample, self.sizes = exc, size, sample, sizes


def batched(op: Any) -> bool:
    """Whether ``op`` takes batches (declared ``batched=True``) and can hold prefetched values."""
    return bool(getattr(op, "batched", False)) and hasattr(op, "resolvent_batch") and hasattr(op, "_prefetched")


def batch_sizes(rows: int, dim: int) -> list[int]:
    """Sizes of consecutive batches covering ``rows`` rows: ``1, ..., SMALL_BATCHES``, then every divisor of
    ``dim`` above that (in increasing order), then the rest in batches of at most ``MAX_BATCH``."""
    wanted = list(range(1, SMALL_BATCHES + 1)) + [d for d in range(SMALL_BATCHES + 1, min(dim, MAX_BATCH) + 1)
                                                  if dim % d == 0]
    out, left = [], rows
    for b in wanted:
        if left <= 0:
            break
        out.append(min(b, left))
        left -= out[-1]
    while left > 0:
        out.append(min(MAX_BATCH, left))
        left -= out[-1]
    return out


@contextlib.contextmanager
def prefetched(op: Any, samples: Sequence[Any]) -> Iterator[int]:
    """Within the block, the resolvents at the points of ``samples`` come from batched calls of the sizes of
    :func:`batch_sizes` (module docstring); yields the number of rows evaluated (0 when ``op`` is not
    batched).  Raises :class:`_BatchFailure` when a batched call raises."""
    if not batched(op) or not samples:
        yield 0
        return
    rows: dict[tuple, tuple[np.ndarray, float, float]] = {}
    owner: dict[tuple, Any] = {}
    for s in samples:
        for x in (s.x1, s.x2):
            for lam in (s.lam, s.mu, s.nu):
                k = key(x, lam, s.t)
                rows.setdefault(k, (x, lam, s.t))
                owner.setdefault(k, s)
    keys = list(rows)
    X = np.stack([rows[k][0] for k in keys])
    lams = np.array([rows[k][1] for k in keys], dtype=float)
    ts = np.array([rows[k][2] for k in keys], dtype=float)
    sizes = batch_sizes(len(keys), int(op.dim))
    J = np.empty_like(X)
    lo = 0
    for b in sizes:
        try:
            J[lo:lo + b] = op.resolvent_batch(X[lo:lo + b], lams[lo:lo + b], ts[lo:lo + b], pad=False)
        except Exception as exc:  # noqa: BLE001 - a declared batched call that raised: the subject fails
            raise _BatchFailure(exc, b, owner[keys[lo]], sizes) from exc
        lo += b
    op._prefetched = {k: J[i] for i, k in enumerate(keys)}
    try:
        yield len(keys)
    finally:
        op._prefetched = None


__all__ = ["prefetched", "batched", "batch_sizes", "_BatchFailure", "SMALL_BATCHES"]
