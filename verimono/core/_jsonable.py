"""Plain JSON values from NumPy values and dataclasses (the bottom of the saving layer; imports nothing of
verimono).  Re-exported as :func:`verimono.records.results.to_jsonable`."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np


def to_jsonable(value: Any) -> Any:
    """Convert numpy values (recursively) to plain JSON types; non-finite floats become strings.

    An object with a ``to_dict()`` method (a :class:`verimono.ConvergenceStudy`) is written as that dict;
    any other dataclass field by field.
    """
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        if all(type(v) is float and v - v == 0.0 for v in value):   # finite floats (a trajectory): as they are
            return list(value)
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        if value.dtype.kind == "f" and np.isfinite(value).all():
            return value.tolist()                                  # nested lists of finite floats
        return to_jsonable(value.tolist())
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return v if math.isfinite(v) else repr(v)
    if value is None or isinstance(value, (int, str)):
        return value
    if callable(getattr(value, "to_dict", None)) and not isinstance(value, type):
        return to_jsonable(value.to_dict())
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return to_jsonable(dataclasses.asdict(value))
    return repr(value)


__all__ = ["to_jsonable"]
