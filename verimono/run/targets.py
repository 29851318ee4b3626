"""Targets of ``verimono check MODULE:OBJECT``: importing the user's object by name or from a file.

``MODULE`` is a dotted module name (``pkg.solvers``: each part an identifier) or the path of an existing
regular ``.py`` file; ``OBJECT`` is a dotted attribute path.  Anything else — a relative or absolute path
that is not a ``.py`` file, a folder or FIFO named ``x.py``, a module that fails to import (whatever it
raises, ``SystemExit`` included) — is a :class:`verimono.BadTarget` naming the target: bad usage (exit
status 2), never a failure of the subject and never a crash of verimono.
"""

from __future__ import annotations

import importlib
import os
import sys
from pathlib import Path
from typing import Any

from ..core.errors import BadTarget


def _load_file(path: Path) -> Any:
    """The module in the file ``path`` itself — not whatever module of the same name is importable (a
    ``types.py`` or a second ``lagged.py`` elsewhere); its folder is put on ``sys.path`` for its own
    imports of neighbouring modules."""
    import importlib.util

    try:
        path = path.resolve()
        exists, regular = path.exists(), path.is_file()
    except (OSError, ValueError, RuntimeError) as exc:   # a NUL byte, a symlink loop, a name too long
        raise BadTarget(f"{path} cannot be read as a Python file: {exc}") from None
    if not exists:
        raise BadTarget(f"{path} does not exist")
    if not regular:
        raise BadTarget(f"{path} is not a regular file (a folder, FIFO or device): a target module is a .py file")
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
    except (Exception, SystemExit) as exc:     # its own error, or a sys.exit() at import: never verimono's status
        sys.modules.pop(name, None)
        raise BadTarget(f"cannot import {path}: {type(exc).__name__}: {exc}") from None
    return module


def _dotted(name: str) -> bool:
    return bool(name) and all(part.isidentifier() for part in name.split("."))


def load_target(spec: str) -> Any:
    """Import ``MODULE:OBJECT`` (``MODULE`` may be a dotted name or a ``.py`` path; ``OBJECT`` dotted);
    :class:`BadTarget` on anything else (see the module docstring)."""
    module_name, sep, attr = spec.rpartition(":") if spec.count(":") > 1 else spec.partition(":")
    if not sep or not module_name or not attr:
        raise BadTarget(f"expected MODULE:OBJECT (e.g. mypackage.solvers:my_stepper), got {spec!r}")
    if not _dotted(attr):
        raise BadTarget(f"{spec!r}: OBJECT must be a dotted Python name (e.g. my_stepper or Solvers.step), "
                        f"got {attr!r}")
    if module_name.endswith(".py"):
        obj: Any = _load_file(Path(module_name))
    elif not _dotted(module_name):
        raise BadTarget(f"{spec!r}: MODULE must be a dotted module name (e.g. mypackage.solvers) or the path of "
                        f"a .py file, got {module_name!r}")
    else:
        if "" not in sys.path and os.getcwd() not in sys.path:
            sys.path.insert(0, os.getcwd())
        try:
            obj = importlib.import_module(module_name)
        except ImportError as exc:
            raise BadTarget(f"cannot import {module_name!r}: {exc}") from None
        except (Exception, SystemExit) as exc:   # the module's own error at import time
            raise BadTarget(f"cannot import {module_name!r}: {type(exc).__name__}: {exc}") from None
    for part in attr.split("."):
        try:
            obj = getattr(obj, part)
        except AttributeError:
            raise BadTarget(f"{module_name!r} has no attribute {attr!r}") from None
    return obj


__all__ = ["load_target"]
