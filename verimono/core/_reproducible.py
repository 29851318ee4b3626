"""Searches that depend on the seed only, not on what else the user imported.

Hypothesis (6.13x and later, checked on the installed 6.170) mixes *local constants* into generation: with
probability 5–15 % a drawn integer or float is replaced by a numeric literal collected, through their
source, from every imported module it deems local (not in site-packages or the standard library; see
``hypothesis.internal.conjecture.providers._get_local_constants``).  The same ``seed`` then draws other
samples after the user imports an unrelated module of constants — and a verdict or a reproduction command
changes with the imports.  No public setting turns this off (the ``backend`` setting swaps the whole
provider and changes shrinking and replay), so :func:`no_local_constants` empties that pool for the
duration of a verimono search: the provider's module-level ``_get_local_constants`` is replaced by one
returning no constants, and its cache of permitted constants by a fresh one, both restored afterwards.
Hypothesis' *global* constants (a fixed list in its source) still apply: they depend on nothing imported.

On a hypothesis without these internals the context manager does nothing (there is then nothing to turn
off, or the mechanism moved: ``tests/core/test_prox_reproducible.py`` detects that by comparing records).
"""

from __future__ import annotations

import contextlib
import threading
from typing import Iterator

_LOCK = threading.RLock()


@contextlib.contextmanager
def no_local_constants() -> Iterator[bool]:
    """Within the block hypothesis draws no constants collected from imported modules; yields whether the
    mechanism was found (and switched off)."""
    try:
        from hypothesis.internal.conjecture import providers as _p
        from hypothesis.internal.constants_ast import Constants
        from hypothesis.internal.cache import LRUCache
    except ImportError:   # an older or newer hypothesis without local constants
        yield False
        return
    get, cache = getattr(_p, "_get_local_constants", None), getattr(_p, "CONSTANTS_CACHE", None)
    if get is None or cache is None:
        yield False
        return
    empty = Constants()
    with _LOCK:
        _p._get_local_constants = lambda: empty
        _p.CONSTANTS_CACHE = LRUCache(1024)
        try:
            yield True
        finally:
            _p._get_local_constants = get
            _p.CONSTANTS_CACHE = cache


__all__ = ["no_local_constants"]
