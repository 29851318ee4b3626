"""Parameters that are either constants or callables of time ``t``."""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ._validate import real_array
from .errors import InvalidProblem


class Param:
    """A parameter ``p(t)``: a constant (array or scalar) or a callable of ``t``.

    ``Param(c)(t)`` returns a float64 array.  Constants are converted once and
    returned as the same read-only array on every call, so there is no per-step cost.
    """

    __slots__ = ("_fn", "_value", "name")

    def __init__(self, value: Any, name: str = "parameter") -> None:
        self.name = name
        if isinstance(value, Param):
            self._fn, self._value = value._fn, value._value
        elif callable(value):
            self._fn, self._value = value, None
        else:
            arr = np.array(real_array(value, name), dtype=float)   # complex values raise, never truncate
            if not np.all(np.isfinite(arr)):
                raise InvalidProblem(f"{name} must be finite, got {value!r}")
            arr.setflags(write=False)
            self._fn, self._value = None, arr

    @property
    def constant(self) -> bool:
        """True when the parameter does not depend on ``t``."""
        return self._fn is None

    def __call__(self, t: float) -> np.ndarray:
        if self._fn is None:
            return self._value
        v = self._fn(t)
        if type(v) is np.ndarray and v.dtype == np.float64:   # the common case, before any message is built
            return v
        if type(v) is float or type(v) is np.float64:       # real_array's own 0-d float64 array of it
            return np.asarray(v)
        return real_array(v, f"{self.name}({t!r})")

    def of(self, v: Any, t: float) -> np.ndarray:
        """What ``self(t)`` returns when the callable returned ``v`` at ``t`` (for a caller that called it
        itself, to take a scalar's fast path: the callable is called once either way)."""
        if type(v) is np.ndarray and v.dtype == np.float64:
            return v
        if type(v) is float or type(v) is np.float64:
            return np.asarray(v)
        return real_array(v, f"{self.name}({t!r})")

    def at_times(self, ts: np.ndarray) -> np.ndarray:
        """The parameter at every time of ``ts`` (shape ``(B,)``): a constant as it is (it broadcasts against
        the rows), a moving one stacked row by row, ``(B, *shape)``, each row the value of a call at that time
        alone (the user's callable is called once per time, with a Python float: no callable is assumed to
        map an array of times; a run of rows at the same time shares one call, as a batch at one time does)."""
        if self._fn is None:
            return self._value
        ts = np.asarray(ts, dtype=float)
        if ts.size > 1 and np.any(ts[1:] == ts[:-1]):     # a time repeated (its rows together): one call each
            first = np.r_[True, ts[1:] != ts[:-1]]
            values = np.array([self(t) for t in ts[first].tolist()], dtype=float)
            return values[np.cumsum(first) - 1]
        return np.array([self(t) for t in ts.tolist()], dtype=float)

    def describe(self) -> str:
        if self._fn is None:
            return np.array2string(self._value, precision=4, threshold=6)
        return getattr(self._fn, "__name__", "f") + "(t)"


def as_param(value: Any, name: str = "parameter") -> Param:
    """Wrap a constant or a callable of ``t`` as a :class:`Param`."""
    return value if isinstance(value, Param) else Param(value, name)


def scalar_or_call(fn: Callable[[float], Any] | None, t: float) -> Any:
    return None if fn is None else fn(t)
