"""The input's form: a searched coordinate of the operator laws — the NumPy arrays a subject's points arrive in.

Every operator law quantifies over points ``x ∈ R^n``, and a user's NumPy code receives those points in many
forms: integer arrays (``np.array([1, 2])``), views into larger buffers (a column of a matrix, every other
entry of a state vector, a slice of a flat parameter vector), read-only arrays (``np.broadcast_to``, memory
maps opened read-only, ``np.asarray`` of a JAX array, ``np.frombuffer`` of ``bytes``).  A resolvent that
allocates its output with ``np.empty_like(x)`` truncates integer input; one that reads ``x.base`` reads its
caller's other data; one that writes into ``x`` corrupts its caller's state.  A battery that passes only
fresh contiguous float64 arrays meets none of these.  So the form is a coordinate of the search
(:mod:`verimono.checks.search`), with values :data:`FORMS`:

* ``"contiguous"`` — a fresh C-contiguous float64 array (what every other phase passes);
* ``"integer"`` — integer-valued points as an ``int64`` array: a sample in this form has its points rounded
  to integers first (:func:`integral`), so the law's own float64 arithmetic uses the same points; a point a
  law derives (``J_λ x``, a perturbation) that is not integer-valued is passed as a fresh float64 array;
* ``"strided"`` — a non-contiguous view, every other entry of a larger buffer whose other entries are
  garbage (NaN, ±the largest float of the dtype, in turn: a read of them shows, whatever the code does
  with it);
* ``"slice"`` — a contiguous view at an offset into a larger buffer of the same garbage;
* ``"readonly"`` — a fresh array with ``flags.writeable = False``;
* ``"declared_dtype"`` — a fresh array of the dtype the subject declares (a float32 NumPy subject:
  float32), only for a subject whose declared dtype is not float64 (:func:`declared_dtype`).

The view and read-only forms are built in the subject's declared dtype, so that its adapter's conversion
(:class:`verimono.core.arrays.Boundary`) passes them on as they are.  Points are 1-D: Fortran order and 0-d
arrays are not forms of them.  Python lists are not a form: the operator protocol
(:mod:`verimono.core.operator_protocol`) promises its members NumPy arrays, not lists.  Forms apply to
NumPy subjects only (:func:`forms_for`): a JAX, PyTorch, CuPy or array-API subject is given its own
library's arrays, fresh, by its own conversion path.

**The law in form F.**  A sample in form ``F`` is the law evaluated on the operator seen through
:func:`in_form` — every point argument of every member (``resolvent``, ``yosida``, ``min_norm``,
``project_domain``, ``contains``, ``value``, ``in_domain``) passed in form ``F`` — and must give the verdict
the law gives on the same points as fresh float64 arrays: ``J_λ`` is a function of the *values* of ``x``.
Part of "``J_λ`` is a function of ``x``" is that the caller's ``x`` is unchanged: after every call the whole
buffer the point lives in (the view's parent, garbage included) is compared bit for bit with a copy taken
before it, and a member that wrote into it raises :class:`InputModified` — the sample fails.

**Read-only input that makes the subject raise is a failure of the subject.**  Is that fair?  A subject
that raises on a read-only array writes into its input (``x -= ...``) or demands a writable buffer; NumPy
users pass read-only arrays without knowing (``np.broadcast_to``, read-only memory maps, arrays from JAX),
and a subject that writes into its input is wrong on writable arrays too (it changes the caller's ``x``).
The one unfair case is code that never writes but *declares* a writable buffer — a Cython kernel typed
``double[:] x`` instead of ``const double[:] x`` raises on read-only input, and one typed ``double[::1]``
on strided views — it is judged failed all the same, because its users' calls fail the same way; the
message names the form (``points passed as a read-only array``), so the fix (``const``, or
``np.ascontiguousarray(x, dtype=float)`` first) is plain.

The draws of the search cycle through the forms (every draw but one in ``len(forms) + 1`` in a form: no
extra samples), and the coordinate phase evaluates the worst sample once in every form
(:func:`form_search`); what was evaluated in each form is recorded (``details["searched"]["forms"]``).
A batched subject's first call at a drawn point returns the value its batched call computed from the
float64 points (:mod:`verimono.checks.batches`); its later calls meet the form.
"""

from __future__ import annotations

import functools
from typing import Any, Callable, Sequence

import numpy as np

from ...core.arrays import _AS_GIVEN, as_given
from ...core.errors import InputModified

CONTIGUOUS, INTEGER, STRIDED, SLICE, READONLY, DECLARED = (
    "contiguous", "integer", "strided", "slice", "readonly", "declared_dtype")
#: the input forms, in the order the search cycles them
FORMS = (CONTIGUOUS, INTEGER, STRIDED, SLICE, READONLY, DECLARED)
#: how each form passes a point (for messages)
DESCRIBED = {CONTIGUOUS: "a fresh contiguous float64 array",
             INTEGER: "an int64 array (integer-valued points)",
             STRIDED: "a strided view (every other entry) into a larger buffer of garbage (NaN, ±huge)",
             SLICE: "a contiguous slice at an offset into a larger buffer of garbage (NaN, ±huge)",
             READONLY: "a read-only array (flags.writeable = False)",
             DECLARED: "a fresh array of the subject's declared dtype"}
#: entries of the parent buffer outside a view: this many before the slice's point
SLICE_OFFSET = 3
#: an integer-valued float64 below this magnitude is exactly an int64 (2^53: every integer below is a float)
EXACT_INT = 2.0 ** 53


def integral(x: np.ndarray) -> np.ndarray:
    """``x`` rounded to integers (a point of the ``"integer"`` form); entries beyond :data:`EXACT_INT` or
    non-finite are kept (they are no int64)."""
    x = np.asarray(x, dtype=float)
    return np.where(np.abs(x) < EXACT_INT, np.rint(x), x)


def declared_dtype(op: Any) -> np.dtype | None:
    """The NumPy dtype the subject declares its points in: a ``dtype`` attribute of its own, else its
    adapter's (:func:`verimono.operator_from_resolvent` / :func:`verimono.operator_from_prox` with
    ``dtype=``), else float64; ``None`` for a dtype NumPy has not (``bfloat16``)."""
    d = getattr(op, "dtype", None)
    if d is None:
        d = getattr(getattr(op, "_io", None), "dtype", "float64")
    try:
        dt = np.dtype(d)
    except TypeError:
        return None
    return dt if dt.kind == "f" else None


def forms_for(op: Any) -> tuple[str, ...]:
    """The forms searched for ``op`` beyond ``"contiguous"``: none for a subject of another array library,
    ``"declared_dtype"`` only for a NumPy subject declaring a dtype other than float64."""
    if getattr(op, "array", "numpy") != "numpy":
        return ()
    dt = declared_dtype(op)
    if dt is None:
        return ()
    return (INTEGER, STRIDED, SLICE, READONLY) + ((DECLARED,) if dt != np.float64 else ())


@functools.lru_cache(maxsize=64)
def _garbage_of(size: int, dt: np.dtype) -> np.ndarray:
    big = np.finfo(dt).max
    return np.resize(np.array([np.nan, big, -big], dtype=dt), size)


def _garbage(size: int, dt: np.dtype) -> np.ndarray:
    """A buffer of ``size`` garbage entries of dtype ``dt`` (NaN, +max, -max in turn): a fresh copy."""
    return _garbage_of(size, dt).copy()


class _Formed:
    """A point in a form, the buffer it lives in and that buffer's bytes before the call."""

    __slots__ = ("array", "buffer", "before")

    def __init__(self, x: Any, form: str, dt: np.dtype) -> None:
        if type(x) is not np.ndarray or x.ndim != 1:     # a batch, a scalar: not a point, passed as it is
            self.array = self.buffer = x
            self.before = None
            return
        n = x.size
        if form == INTEGER:
            # np.all and np.array_equal's tests as the arrays' own (the same shape: rint keeps it), without the dispatch
            exact = x.dtype.kind in "iu" or bool((np.abs(x) < EXACT_INT).all() and (x == np.rint(x)).all())
            a = buf = x.astype(np.int64) if exact else np.array(x, dtype=float)
        elif form == STRIDED:
            buf = _garbage(2 * n + 1, dt)
            a = buf[1::2]
            a[...] = x
        elif form == SLICE:
            buf = _garbage(n + 2 * SLICE_OFFSET, dt)
            a = buf[SLICE_OFFSET:SLICE_OFFSET + n]
            a[...] = x
        elif form == READONLY:
            a = buf = np.array(x, dtype=dt)
            a.flags.writeable = False
        elif form == DECLARED:
            a = buf = np.array(x, dtype=dt)
        else:
            a = buf = np.array(x, dtype=float)
        self.array, self.buffer, self.before = a, buf, buf.tobytes()

    def unchanged(self, member: str, form: str) -> None:
        """:class:`InputModified` when the buffer's bytes changed during the call."""
        if self.before is None or self.buffer.tobytes() == self.before:
            return
        was = np.frombuffer(self.before, dtype=self.buffer.dtype)
        now = np.asarray(self.buffer)
        changed = int(np.count_nonzero((was != now) & ~(np.isnan(was) & np.isnan(now)) if was.dtype.kind == "f"
                                       else was != now))
        where = "its input" if self.buffer is self.array else "the buffer its input is a view of"
        raise InputModified(f"{member} wrote into {where} ({changed} entr{'y' if changed == 1 else 'ies'} changed; "
                            f"points passed as {DESCRIBED[form]}): J_λ is a function of x, and the caller's x "
                            "must be unchanged")


class InForm:
    """``op`` seen through the input form ``form``: its members are given their point arguments in that form
    and checked not to write into them (:class:`InputModified`); every other attribute is ``op``'s."""

    def __init__(self, op: Any, form: str) -> None:
        self._op, self.form = op, form
        self._dtype = declared_dtype(op) or np.dtype(np.float64)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._op, name)

    def _call(self, member: str, points: Sequence[Any], *rest: Any, **kw: Any) -> Any:
        if len(points) == 1:        # one point (all members but contains): as below, without the list and generator
            f = _Formed(points[0], self.form, self._dtype)
            token = _AS_GIVEN.set(True)         # as_given(), without the context manager's object
            try:
                out = getattr(self._op, member)(f.array, *rest, **kw)
            finally:
                _AS_GIVEN.reset(token)
            f.unchanged(member, self.form)
            return out
        formed = [_Formed(x, self.form, self._dtype) for x in points]
        with as_given():
            out = getattr(self._op, member)(*(f.array for f in formed), *rest, **kw)
        for f in formed:
            f.unchanged(member, self.form)
        return out

    def resolvent(self, x, *args, **kw):
        return self._call("resolvent", (x,), *args, **kw)

    def yosida(self, x, *args, **kw):
        return self._call("yosida", (x,), *args, **kw)

    def min_norm(self, x, *args, **kw):
        return self._call("min_norm", (x,), *args, **kw)

    def project_domain(self, x, *args, **kw):
        return self._call("project_domain", (x,), *args, **kw)

    def contains(self, x, y, *args, **kw):
        return self._call("contains", (x, y), *args, **kw)

    def value(self, x, *args, **kw):
        return self._call("value", (x,), *args, **kw)

    def in_domain(self, x, *args, **kw):
        return self._call("in_domain", (x,), *args, **kw)

    def __repr__(self) -> str:
        return f"in_form({self._op!r}, {self.form!r})"


def in_form(op: Any, form: str) -> Any:
    """``op`` with its points passed in ``form`` (:class:`InForm`); ``op`` itself for ``"contiguous"``."""
    if form == CONTIGUOUS:
        return op
    if form not in FORMS:
        raise ValueError(f"no input form {form!r}; the forms are {FORMS}")
    return InForm(op, form)


def form_note(form: str) -> str:
    """What a message about a sample in ``form`` adds: how its points were passed (``""`` when contiguous)."""
    return "" if form == CONTIGUOUS else f" (points passed as {DESCRIBED.get(form, form)})"


def cycled(samples: list, forms: Sequence[str]) -> list:
    """``samples`` with the forms cycled over them: sample ``i`` in ``forms[i % (len(forms) + 1) - 1]``, the
    first of every ``len(forms) + 1`` left contiguous (no extra samples)."""
    if not forms:
        return samples
    k = len(forms) + 1
    return [s if i % k == 0 else s.in_form(forms[i % k - 1]) for i, s in enumerate(samples)]


def form_search(evaluate: Callable[[Any], Any], start: Any, forms: Sequence[str]) -> dict | None:
    """The worst sample ``start`` (contiguous) evaluated once in every form of ``forms`` (``evaluate`` raises to end the
    search, as on a violation); what was covered, or ``None`` when there is no form to search."""
    if not forms:
        return None
    for f in forms:
        evaluate(start.in_form(f))
    return {"coordinate": "form", "forms": list(forms), "points": len(forms)}


__all__ = ["FORMS", "DESCRIBED", "InForm", "InputModified", "in_form", "forms_for", "declared_dtype", "integral",
           "cycled", "form_search", "form_note", "CONTIGUOUS", "INTEGER", "STRIDED", "SLICE", "READONLY", "DECLARED"]
