"""Targets of ``verimono check MODULE:OBJECT``: importing the user's object by name or from a file."""

from __future__ import annotations

import importlib
import os
import sys
from pathlib import Path
from typing import Any

from .errors import BadTarget


def _load_file(path: Path) -> Any:
    """The module in the file ``path`` itself — not whatever module of the same name is importable (a
    ``types.py`` or a second ``lagged.py`` elsewhere); its folder is put on ``sys.path`` for its own
    imports of neighbouring modules."""
    import importlib.util

    path = path.resolve()
    if not path.is_file():
        raise BadTarget(f"{path} does not exist")
    name = f"verimono_target_{abs(hash(str(path))):x}_{path.stem}"
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise BadTarget(f"cannot load {path} as a Python module")
    module = importlib.util.module_from_spec(spec)
    if str(path.parent) not in sys.path:
        sys.path.insert(0, str(path.parent))
    sys.modules[name] = module           # dataclasses, pickling and relative lookups need it registered
    try:
        spec.loader.exec_module(module)
    except Exception as exc:
        sys.modules.pop(name, None)
        raise BadTarget(f"cannot import {path}: {type(exc).__name__}: {exc}") from None
    return module


def load_target(spec: str) -> Any:
    """Import ``MODULE:OBJECT`` (``MODULE`` may be a dotted name or a ``.py`` path; ``OBJECT`` dotted)."""
    module_name, sep, attr = spec.partition(":")
    if not sep or not module_name or not attr:
        raise BadTarget(f"expected MODULE:OBJECT (e.g. mypackage.solvers:my_stepper), got {spec!r}")
    if module_name.endswith(".py"):
        obj: Any = _load_file(Path(module_name))
    else:
        if "" not in sys.path and os.getcwd() not in sys.path:
            sys.path.insert(0, os.getcwd())
        try:
            obj = importlib.import_module(module_name)
        except ImportError as exc:
            raise BadTarget(f"cannot import {module_name!r}: {exc}") from None
    for part in attr.split("."):
        try:
            obj = getattr(obj, part)
        except AttributeError:
            raise BadTarget(f"{module_name!r} has no attribute {attr!r}") from None
    return obj


__all__ = ["load_target"]
