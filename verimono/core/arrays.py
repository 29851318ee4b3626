"""Array libraries at verimono's boundary: what a subject computes with, and the conversions both ways.

verimono's laws do their arithmetic in NumPy float64.  A subject — an operator, a prox, a stepper — may
compute with JAX, PyTorch, CuPy or any array-API library, and in float32 or half precision.  This module

* recognises a value's library (:func:`library_of`) and precision (:func:`precision_of`);
* converts a subject's output to NumPy (:func:`to_numpy`, keeping its dtype; :func:`as_float64` for the
  laws' arithmetic), reporting the precision it drops to the judgement in progress
  (:func:`verimono.core.tolerances.observe`) — never silently;
* converts verimono's NumPy inputs to the array type a subject declares or is detected to use
  (:class:`ArrayKind`, :func:`array_kind`): ``"numpy"``, ``"jax"``, ``"torch"``, ``"cupy"``, or an array-API
  namespace module (``array_api_strict``, ``torch``'s compat namespace, ...), in that library's default
  floating dtype unless a ``dtype`` is given (JAX: float32 unless ``jax_enable_x64``; PyTorch:
  ``torch.get_default_dtype()``; NumPy and CuPy: float64).

Libraries are imported only when a value of theirs is met or a subject declares them: none is a
dependency of verimono.
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import importlib
import sys
from typing import Any, Callable

import numpy as np

from .errors import InvalidProblem
from .tolerances import observe, precision_name

#: the array libraries known by name (anything else with ``__array_namespace__`` is an array-API array)
LIBRARIES = ("numpy", "jax", "torch", "cupy")


def library_of(value: Any) -> str | None:
    """The array library of ``value``: ``"numpy"``, ``"jax"``, ``"torch"``, ``"cupy"``, ``"array-api"`` (another
    array with ``__array_namespace__``), or ``None`` (Python numbers, lists, anything else)."""
    if isinstance(value, (np.ndarray, np.generic)):
        return "numpy"
    root = type(value).__module__.split(".", 1)[0]
    if root in ("jax", "jaxlib"):
        return "jax"
    if root in ("torch", "cupy"):
        return root
    if hasattr(value, "__array_namespace__"):
        return "array-api"
    return None


def precision_of(value: Any) -> str | None:
    """The floating-point precision ``value`` carries (``"float64"``, ``"float32"``, ``"float16"``,
    ``"bfloat16"``), ``"float64"`` for Python floats, ``None`` for exact values (integers, booleans) and
    non-arrays."""
    if isinstance(value, float):
        return "float64"
    dtype = getattr(value, "dtype", None)
    if dtype is None:
        if isinstance(value, (list, tuple)):
            try:
                return precision_name(np.asarray(value).dtype)
            except (TypeError, ValueError):
                return None
        return None
    return precision_name(dtype)


def to_numpy(value: Any) -> Any:
    """``value`` as a NumPy array in its own dtype where NumPy has it (bfloat16 tensors of PyTorch become
    float32, exactly): PyTorch tensors are detached and moved to the CPU, CuPy arrays copied to the host,
    other array-API arrays exchanged through DLPack.  Anything else is returned as it is."""
    lib = library_of(value)
    if lib is None or lib == "numpy":
        return value
    if lib == "torch":
        t = value.detach()
        if t.device.type != "cpu":
            t = t.cpu()
        if str(t.dtype) == "torch.bfloat16":      # NumPy has no bfloat16: float32 holds it exactly
            t = t.float()
        return t.numpy()
    if lib == "cupy":
        return value.get()
    if lib == "jax":
        return np.asarray(value)
    try:
        return np.from_dlpack(value)
    except (TypeError, ValueError, RuntimeError, BufferError, AttributeError):
        return np.asarray(value)


def as_float64(value: Any) -> np.ndarray:
    """``value`` (any library's array, a list, a number) as a NumPy float64 array for the laws' arithmetic,
    its precision reported to the judgement in progress (:func:`verimono.core.tolerances.observe`).  A float64
    NumPy array is returned as it is; complex or non-numeric values raise ``TypeError``/``ValueError``
    as ``np.asarray(value, dtype=float)`` does."""
    kind = type(value)
    if kind is np.ndarray:
        if value.dtype == np.float64:
            return value
        if value.dtype == np.float32:   # a NumPy float32 subject's outputs: what the general path below does,
            observe("float32")          # without its dtype-name lookups (a third of a float32 battery's CPU)
            return value.astype(np.float64)
    elif kind is np.float32:
        observe("float32")
        return np.asarray(value, dtype=float)
    p = precision_of(value)
    if p is not None and p != "float64":
        observe(p)
    a = to_numpy(value)
    if getattr(a, "dtype", None) is not None and np.dtype(a.dtype).kind == "c":
        raise TypeError(f"complex values where real ones are expected: {a!r:.80}")
    return np.asarray(a, dtype=float)


# -- verimono's inputs in a subject's array type -------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class ArrayKind:
    """The array type a subject computes with: ``name`` (a library of :data:`LIBRARIES` or a namespace's
    name), ``dtype`` (the precision inputs are converted to) and the conversion of a NumPy array."""

    name: str
    dtype: str
    convert: Callable[[np.ndarray], Any] = dataclasses.field(repr=False, compare=False)

    def asarray(self, x: Any) -> Any:
        """``x`` (NumPy) in this array type and dtype; the precision it is given reported
        (:func:`verimono.core.tolerances.observe`: the coarser of input and output decides)."""
        observe(self.dtype)
        return self.convert(np.asarray(x))

    @property
    def plain(self) -> bool:
        """NumPy float64: verimono's own type, no conversion."""
        return self.name == "numpy" and self.dtype == "float64"


def _jax(dtype: str | None, device: Any) -> ArrayKind:
    import jax
    import jax.numpy as jnp

    dt = jnp.dtype(dtype) if dtype else jnp.asarray(0.0).dtype
    dev = device

    def convert(x):
        # cast by NumPy, then one transfer: jnp.asarray(x, dtype=...) dispatches a conversion primitive per
        # call (about 0.4 ms, more than a jitted prox of 100 coordinates)
        return jax.device_put(np.asarray(x, dtype=dt), dev)
    name = precision_name(jnp.asarray(0.0, dtype=dt).dtype)   # float64 without x64 enabled is float32
    return ArrayKind("jax", name, convert)


def _torch(dtype: str | None, device: Any) -> ArrayKind:
    import torch

    dt = getattr(torch, dtype) if dtype else torch.get_default_dtype()
    return ArrayKind("torch", precision_name(dt), lambda x: torch.as_tensor(x, dtype=dt, device=device))


def _cupy(dtype: str | None, device: Any) -> ArrayKind:
    import cupy

    dt = cupy.dtype(dtype or "float64")
    return ArrayKind("cupy", precision_name(dt), lambda x: cupy.asarray(x, dtype=dt))


def _numpy(dtype: str | None, device: Any) -> ArrayKind:
    dt = np.dtype(dtype or "float64")
    if dt == np.float64:
        return ArrayKind("numpy", "float64", lambda x: x)
    return ArrayKind("numpy", precision_name(dt), lambda x: np.asarray(x, dtype=dt))


def _namespace(xp: Any, dtype: str | None, device: Any) -> ArrayKind:
    """An array-API namespace: ``xp.asarray(x, dtype=...)``; its default real floating dtype unless
    ``dtype`` is given."""
    if dtype:
        dt = getattr(xp, dtype)
    else:
        info = getattr(xp, "__array_namespace_info__", None)
        try:
            dt = info().default_dtypes(device=device)["real floating"]
        except Exception:   # noqa: BLE001 - an older namespace without the inspection API
            dt = getattr(xp, "float64")
    kw = {} if device is None else {"device": device}
    name = precision_name(xp.asarray(0.0, dtype=dt, **kw).dtype) or "float64"
    return ArrayKind(getattr(xp, "__name__", type(xp).__name__), name,
                     lambda x: xp.asarray(x, dtype=dt, **kw))


_BUILDERS = {"numpy": _numpy, "jax": _jax, "torch": _torch, "cupy": _cupy}


def array_kind(array: Any = None, *, dtype: Any = None, device: Any = None) -> ArrayKind | None:
    """The :class:`ArrayKind` a subject declares: ``array`` a library name of :data:`LIBRARIES`, the name
    of an importable array-API namespace module, or the namespace module itself; ``dtype`` the precision
    its inputs get (a dtype or its name; default the library's default floating dtype); ``device`` where
    (PyTorch, JAX, array-API).  ``None`` for ``array=None`` and ``dtype=None`` (detect from the outputs)."""
    if array is None and dtype is None:
        return None
    dname = None if dtype is None else (precision_name(dtype) or str(dtype))
    if dname is not None and dname not in ("float64", "float32", "float16", "bfloat16"):
        raise InvalidProblem(f"dtype must be a floating-point precision (float64, float32, float16, bfloat16), "
                             f"got {dtype!r}")
    if array is None:
        array = "numpy"
    if isinstance(array, str):
        builder = _BUILDERS.get(array)
        if builder is not None:
            try:
                return builder(dname, device)
            except ImportError as exc:
                raise InvalidProblem(f"array={array!r}: {array} is not installed ({exc})") from None
        try:
            array = importlib.import_module(array)
        except ImportError as exc:
            raise InvalidProblem(f"array={array!r} is neither one of {LIBRARIES} nor an importable array-API "
                                 f"namespace ({exc})") from None
    name = getattr(array, "__name__", "")
    if name in _BUILDERS and name != "numpy":
        return _BUILDERS[name](dname, device)
    if name == "numpy" or name == "numpy.array_api":
        return _numpy(dname, device)
    if not callable(getattr(array, "asarray", None)):
        raise InvalidProblem(f"array must name an array library ({', '.join(LIBRARIES)}) or be an array-API "
                             f"namespace with asarray, got {array!r}")
    return _namespace(array, dname, device)


#: a batch of samples is handed to a batched subject in chunks of at most this many rows, each padded to a
#: power of two (by repeating its first row): a jitted function then compiles for a few shapes only
MAX_BATCH = 1024


def padded(rows: int) -> int:
    """The batch size a chunk of ``rows`` rows is padded to: the next power of two."""
    return 1 << max(0, int(rows) - 1).bit_length()


def batch_chunks(count: int, pad: bool = True):
    """``(lo, rows, pick)`` for the chunks of ``count`` rows: rows ``lo .. lo + rows`` of the batch, and
    ``pick`` the indices of the chunk padded to :func:`padded` rows by repeating its first row (a batched
    subject is called once per chunk with ``X[pick]``; its first ``rows`` answers are kept).  ``pad=False``:
    the chunk as it is (the checks call a batched subject at every batch size, odd ones included)."""
    for lo in range(0, count, MAX_BATCH):
        rows = min(MAX_BATCH, count - lo)
        extra = padded(rows) - rows if pad else 0
        yield lo, rows, np.r_[np.arange(lo, lo + rows), np.full(extra, lo)].astype(int)


def prefetch_key(x: np.ndarray, lam: float, t: float) -> tuple:
    """The key of a prefetched ``J_λ x`` at ``t`` (exact: the bytes of ``x``;
    :func:`verimono.checks.engine.batches.prefetched`)."""
    return (np.ascontiguousarray(x, dtype=float).tobytes(), float(lam), float(t))


def take_prefetched(cache: dict | None, x: Any, lam: float, t: float) -> np.ndarray | None:
    """The prefetched ``J_λ x`` at ``t`` from a batched subject's ``cache``, removed from it (each value is
    handed out once: a second call at the same point evaluates the subject again), or ``None``."""
    if not cache or type(x) is not np.ndarray or x.ndim != 1:
        return None
    hit = cache.pop(prefetch_key(x, lam, t), None)
    return None if hit is None else hit.copy()


#: what an error raised by a function of another library's arrays, given NumPy's, says of that library
_LIBRARY_SIGNS = {"torch": ("Tensor", "torch"), "jax": ("jax", "Array'"), "cupy": ("cupy",)}


def library_hint(exc: BaseException, given: str = "numpy") -> str:
    """A sentence for the message of ``exc``, raised by a user's function that verimono gave ``given``
    arrays: when its text names another array library (``must be Tensor, not numpy.ndarray``), the option that
    makes verimono give it that library's arrays (``array="torch"``); else ``""``."""
    if given != "numpy":
        return ""
    text = f"{type(exc).__name__}: {exc}"
    for lib, signs in _LIBRARY_SIGNS.items():
        if any(sign in text for sign in signs):
            return (f"; it was given NumPy arrays and looks like a function of {lib} arrays: wrap it with "
                    f'array="{lib}" (verimono.operator_from_prox(..., array="{lib}"), or operator_from_resolvent) '
                    f"so that it is given {lib} arrays")
    return ""


#: while set (:func:`as_given`), a NumPy subject's adapter hands it the NumPy arrays it is called with as they
#: are — integer dtypes, strided or offset views, read-only arrays — instead of a float64 copy: the input
#: forms of the operator laws (:mod:`verimono.checks.engine.forms`) reach the user's own function
_AS_GIVEN: contextvars.ContextVar[bool] = contextvars.ContextVar("verimono_as_given", default=False)


class as_given(contextlib.AbstractContextManager):
    """Within the block, NumPy subjects are given their inputs as they are (:data:`_AS_GIVEN`); a class, not a
    generator: it wraps every call of an operator in an input form."""

    def __enter__(self) -> None:
        self._token = _AS_GIVEN.set(True)

    def __exit__(self, *exc: Any) -> None:
        _AS_GIVEN.reset(self._token)


def given_as_is(x: Any, library: str) -> bool:
    """Whether ``x`` goes to a subject computing with ``library`` as it is: inside :func:`as_given`, a NumPy
    array of a real (integer or floating) dtype given to a NumPy subject."""
    return (library == "numpy" and type(x) is np.ndarray and x.dtype.kind in "iuf" and _AS_GIVEN.get())


class Boundary:
    """The conversions of one subject at verimono's boundary: its inputs from NumPy to its array type (none
    for NumPy float64), its outputs to NumPy float64 with their precision reported.  ``kind=None``: the
    array type is detected from the first value the subject returns (a JAX function given NumPy returns
    JAX arrays; from then on it is given JAX arrays)."""

    def __init__(self, kind: ArrayKind | None) -> None:
        self.kind = kind
        self.detect = kind is None
        #: the subject's last converted output, watched (:meth:`_watch`): its NumPy memory, its bytes as returned,
        #: and the float64 copy handed to the laws
        self._handed: tuple[np.ndarray, bytes, np.ndarray] | None = None

    @property
    def name(self) -> str:
        return "numpy" if self.kind is None else self.kind.name

    @property
    def dtype(self) -> str:
        return "float64" if self.kind is None else self.kind.dtype

    def given(self, x: Any) -> Any:
        """A NumPy array (or number) as the subject is given it."""
        k = self.kind
        return x if k is None or k.plain else k.asarray(x)

    def returned(self, value: Any) -> np.ndarray:
        """What the subject returned, as NumPy float64 (its precision observed; the first value fixes a
        detected array type)."""
        if self.detect:
            self.detect = False
            self.kind = kind_of(value)
        out = as_float64(value)
        if self._handed is not None or out is not value:
            self._watch(value, out)
        return out

    def _watch(self, value: Any, out: np.ndarray) -> None:
        """Keep a value once returned the caller's across the conversion (prop:maxmon-resolvent-Yosida i–ii: ``J_λ``
        is a function; what it returned is not changed by a later call).  A float64 NumPy output reaches the laws
        as it is, so a subject that writes every value into one buffer and returns it shows the fault to them
        (``resolvent_single_valued`` holds ``J_λx1`` over a call at ``x2``).  A float32 (any converted) output
        reaches them as a float64 copy, which no later call can change: the fault was invisible.  So the array
        converted last is watched: when the subject's next output comes back and that array's bytes have changed
        since it was returned, the subject overwrote a value it had handed out, and the copy verimono handed out
        takes the new values — the caller sees exactly what a float64 caller of the same code would.  A subject
        returning a fresh array per call (or the same cached array for the same input) changes nothing."""
        prev = self._handed
        if prev is not None:
            raw, before, copy = prev
            if raw.tobytes() != before and copy.flags.writeable:    # (a copy made read-only since is the caller's)
                copy[...] = np.asarray(raw, dtype=float).reshape(copy.shape)
        # NumPy outputs only: JAX arrays are immutable, CuPy's reach NumPy as copies; a PyTorch CPU tensor shares its
        # memory with its .numpy() and could be watched the same way (no PyTorch on the machine this was written on)
        raw = value if type(value) is np.ndarray else None
        if out is value or raw is None or not raw.flags.writeable or raw.size != out.size:
            self._handed = None
        else:
            self._handed = (raw, raw.tobytes(), out)

    def scalar(self, value: Any) -> Any:
        """A scalar the subject returned (a function value), as NumPy, its precision observed."""
        p = precision_of(value)
        if p is not None and p != "float64":
            observe(p)
        return to_numpy(value)


def kind_of(value: Any) -> ArrayKind | None:
    """The :class:`ArrayKind` of a value a subject returned when it is another library's array (a subject
    that computes with JAX returns JAX arrays for NumPy inputs): that library in the value's precision;
    ``None`` for NumPy arrays and non-arrays."""
    lib = library_of(value)
    if lib in (None, "numpy"):
        return None
    dt = precision_of(value)
    if lib == "array-api":
        ns = value.__array_namespace__()
        return _namespace(ns, dt, getattr(value, "device", None))
    if lib not in sys.modules and lib != "jax":
        return None
    return array_kind(lib, dtype=dt, device=getattr(value, "device", None) if lib == "torch" else None)


__all__ = ["as_given", "given_as_is", "LIBRARIES", "MAX_BATCH", "Boundary", "padded", "batch_chunks", "prefetch_key", "take_prefetched", "ArrayKind", "array_kind", "kind_of", "library_of", "precision_of", "to_numpy", "as_float64"]
