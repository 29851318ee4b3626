"""Where a time budget's interrupt may be raised: in the law's and the subject's code, never inside a library's
machinery, a garbage-collector callback or a finalizer.

:func:`verimono.execution.timeouts.time_limit` stops a unit with ``SIGALRM``, whose Python handler runs in the
main thread between two bytecodes of whatever runs then — and raising there is not always safe:

* inside a **garbage-collector callback** or a **finalizer** (``__del__``, a ``weakref.finalize`` callback),
  Python prints "Exception ignored" and drops the exception: the interrupt is lost and the unit runs on past
  its budget (hypothesis registers a gc callback that times every collection, where the alarm landed);
* inside **hypothesis's engine** (drawing a sample, its bookkeeping between test calls, its digest of the
  test), the exception leaves the engine's state half-updated: the next laws of the same process raised
  ``AssertionError: state._runner is not None`` or ``IndexError: pop from empty list`` — recorded as failures
  of a correct half-plane projection in 6 of 10 runs at ``--timeout 0.05``;
* inside a **context manager's exit** (``__exit__``), the state it restores stays changed;
* inside **verimono's own budget machinery** (the timer's arming and disarming, the watchdog), an interrupt
  escaped as the internal ``_Expired`` (always at a 1e-6 s budget) and killed ``verimono check``.

:func:`safe_to_interrupt` reads the interrupted frame's stack, innermost first, up to the frame that opened
the limit: a gc callback, a finalizer or an ``__exit__`` anywhere on it, or a frame of hypothesis before any
frame registered with :func:`interruptible` (the law's evaluation of one sample: everything it calls is the
law's and the subject's code, even while hypothesis's frames are further out), defers the interrupt; so does
an innermost frame of verimono's execution machinery (the modules of :mod:`verimono.execution`).  Standard
library frames are transparent (their caller decides).  The handler then re-arms the timer for
:data:`DEFER_STEP` seconds and tries again; :func:`verimono.execution.timeouts.checkpoint` stops at the next
safe point (the start of a sample) at once.
"""

from __future__ import annotations

import gc
import sys
from types import CodeType, FrameType
from typing import Callable, TypeVar

#: seconds between two attempts of a deferred interrupt (each reads the stack once: microseconds)
DEFER_STEP = 2e-3
#: modules in which an interrupt is never raised (before an :func:`interruptible` frame)
LIBRARIES = ("hypothesis",)
#: verimono's own budget machinery: an interrupt landing in its code (the innermost frame that is not the
#: standard library's) waits until it returns to the unit's
MACHINERY = "verimono.execution."
#: frames that clean up or finalize: an interrupt inside them is dropped or leaves state half restored
CLEANUP = frozenset({"__del__", "__exit__", "__aexit__"})

_ENTRY_POINTS: set[CodeType] = set()
_STDLIB = frozenset(getattr(sys, "stdlib_module_names", ())) | {"builtins"}

F = TypeVar("F", bound=Callable)


def interruptible(fn: F) -> F:
    """Mark ``fn`` as the entry of the law's and the subject's code (the evaluation of one sample): an
    interrupt may be raised in it and in everything it calls, even where a library's frames (hypothesis
    calling its test) are further out.  Returns ``fn``."""
    _ENTRY_POINTS.add(fn.__code__)
    return fn


def _module(frame: FrameType) -> str:
    return frame.f_globals.get("__name__", "") or ""


def _library(module: str) -> bool:
    return any(module == lib or module.startswith(lib + ".") for lib in LIBRARIES)


def _finalizer(frame: FrameType, gc_codes: set) -> bool:
    code = frame.f_code
    if code.co_name in CLEANUP or code in gc_codes:
        return True
    return code.co_name == "__call__" and _module(frame) == "weakref"     # weakref.finalize's callback


def safe_to_interrupt(frame: FrameType | None, boundary: FrameType | None = None) -> bool:
    """Whether raising the interrupt in ``frame`` (the frame the signal handler received) is safe, reading its
    stack up to ``boundary`` (the frame that opened the limit; the whole stack when it is not on it): see the
    module docstring."""
    gc_codes = {getattr(cb, "__code__", None) for cb in gc.callbacks}
    owner: str | None = None          # the innermost module that is not the standard library's
    f = frame
    while f is not None and f is not boundary:
        if _finalizer(f, gc_codes):
            return False
        if f.f_code in _ENTRY_POINTS:
            break
        module = _module(f)
        if _library(module):
            return False
        if owner is None and module.partition(".")[0] not in _STDLIB:
            owner = module
        f = f.f_back
    return owner is None or not owner.startswith(MACHINERY)


__all__ = ["DEFER_STEP", "interruptible", "safe_to_interrupt"]
