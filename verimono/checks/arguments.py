"""The arguments every public check validates the same way: a seed, a time horizon (typed errors, no hypothesis
import: the stepper laws take them too)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..core.errors import InvalidCheckArgument


def valid_seed(seed: Any) -> int:
    """``seed`` as a non-negative integer; :class:`InvalidCheckArgument` otherwise."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidCheckArgument(f"seed must be a non-negative integer, got {seed!r}")
    return int(seed)


def valid_horizon(horizon: Any) -> float:
    """``horizon`` as a finite time ``≥ 0``; :class:`InvalidCheckArgument` otherwise."""
    if isinstance(horizon, bool) or not isinstance(horizon, (int, float, np.integer, np.floating)) \
            or not (math.isfinite(horizon) and horizon >= 0):
        raise InvalidCheckArgument(f"horizon must be a finite time >= 0, got {horizon!r}")
    return float(horizon)


__all__ = ["valid_seed", "valid_horizon"]
