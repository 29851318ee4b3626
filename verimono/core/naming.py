"""The name of a subject — an operator, a problem, a stepper — decided once for every record of it."""

from __future__ import annotations

from typing import Any


def subject_name(obj: Any) -> str:
    """The subject's ``name`` (an operator's, a problem's, a :class:`verimono.Stepper`'s), else its
    ``__name__`` (a function), else its type's name.  It is the key the gate compares, whatever a record's
    status."""
    for attr in ("name", "__name__"):
        value = getattr(obj, attr, None)
        if isinstance(value, str) and value:
            return value
    return type(obj).__name__


__all__ = ["subject_name"]
