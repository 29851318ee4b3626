"""Batched evaluation of a batched subject: a prox (or resolvent) declared ``batched=True`` maps points
``(B, n)`` with steps and times ``(B,)`` at once (``jax.vmap``, ``torch.vmap``, vectorised NumPy), so the
search hands it the points of a whole list of samples in one call instead of one call per point.

Before a phase of the search that knows its samples in advance — the NumPy draws and the scale sweep
(:mod:`verimono.checks.search`) — :func:`prefetched` evaluates ``J_λ``, ``J_μ``, ``J_ν`` at ``x1`` and ``x2``
of every sample, at the sample's time, by :meth:`resolvent_batch` (chunks of at most
:data:`verimono.core.arrays.MAX_BATCH` rows, padded to a power of two so that a jitted prox compiles for a few
shapes only).  The laws then call ``op.resolvent`` as always; a call at a prefetched ``(x, λ, t)`` gets the
batched value **once** — a second call at the same point evaluates the prox again, so
``resolvent_single_valued`` compares the batched value with a single call (a prox whose batched and
single results differ, or that is not deterministic, is still caught), and an input-mutating prox still
meets its own input.  Points the laws derive from other values (``J_μ(J_λ x)``, perturbations) are
evaluated one call each.  The hypothesis phase draws its samples one at a time: there each sample's points
are evaluated as they come (a batch of one).
"""

from __future__ import annotations

import contextlib
from typing import Any, Iterator, Sequence

import numpy as np

from ..core.arrays import prefetch_key as key


def batched(op: Any) -> bool:
    """Whether ``op`` takes batches (declared ``batched=True``) and can hold prefetched values."""
    return bool(getattr(op, "batched", False)) and hasattr(op, "resolvent_batch") and hasattr(op, "_prefetched")


@contextlib.contextmanager
def prefetched(op: Any, samples: Sequence[Any]) -> Iterator[int]:
    """Within the block, the resolvents at the points of ``samples`` come from batched calls (module
    docstring); yields the number of rows evaluated (0 when ``op`` is not batched, or when the batched call
    raised — the samples then meet the exception one by one, judged by the search's policy)."""
    if not batched(op) or not samples:
        yield 0
        return
    rows: dict[tuple, tuple[np.ndarray, float, float]] = {}
    for s in samples:
        for x in (s.x1, s.x2):
            for lam in (s.lam, s.mu, s.nu):
                rows.setdefault(key(x, lam, s.t), (x, lam, s.t))
    keys = list(rows)
    X = np.stack([rows[k][0] for k in keys])
    lams = np.array([rows[k][1] for k in keys], dtype=float)
    ts = np.array([rows[k][2] for k in keys], dtype=float)
    try:
        J = op.resolvent_batch(X, lams, ts)
    except Exception:  # noqa: BLE001 - evaluated again sample by sample, where the policy judges it
        yield 0
        return
    op._prefetched = {k: J[i] for i, k in enumerate(keys)}
    try:
        yield len(keys)
    finally:
        op._prefetched = None


__all__ = ["prefetched", "batched"]
