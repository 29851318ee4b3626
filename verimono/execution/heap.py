"""Freed large blocks kept by the C allocator for one battery in a large dimension (glibc only).

A law at n = 10^6 makes a few 8 MB arrays per sample (the points, their resolvents, differences) and frees them
when the sample ends.  glibc's ``free`` gives the top of its heap back to the system once more than its trim
threshold (twice its dynamic mmap threshold: about 16 MB after 8 MB blocks) lies free there, and blocks above
the mmap threshold are unmapped at once; the next sample's arrays are then faulted in again page by page, the
kernel zeroing each page.  Measured (branch bigop4, docs/speed.md): ``check_operator(NormSubdifferential(1 + t,
10^6), seed=0, profile="ci")`` took 3.66 million minor page faults and 16.3 s of system CPU (of 89 s); with the
thresholds raised as here, 68 thousand faults and 0.44 s, the user CPU the same (72.7 and 72.9 s).

:func:`heap_kept` raises both thresholds for the length of a battery whose subject has more than
:data:`verimono.execution.profiles.LARGE_N` coordinates, then gives the free memory back (``malloc_trim``).
glibc has no call that reads its thresholds or restores its dynamic rule once ``mallopt`` set them, so after
the battery they stay at the dynamic rule's ceiling (:data:`AFTER_MMAP`, :data:`AFTER_TRIM`: what glibc's
own rule reaches after freeing blocks of 32 MB or more).  Elsewhere (another C library, a small subject) it
does nothing.  Only the allocator's bookkeeping changes: every array, every number, every record is the same.
"""

from __future__ import annotations

import contextlib
import ctypes
import threading
from typing import Iterator

from .profiles import LARGE_N

#: glibc's ``mallopt`` parameters (``malloc.h``)
M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
#: the mmap threshold during a battery: glibc's largest (``DEFAULT_MMAP_THRESHOLD_MAX`` on 64-bit; an 8 MB
#: n-vector at n = 10^6 and blocks of rows up to 32 MB come from the heap and go back to it)
KEPT_MMAP = 32 << 20
#: the trim threshold during a battery: free memory at the heap's top up to 1 GiB is kept for the next sample
#: (the battery's peak is its live arrays; this only keeps what it freed, until the battery ends)
KEPT_TRIM = 1 << 30
#: the thresholds left after a battery: glibc's dynamic rule's ceiling (mmap 32 MB, trim twice that)
AFTER_MMAP, AFTER_TRIM = 32 << 20, 64 << 20

_lock = threading.Lock()
_depth = 0


def _glibc():
    """The C library's ``mallopt``/``malloc_trim`` when it is glibc, else ``None``."""
    try:
        libc = ctypes.CDLL(None)
        libc.gnu_get_libc_version          # glibc only
        return libc.mallopt, libc.malloc_trim
    except (OSError, AttributeError, TypeError):     # TypeError: Windows' LoadLibrary needs a name
        return None


@contextlib.contextmanager
def heap_kept(n: int) -> Iterator[bool]:
    """Freed blocks kept by glibc's allocator while a battery on a subject of ``n`` coordinates runs (yields
    whether it did: only above ``LARGE_N`` and with glibc).  Nested and concurrent batteries share one setting;
    the last to end gives the free memory back."""
    global _depth
    calls = _glibc() if n > LARGE_N else None
    if calls is None:
        yield False
        return
    mallopt, malloc_trim = calls
    with _lock:
        if _depth == 0:
            mallopt(M_MMAP_THRESHOLD, KEPT_MMAP)
            mallopt(M_TRIM_THRESHOLD, KEPT_TRIM)
        _depth += 1
    try:
        yield True
    finally:
        with _lock:
            _depth -= 1
            if _depth == 0:
                mallopt(M_TRIM_THRESHOLD, AFTER_TRIM)
                mallopt(M_MMAP_THRESHOLD, AFTER_MMAP)
                malloc_trim(0)


__all__ = ["heap_kept", "KEPT_MMAP", "KEPT_TRIM", "AFTER_MMAP", "AFTER_TRIM"]
