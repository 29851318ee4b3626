"""Module paths that moved keep working: ``verimono.stepping`` is ``verimono.core.stepping``.

A meta-path finder answers for the old names only; the module it returns is the one of the new home (the same
object in ``sys.modules`` under both names), so patching, pickling and ``isinstance`` see one module.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
from types import ModuleType
from typing import Mapping


class _MovedModules(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    def __init__(self, package: str, moved: Mapping[str, str]):
        self.targets = {f"{package}.{old}": f"{package}.{new}" for old, new in moved.items()}
        # every import after ``import verimono`` asks this finder first (SciPy's, hypothesis's: ~630 on the
        # check path): one C-level prefix test answers the others (the loop below cost 0.03-0.05 s of them)
        self._packages = tuple(old + "." for old in self.targets)

    def _target(self, name: str) -> str | None:
        if name in self.targets:
            return self.targets[name]
        if not name.startswith(self._packages):
            return None
        for old, new in self.targets.items():   # a submodule of a moved package
            if name.startswith(old + "."):
                return new + name[len(old):]
        return None

    def find_spec(self, name, path=None, target=None):
        new = self._target(name)
        if new is None:
            return None
        return importlib.machinery.ModuleSpec(name, self, is_package=False)

    def create_module(self, spec) -> ModuleType:
        module = importlib.import_module(self._target(spec.name))
        spec.loader_state = module.__spec__
        return module

    def exec_module(self, module: ModuleType) -> None:
        """Nothing to run (:meth:`create_module` imported the new home); the import system has just set the
        module's ``__spec__`` to the old name's, which would misdirect its own relative imports: restore it."""
        module.__spec__ = module.__spec__.loader_state


def install_moved_modules(package: str, moved: Mapping[str, str]) -> None:
    """Register the finder for ``package``'s moved modules (once per process)."""
    if not any(isinstance(f, _MovedModules) for f in sys.meta_path):
        sys.meta_path.insert(0, _MovedModules(package, moved))
