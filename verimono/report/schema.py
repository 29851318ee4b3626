"""The JSON schema of ``results.json`` and ``baseline.json`` — one document, versioned.

Layout (schema ``verimono.results``, version ``SCHEMA_VERSION`` = ``MAJOR.MINOR``)::

    {
      "schema": "verimono.results",
      "schema_version": "1.0",
      "created": "2025-01-01T12:00:00+00:00",          # UTC, when the document was first written
      "summary": {"passed": 12, "failed": 0, "skipped": 0, "xfail": 0},   # derived, for humans
      "meta": {                                        # free-form facts about the run; keys verimono writes:
        "command": "run" | "check" | "pytest",         #   what produced the records
        "target": "verimono.stepping:solve" | null,     #   the object a `verimono check` verified
        "profile": "ci",                               #   dev | ci | thorough
        "seed": 0 | null,
        "stages": [{"name", "status", "records", "duration", "message"}],   # one per stage, in order
        "calibration": 0.012,                          #   seconds of a fixed NumPy workload, same job
        "data_dir": "/path/to/shared" | null,          #   Siconos reference data used, if any
        "environment": {...}                           #   see environment() below
      },
      "results": [CheckResult.to_dict(), ...],         # every record: check, subject, status, worst, bound,
                                                       #   counterexample, message, seed, details, duration
      "studies": [ConvergenceStudy.to_dict(), ...],    # every error of every grid, fits with intervals
      "trajectories": [{"problem", "stepper", "h", "t", "x", "exact"}, ...]   # samples for plots
    }

Non-finite floats are written as the strings ``"inf"``, ``"-inf"``, ``"nan"`` (strict JSON has no such
numbers) and read back as floats where the field is numeric.  Compatibility: a reader accepts the same
MAJOR version and any MINOR (minor versions only add optional keys); anything else is a
:class:`SchemaError`, which the gate turns into exit status 2.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import platform
import sys
from importlib import metadata
from pathlib import Path
from typing import Any

from ..errors import VerimonoError
from ..results import CheckResult, Report, to_jsonable

SCHEMA_NAME = "verimono.results"
SCHEMA_VERSION = "1.0"
#: distributions whose versions every document records
VERSIONED = ("verimono", "numpy", "scipy", "hypothesis", "qpsolvers", "proxsuite", "daqp", "matplotlib",
             "pytest")


class SchemaError(VerimonoError, ValueError):
    """A results/baseline document is missing, not JSON, not verimono's, or of an incompatible version."""


def _version(dist: str) -> str | None:
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


def environment() -> dict[str, Any]:
    """Versions of Python and the libraries that shape results, and the machine they ran on."""
    versions = {"python": platform.python_version()}
    versions.update({d: _version(d) for d in VERSIONED})
    return {
        "versions": versions,
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


def _study_to_dict(study: Any) -> Any:
    return study.to_dict() if hasattr(study, "to_dict") else to_jsonable(study)


def _study_from_dict(data: Any) -> Any:
    from ..convergence import ConvergenceStudy

    if isinstance(data, dict) and {"problem", "stepper", "mesh", "errors", "fits"} <= data.keys():
        try:
            return ConvergenceStudy.from_dict(data)
        except (TypeError, KeyError, ValueError) as exc:
            raise SchemaError(f"malformed convergence study for {data.get('problem')!r}: {exc}") from None
    return data


def report_to_dict(report: Report) -> dict[str, Any]:
    """The schema document of ``report``; fills ``meta.environment`` and ``created`` when absent."""
    meta = dict(report.meta)
    meta.setdefault("environment", environment())
    created = meta.pop("created", None) or _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
    report.meta.setdefault("environment", meta["environment"])
    report.meta.setdefault("created", created)
    return {
        "schema": SCHEMA_NAME,
        "schema_version": SCHEMA_VERSION,
        "created": created,
        "summary": report.counts,
        "meta": to_jsonable(meta),
        "results": [r.to_dict() for r in report.results],
        "studies": [_study_to_dict(s) for s in report.studies],
        "trajectories": to_jsonable(report.trajectories),
    }


def check_compatible(data: Any) -> None:
    """Raise :class:`SchemaError` unless ``data`` is a document this version of verimono can read."""
    if not isinstance(data, dict):
        raise SchemaError(f"expected a JSON object, got {type(data).__name__}")
    if data.get("schema") != SCHEMA_NAME:
        raise SchemaError(f"not a verimono results document (schema = {data.get('schema')!r}, "
                          f"expected {SCHEMA_NAME!r})")
    version = str(data.get("schema_version", ""))
    if version.split(".")[0] != SCHEMA_VERSION.split(".")[0]:
        raise SchemaError(f"incompatible schema version {version!r}: this verimono reads "
                          f"{SCHEMA_VERSION.split('.')[0]}.x; regenerate it with `verimono baseline`")
    for key, kind in (("results", list), ("studies", list), ("meta", dict)):
        if not isinstance(data.get(key), kind):
            raise SchemaError(f"document lacks a {kind.__name__} {key!r}")


def report_from_dict(data: Any) -> Report:
    """Read a schema document back into a :class:`Report` (inverse of :func:`report_to_dict`)."""
    check_compatible(data)
    try:
        results = [CheckResult.from_dict(r) for r in data["results"]]
    except (TypeError, ValueError, KeyError) as exc:
        raise SchemaError(f"malformed result record: {exc}") from None
    meta = dict(data["meta"])
    meta["created"] = data.get("created")
    return Report(results, [_study_from_dict(s) for s in data["studies"]], meta,
                  list(data.get("trajectories") or []))


def loads(text: str, source: str = "<string>") -> Report:
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise SchemaError(f"{source} is not valid JSON ({exc})") from None
    return report_from_dict(data)


def load(path: str | Path) -> Report:
    """Read ``path``; :class:`SchemaError` (with the path) if it is missing, garbled or incompatible."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SchemaError(f"{path} does not exist") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SchemaError(f"{path} cannot be read: {exc}") from None
    try:
        return loads(text, str(path))
    except SchemaError as exc:
        msg = str(exc)
        raise SchemaError(msg if str(path) in msg else f"{path}: {msg}") from None


__all__ = ["SCHEMA_NAME", "SCHEMA_VERSION", "SchemaError", "environment", "report_to_dict",
           "report_from_dict", "check_compatible", "loads", "load"]
