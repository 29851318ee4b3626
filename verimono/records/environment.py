"""The environment a run was measured in: versions of Python and of the libraries that shape results, the
BLAS in use, and the machine (``meta.environment`` of a results document, :mod:`verimono.records.schema`)."""

from __future__ import annotations

import os
import platform
import sys
from typing import Any

#: distributions whose versions every document records
VERSIONED = ("verimono", "numpy", "scipy", "hypothesis", "qpsolvers", "proxsuite", "daqp", "matplotlib",
             "pytest")
#: optional solvers whose versions are recorded, or ``"not installed"``
OPTIONAL = ("cvxpy", "clarabel")


def _version(dist: str) -> str | None:
    from importlib import metadata  # stdlib, but slow to import: only when a document is written

    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return None


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.lower().startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _memory_gb() -> float | None:
    try:
        return round(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30, 1)
    except (ValueError, OSError, AttributeError):
        return None


def _blas() -> list[dict[str, Any]]:
    """The BLAS libraries loaded in this process (NumPy's, SciPy's), as ``threadpoolctl`` reports them."""
    try:
        import numpy  # noqa: F401  (loads NumPy's BLAS so that threadpoolctl sees it)
        from threadpoolctl import threadpool_info
    except ImportError:
        return []
    keys = ("internal_api", "version", "prefix", "threading_layer", "architecture", "num_threads")
    return [{k: info.get(k) for k in keys} for info in threadpool_info() if info.get("user_api") == "blas"]


def environment() -> dict[str, Any]:
    """Versions of Python and the libraries that shape results, the BLAS in use, and the machine."""
    versions = {"python": platform.python_version()}
    versions.update({d: _version(d) for d in VERSIONED})
    versions.update({d: _version(d) or "not installed" for d in OPTIONAL})
    return {
        "versions": versions,
        "blas": _blas(),
        "machine": {
            "system": f"{platform.system()} {platform.release()}",
            "platform": platform.platform(),
            "architecture": platform.machine(),
            "cpu": _cpu_model(),
            "cpu_count": os.cpu_count(),
            "memory_gb": _memory_gb(),
            "python_implementation": platform.python_implementation(),
            "python_executable": sys.executable,
        },
    }


__all__ = ["environment", "VERSIONED", "OPTIONAL"]
