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
import time
from typing import Any, Iterator, Sequence

import numpy as np

from ...core.arrays import MAX_BATCH, as_float64
from ...core._small import row_abs_max, row_all, row_finite
from ...core.operator_protocol import accepts_steps, accepts_times
from ...execution.timeouts import interrupted
from ...core.arrays import prefetch_key as key
from .blocks import SampleBlock, stack_fields

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


# -- vectorised law arithmetic over many samples ---------------------------------------------------------
# A law may state, besides its evaluator of one sample, a **vectorised** form ``fn(op, rows) -> ratios``
# (:func:`vectorised`): the same inequality over the rows of :class:`Rows` (the samples' points stacked ``(B, n)``,
# their step sizes and times ``(B,)``), its resolvents from :func:`row_resolvents` — one call per distinct
# ``(λ, t)`` when the operator maps batches row by row (``_accepts_batches``: the catalog's, bit-identical to
# separate calls), else one call per row — and its arithmetic over all rows at once.  The search
# (:meth:`verimono.checks.engine.search._Search.evaluate_many`) accepts a row's vectorised ratio only when it is
# finite and at most :data:`SUSPECT`; every other row (a call that raised or returned no finite point of the
# input's shape, a ratio near or above the bound, NaN) is evaluated again by the law's own evaluator, which alone
# decides a failure and writes the record's numbers.  The vectorised form therefore never fails a sample, and
# passes one only with a ratio at least ``1 - SUSPECT`` inside the bound (far beyond the rounding differences of
# row-wise sums) — or, when the form states a bound on those differences (:func:`rounding`, ``Rows.err``), with
# the ratio plus that bound within the bound: the forms repeat the law's elementwise operations (bit-identical in
# IEEE arithmetic; the catalog's batched resolvents are bit-identical to separate calls), and only their sums —
# norms and dot products, reduced in another order — may differ, by at most a few ``n·eps`` of the summands.

#: law name → its vectorised form ``fn(op, rows) -> ratios (B,)`` (:func:`vectorised`)
VECTORISED: dict[str, Any] = {}
#: the laws whose vectorised form decides a row by the other rows of its pass (``yosida_limit``: the last row still
#: open goes to the evaluator), so that its rows are decided only in a pass of their own list (never prefetched with
#: other lists: :meth:`verimono.checks.engine.search._Search.prefetch`); every other form is computed row by row
PER_PASS = {"yosida_limit"}
#: a vectorised ratio above this (or not finite) is evaluated again by the law's evaluator of one sample
SUSPECT = 0.999
#: the most coordinates stacked in one vectorised evaluation (rows × n): bounds its memory at n = 10^6
ROW_CELLS = 1 << 20


def vectorised(name: str):
    """Register ``fn(op, rows: Rows) -> np.ndarray`` as the vectorised form of the operator law ``name``."""
    def register(fn):
        VECTORISED[name] = fn
        return fn
    return register


class Rows:
    """Samples stacked: ``x1``, ``x2`` ``(B, n)``; ``lam``, ``mu``, ``nu``, ``t`` ``(B,)``; ``ok`` ``(B,)`` the rows
    every resolvent call of the vectorised law answered with a finite point of the right shape; ``err`` ``(B,)``,
    when the form states it (:func:`rounding`), a bound on the difference between each row's vectorised ratio and
    the law's own (``None``: the margin ``1 - SUSPECT``).  ``inconclusive`` ``(B,)``, when the form states it: rows
    (not ``ok``) that the law's evaluator would itself find inconclusive — by its own test, which the form's
    arithmetic decides with a margin beyond the rounding of its sums — with the evaluator's message
    ``inconclusive_what``: the search counts them as that evaluator's inconclusive samples, in their order,
    without calling the subject again (:meth:`verimono.checks.engine.search._Search.evaluate_many`).

    Built from a list of samples (their fields stacked row by row) or from a
    :class:`~verimono.checks.engine.blocks.SampleBlock` (its arrays copied whole: no sample is made, none taken
    apart; the same float64 numbers)."""

    __slots__ = ("x1", "x2", "lam", "mu", "nu", "t", "ok", "err", "inconclusive", "inconclusive_what")

    def __init__(self, samples: Sequence[Any]) -> None:
        if isinstance(samples, SampleBlock):     # the block's arrays, copied in one pass each (no row is made)
            fields = (np.array(a, dtype=float) for a in
                      (samples.x1, samples.x2, samples.lam, samples.mu, samples.nu, samples.t))
        else:
            fields = stack_fields(samples)
        self.x1, self.x2, self.lam, self.mu, self.nu, self.t = fields
        self.ok = np.ones(len(samples), dtype=bool)
        self.err = None
        self.inconclusive, self.inconclusive_what = None, ""

    def accepted(self, q: np.ndarray, bound: float = 1.0) -> np.ndarray:
        """The rows decided by their vectorised ratios ``q``: every call answered, ``q`` finite and ``q`` plus its
        rounding bound (``err``; ``1 - SUSPECT`` when the form states none) within ``bound``."""
        with np.errstate(invalid="ignore"):
            if self.err is None:
                return self.ok & np.isfinite(q) & (q <= SUSPECT * bound)
            return self.ok & np.isfinite(q) & np.isfinite(self.err) & (q + self.err <= bound)


def rows_accepted(op: Any) -> bool:
    """Whether the operator's resolvent maps a batch ``(B, n)`` row by row, as separate calls would (its class
    says so, and no resolvent was set on the object itself: an instrumented or patched one is called per row)."""
    if "resolvent" in getattr(op, "__dict__", {}):
        return False
    try:
        return bool(op._accepts_batches())
    except Exception:   # noqa: BLE001 - a user's object without the hook: one call per row
        return False


#: the search whose vectorised evaluation is running (``[state]`` while it runs): every subject call of
#: :func:`row_resolvents` is timed on it as a call of its own (:func:`_call_starts`)
CLOCK: list = []


def _call_starts() -> None:
    """A subject call starts: the running search's ``in_flight`` is its start, and the call before it, now
    returned, counts toward ``slowest``.  A vectorised pass is many calls, judged one by one as the search
    judges its samples (:func:`verimono.records.verdicts.never_returned`): a subject slow at every call is no
    subject that hangs (the pass as one call would have been, at ``HANG_MULTIPLE`` x its fast first calls)."""
    if CLOCK:
        state, now = CLOCK[-1], time.perf_counter()
        if state.in_flight is not None:
            state.slowest = max(state.slowest, now - state.in_flight)
        state.in_flight = now


def _groups(lams: np.ndarray, ts: np.ndarray) -> tuple[np.ndarray | None, list[int]]:
    """The rows grouped by the bits of their ``(λ, t)``: a stable order (``None``: one group, the rows as they are)
    and the groups' bounds in that order (``[0, b_1, ..., B]``)."""
    B = lams.shape[0]
    li = np.ascontiguousarray(lams, dtype=float).view(np.int64)
    ti = np.ascontiguousarray(ts, dtype=float).view(np.int64)
    if B < 2 or ((li == li[0]).all() and (ti == ti[0]).all()):
        return None, [0, B]
    order = np.lexsort((ti, li))
    ls, tt = li[order], ti[order]
    cut = np.flatnonzero((ls[1:] != ls[:-1]) | (tt[1:] != tt[:-1])) + 1
    return order, [0] + cut.tolist() + [B]


def row_resolvents(op: Any, X: np.ndarray, lams: np.ndarray, ts: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """``J_{λ_i} X_i`` at ``t_i`` for every row (on copies of the rows); a row whose call raised, returned no
    finite point of its shape or modified its input is marked ``False`` in ``ok`` (its values are then meaningless).  Each subject
    call is timed as a call of its own (:func:`_call_starts`).

    On an operator that maps batches, the rows of each distinct ``(λ, t)`` (the same bits) are one call on a
    contiguous block of one sorted copy of ``X``; the loop over the groups only calls and stores, and the checks
    (finite output, input left unchanged) are one pass over all rows after it — a design that moves ``λ`` or ``t``
    is one group per row, so the loop's cost per group is the engine's cost per row there."""
    B, n = X.shape
    good = np.ones(B, dtype=bool)
    if B == 0:
        return np.zeros_like(X)
    st, perf = (CLOCK[-1] if CLOCK else None), time.perf_counter      # _call_starts, inlined: the loops below are
    if rows_accepted(op):                                               # the engine's cost per row
        J = _one_call(op, X, lams, ts, ok)
        if J is not None:
            return J
        order, bounds = _groups(lams, ts)
        Xs = X.copy() if order is None else X[order]        # the subject's input: one private copy
        lam_l = (lams if order is None else lams[order]).tolist()
        t_l = (ts if order is None else ts[order]).tolist()
        Js, resolvent = np.empty_like(Xs), op.resolvent
        for lo, hi in zip(bounds[:-1], bounds[1:]):
            if st is not None:
                now, f = perf(), st.in_flight
                if f is not None and now - f > st.slowest:
                    st.slowest = now - f
                st.in_flight = now
            try:
                P = resolvent(Xs if hi - lo == B else Xs[lo:hi], lam_l[lo], t_l[lo])
                if type(P) is not np.ndarray or P.dtype is not _F64:
                    P = as_float64(P)
                if P.shape != (hi - lo, n):
                    raise ValueError
            except Exception:   # noqa: BLE001 - the law's evaluator of one sample meets it and judges it
                if interrupted():
                    raise
                good[lo:hi] = False
                Js[lo:hi] = 0.0
                continue
            Js[lo:hi] = P
        good &= row_finite(Js) & row_all(Xs == (X if order is None else X[order]))  # inputs unchanged
        if order is None:
            ok &= good
            return Js
        J = np.empty_like(Js)
        J[order] = Js
        ok[order] &= good
        return J
    J = np.zeros_like(X)
    Xc = X.copy()       # row i is the subject's input of call i (a row of a private copy)
    lam_l, t_l, resolvent = lams.tolist(), ts.tolist(), op.resolvent
    for i in range(B):
        if st is not None:
            now, f = perf(), st.in_flight
            if f is not None and now - f > st.slowest:
                st.slowest = now - f
            st.in_flight = now
        try:
            p = resolvent(Xc[i], lam_l[i], t_l[i])
            if type(p) is not np.ndarray or p.dtype is not _F64:
                p = as_float64(p)
            if p.shape != (n,):
                raise ValueError
        except Exception:   # noqa: BLE001 - as above
            if interrupted():
                raise
            good[i] = False
            continue
        J[i] = p
    good &= row_finite(J) & row_all(Xc == X)
    ok &= good
    return J


def _one_call(op: Any, X: np.ndarray, lams: np.ndarray, ts: np.ndarray, ok: np.ndarray) -> np.ndarray | None:
    """:func:`row_resolvents` of rows whose ``(λ, t)`` differ, as one call when the operator takes them so — a step
    size per row (:func:`verimono.core.operator_protocol.accepts_steps`) where the ``λ`` differ, a time per row
    (``accepts_times``) where the ``t`` differ — bit-identical to its calls per ``(λ, t)`` (what the catalog
    declares); ``None`` when it does not (or all rows share one ``(λ, t)``: one call already) and when the one call
    raised or answered no array of the rows' shape: then the calls per ``(λ, t)`` say which rows are bad."""
    B, n = X.shape
    li = lams.view(np.int64) if lams.dtype == _F64 and lams.flags.c_contiguous else None
    ti = ts.view(np.int64) if ts.dtype == _F64 and ts.flags.c_contiguous else None
    if li is None or ti is None or B < 2:
        return None
    one_lam, one_t = bool((li == li[0]).all()), bool((ti == ti[0]).all())
    if (one_lam and one_t) or (not one_lam and not accepts_steps(op)) or (not one_t and not accepts_times(op)):
        return None
    Xs = X.copy()       # the subject's input: one private copy
    _call_starts()      # one call, timed as one
    try:
        J = op.resolvent(Xs, lams[0].item() if one_lam else lams.copy(), ts[0].item() if one_t else ts.copy())
        if type(J) is not np.ndarray or J.dtype is not _F64:
            J = as_float64(J)
        if J.shape != (B, n):
            return None
    except Exception:   # noqa: BLE001 - the calls per (λ, t) meet it, row by row, as before
        if interrupted():
            raise
        return None
    ok &= row_finite(J) & row_all(Xs == X)      # inputs unchanged
    return J


#: float64's dtype (``P.dtype is _F64``: NumPy's native float64 dtype is one object; any other goes through ``as_float64``)
_F64 = np.dtype(np.float64)


#: the members :func:`row_member` calls once for a block when their operator takes a time per row
#: (:meth:`verimono.core.operator_protocol.Operator._accepts_times` declares these two besides the resolvent and yosida)
_TIMED_MEMBERS = ("min_norm", "project_domain")


def _member_takes_times(member: Any) -> bool:
    """Whether ``member`` is the ``min_norm`` or ``project_domain`` its operator's class defines (a bound method, not
    one replaced on the object) and the operator declares a time per row for it
    (:func:`verimono.core.operator_protocol.accepts_times`, which is false where a member is replaced on the object
    or overridden by a subclass of the catalog): then one call on ``(B, n)`` rows with ``t`` of shape ``(B,)`` is
    bit-identical to the ``B`` calls per row."""
    owner, fn = getattr(member, "__self__", None), getattr(member, "__func__", None)
    if owner is None or fn is None or not accepts_times(owner):
        return False
    cls = type(owner)
    return any(getattr(cls, m, None) is fn for m in _TIMED_MEMBERS)


def _member_block(member: Any, X: np.ndarray, ts: np.ndarray, rows: np.ndarray) -> np.ndarray | None:
    """``member(X[rows], ts[rows])`` as one call (timed as one subject call, :func:`_call_starts`), or ``None`` when
    it raised (an ``OutsideDomain`` at any row among them) or answered no array of the rows' shape: then the calls
    per row say which rows are bad."""
    _call_starts()
    try:
        P = member(X[rows], ts[rows].astype(float))     # fancy indexing: the subject's input is a private copy
        if type(P) is not np.ndarray or P.dtype is not _F64:
            P = as_float64(P)
        if P.shape != (rows.size, X.shape[1]):
            return None
    except Exception:   # noqa: BLE001 - the calls per row meet it, row by row, as before
        if interrupted():
            raise
        return None
    return P


def row_member(member: Any, X: np.ndarray, ts: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """``member(X_i, t_i)`` of every row still ``ok``, on copies; a row whose call raised (an ``OutsideDomain``
    among them: the law's evaluator judges it) or returned no finite point of its shape is marked ``False`` in
    ``ok``.  Each call is timed as a call of its own (:func:`_call_starts`).

    Where ``member`` is a catalog operator's own ``min_norm`` or ``project_domain`` and the operator takes a time
    per row (:func:`_member_takes_times`), the rows are one call (bit-identical to the calls per row, as the
    operator declares); if that call raises (one row outside the domain) or answers no ``(B, n)`` array, the calls
    per row run as before and judge the rows one by one.  Any other member (a user's, one replaced on the object)
    is called once per row."""
    out = np.zeros_like(X)
    t_l, n, bad = ts.tolist(), X.shape[1], []
    st, perf = (CLOCK[-1] if CLOCK else None), time.perf_counter      # _call_starts, inlined
    rows = np.flatnonzero(ok)
    if rows.size >= 2 and _member_takes_times(member):
        P = _member_block(member, X, ts, rows)
        if P is not None:
            out[rows] = P
            ok &= row_finite(out)
            return out
    for i in rows.tolist():
        if st is not None:
            now, f = perf(), st.in_flight
            if f is not None and now - f > st.slowest:
                st.slowest = now - f
            st.in_flight = now
        try:
            p = member(X[i].copy(), t_l[i])
            if type(p) is not np.ndarray or p.dtype is not _F64:
                p = as_float64(p)
            if p.shape != (n,):
                raise ValueError
        except Exception:   # noqa: BLE001 - the law's evaluator of one sample meets it and judges it
            if interrupted():
                raise
            bad.append(i)
            continue
        out[i] = p
    ok[bad] = False
    ok &= row_finite(out)
    return out


def row_values(op: Any, Z: np.ndarray, ts: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """``g(t_i, Z_i)`` (``op.value``, as :func:`verimono.checks.members.value` reads it) of every row still ``ok``,
    one call each on a copy; a row whose call raised or whose value is not finite is marked ``False`` in ``ok``
    (the law's evaluator judges a point outside ``dom g``)."""
    out = np.zeros(len(ok))
    if _values_block(op, Z, ts, ok, out):
        return out
    t_l, value = ts.tolist(), op.value
    st, perf = (CLOCK[-1] if CLOCK else None), time.perf_counter      # _call_starts, inlined
    for i in np.flatnonzero(ok).tolist():
        if st is not None:
            now, f = perf(), st.in_flight
            if f is not None and now - f > st.slowest:
                st.slowest = now - f
            st.in_flight = now
        try:
            v = value(np.array(Z[i], dtype=float), t_l[i])
            v = float(v if type(v) is float else as_float64(v))
        except Exception:   # noqa: BLE001 - as above
            if interrupted():
                raise
            ok[i] = False
            continue
        if not np.isfinite(v):
            ok[i] = False
            continue
        out[i] = v
    return out


def _values_block(op: Any, Z: np.ndarray, ts: np.ndarray, ok: np.ndarray, out: np.ndarray) -> bool:
    """:func:`row_values` of the rows still ``ok`` as one call of the class's ``_value_rows`` with a time per row,
    where it states one (the catalog's, bit-identical to ``value`` per row; looked up on the class, so an input-form
    wrapper declines; timed as one subject call), its values in ``out`` and a non-finite one marked ``False`` in
    ``ok``; ``False`` when there is none, fewer than 2 rows, or it declines, raises or answers no ``(B,)`` float64
    array: the calls per row then judge every row."""
    rows = np.flatnonzero(ok)
    block = getattr(type(op), "_value_rows", None)
    if block is None or rows.size < 2:
        return False
    _call_starts()
    try:
        v = block(op, Z[rows], ts[rows].astype(float))
    except Exception:   # noqa: BLE001 - the calls per row meet it, row by row
        if interrupted():
            raise
        return False
    if type(v) is not np.ndarray or v.dtype != np.float64 or v.shape != rows.shape:
        return False
    good = np.isfinite(v)
    out[rows] = np.where(good, v, 0.0)
    ok[rows] &= good
    return True


def row_contains(op: Any, X: np.ndarray, Y: np.ndarray, ts: np.ndarray, tols: np.ndarray,
                 ok: np.ndarray, lacking: bool = False) -> np.ndarray:
    """``op.contains(X_i, Y_i, t_i, tol_i)`` of every row still ``ok`` (one call each, on copies); a row whose call
    raised or answered other than a truth value is marked ``False`` in ``ok`` — one that raised
    ``NotImplementedError`` counts as inside with ``lacking`` (a law that certifies by ``contains`` only where it
    can)."""
    got = np.zeros(len(ok), dtype=bool)
    rows = np.flatnonzero(ok)
    if rows.size >= 2 and _contains_block(op, X, Y, ts, tols, rows, got):
        return got
    t_l, tol_l, contains = ts.tolist(), np.broadcast_to(tols, ts.shape).tolist(), op.contains
    st, perf = (CLOCK[-1] if CLOCK else None), time.perf_counter      # _call_starts, inlined
    for i in rows.tolist():
        if st is not None:
            now, f = perf(), st.in_flight
            if f is not None and now - f > st.slowest:
                st.slowest = now - f
            st.in_flight = now
        try:
            v = contains(X[i].copy(), Y[i].copy(), t_l[i], tol_l[i])
        except NotImplementedError:
            if lacking:
                got[i] = True
            else:
                ok[i] = False
            continue
        except Exception:   # noqa: BLE001 - as above
            if interrupted():
                raise
            ok[i] = False
            continue
        if not isinstance(v, (bool, np.bool_)):
            ok[i] = False
            continue
        got[i] = bool(v)
    return got


def _contains_block(op: Any, X: np.ndarray, Y: np.ndarray, ts: np.ndarray, tols: Any, rows: np.ndarray,
                    got: np.ndarray) -> bool:
    """:func:`row_contains` of ``rows`` as one call of a catalog operator's ``_contains_rows`` (bit-identical to its
    ``contains`` per row, as the class declares; timed as one subject call), its answers in ``got``; ``False`` when the
    operator has none, declines (a member that is not the class's own), raises or answers no ``(B,)`` booleans: the
    calls per row then judge every row."""
    block = getattr(op, "_contains_rows", None)
    if block is None:
        return False
    _call_starts()
    try:
        b = block(X[rows], Y[rows], ts[rows].astype(float), np.broadcast_to(tols, ts.shape)[rows].astype(float))
    except Exception:   # noqa: BLE001 - the calls per row meet it, row by row
        if interrupted():
            raise
        return False
    if type(b) is not np.ndarray or b.dtype != bool or b.shape != rows.shape:
        return False
    got[rows] = b
    return True


def row_norms(V: np.ndarray) -> np.ndarray:
    """:func:`verimono.checks.members.norm` of every row (scaled by the row's largest entry: no underflow; 0 for
    a zero row and, as there, for a row whose largest entry is not finite)."""
    m = row_abs_max(V)
    good = (m > 0.0) & np.isfinite(m)
    safe = np.where(good, m, 1.0)
    W = V / safe[:, None]       # one scaled copy (it was made twice: a (rows, n) temporary each)
    out = safe * np.sqrt(np.einsum("ij,ij->i", W, W))
    return np.where(good, out, 0.0)


#: the safety factor of :func:`rounding` over the textbook bounds (``γ_n ≈ n·eps`` for a sum of ``n`` terms)
ROUNDING_SAFETY = 8.0


def rounding(r: Rows, q: np.ndarray, den: np.ndarray, *products: np.ndarray) -> np.ndarray:
    """Set and return ``r.err``: a bound on ``|q - q_law|`` for ratios ``q = lhs / den`` whose norms (and
    tolerances, exact maxima) the law computes in another summation order — each norm relatively within
    ``(n + 2)·eps``, so ``q`` within ``g·|q|``, ``g = ROUNDING_SAFETY·(n + 4)·eps`` — and whose ``products`` (``|a|·|b|``
    of each dot product in ``lhs`` or ``den``; a sum of ``n`` products is within ``γ_n Σ|a_i b_i| ≤ γ_n |a||b|``
    of its exact value in any order) add ``g·|a||b| / den`` each (``inf`` where ``den ≤ 0``)."""
    r.err = rounding_bound(r.x1.shape[1] if r.x1.ndim == 2 else 1, q, den, *products)
    return r.err


def rounding_bound(n: int, q: np.ndarray, den: np.ndarray, *products: np.ndarray) -> np.ndarray:
    """The bound of :func:`rounding` for rows of ``n`` coordinates, returned without setting ``Rows.err`` (a form
    that decides rows at several steps, each with its own bound)."""
    g = ROUNDING_SAFETY * (n + 4) * np.finfo(float).eps
    with np.errstate(all="ignore"):
        e = g * np.abs(q)
        for p in products:
            e = e + np.where(den > 0.0, g * p / np.where(den > 0.0, den, 1.0), np.inf)
    return np.where(np.isnan(e), np.inf, e)


def row_dots(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", A, B)


def row_ratios(lhs: np.ndarray, rhs: np.ndarray, slack: np.ndarray) -> np.ndarray:
    """:func:`verimono.checks.core.ratio` of every row: ``lhs / (rhs + slack)``, ``inf`` when a side is not
    finite, 0 or ``inf`` when the denominator is 0 (NaN never: it would compare as a pass)."""
    den = rhs + slack
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        r = np.where(den > 0.0, lhs / np.where(den > 0.0, den, 1.0), np.where(lhs <= 0.0, 0.0, np.inf))
    bad = ~(np.isfinite(lhs) & np.isfinite(den)) | np.isnan(r)
    return np.where(bad, np.inf, r)


__all__ += ["VECTORISED", "PER_PASS", "SUSPECT", "ROW_CELLS", "ROUNDING_SAFETY", "vectorised", "Rows", "rows_accepted", "rounding",
            "rounding_bound",
            "row_resolvents", "row_member", "row_contains", "row_values",
            "row_norms", "row_dots", "row_ratios"]
