"""The JSON schema of ``results.json`` and ``baseline.json`` — one document, versioned.

Layout (schema ``verimono.results``, version ``SCHEMA_VERSION`` = ``MAJOR.MINOR``)::

    {
      "schema": "verimono.results",
      "schema_version": "1.1",
      "created": "2025-01-01T12:00:00+00:00",          # UTC, when the document was first written
      "summary": {"passed": 12, "failed": 0, "skipped": 0, "xfail": 0},   # derived, for humans
      "meta": {                                        # free-form facts about the run; keys verimono writes:
        "command": "run" | "check" | "pytest",         #   what produced the records
        "target": "verimono.stepping:solve" | null,     #   the object a `verimono check` verified
        "profile": "ci",                               #   dev | ci | thorough
        "seed": 0 | null,
        "selection": {"stages": [...] | null,          #   the --stage and --reference choices (null: all)
                      "references": [...] | null},
        "stages": [{"name", "status", "records", "duration", "message"}],   # one per stage, in order
        "calibration": 0.012,                          #   seconds of a fixed NumPy workload, same job
        "duration": 93.5,                              #   seconds of the whole run (or pytest session)
        "data_dir": "/path/to/shared" | null,          #   Siconos reference data used, if any
        "environment": {...}                           #   see environment() below
      },
      "results": [CheckResult.to_dict(), ...],         # every record: check, subject, status, worst, bound,
                                                       #   counterexample, message, seed, details, duration
      "studies": [ConvergenceStudy.to_dict(), ...],    # every error of every grid, fits with intervals
      "trajectories": [{"problem", "stepper", "h", "t", "x", "exact"}, ...]   # samples for plots
    }

``environment`` holds ``versions`` (Python and the distributions in ``VERSIONED``, ``null`` when absent;
the optional solvers in ``OPTIONAL`` as ``"not installed"``), ``blas`` (the BLAS libraries NumPy and SciPy
loaded, from ``threadpoolctl``) and ``machine``.  A pytest session (``--verimono-report``) writes
``command``, ``target``, ``profile``, ``seed``, ``duration`` and ``environment`` only.

Non-finite floats are written as the strings ``"inf"``, ``"-inf"``, ``"nan"`` (strict JSON has no such
numbers) and read back as floats where the field is numeric; ``null`` in a numeric list (errors, slopes)
reads as ``nan``.  Reading type-checks every field the gate and the report use (records, their
``details``, the studies' per-grid lists and fits, ``meta.stages``, ``meta.calibration``).
Compatibility: a reader accepts the same MAJOR version and any MINOR (minor versions only add optional
keys; 1.1 added ``environment.blas`` and the optional solvers' versions); anything else, and any
malformed field, is a :class:`SchemaError`, which the gate turns into exit status 2.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import platform
import sys
from importlib import metadata
from pathlib import Path
from typing import Any

from ..errors import VerimonoError
from ..results import CheckResult, Report, to_jsonable

SCHEMA_NAME = "verimono.results"
SCHEMA_VERSION = "1.1"
_NON_FINITE = ("nan", "inf", "-inf", "+inf", "infinity", "-infinity")
#: distributions whose versions every document records
VERSIONED = ("verimono", "numpy", "scipy", "hypothesis", "qpsolvers", "proxsuite", "daqp", "matplotlib",
             "pytest")
#: optional solvers whose versions are recorded, or ``"not installed"``
OPTIONAL = ("cvxpy", "clarabel")


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


def _study_to_dict(study: Any) -> Any:
    return study.to_dict() if hasattr(study, "to_dict") else to_jsonable(study)


def _number(value: Any, where: str, *, allow_null: bool = True) -> float:
    """A numeric field as a float: a JSON number, a non-finite string (``"nan"``, ``"inf"``, ``"-inf"``) or,
    where ``allow_null``, ``null`` (read as ``nan``: a value that was not a number when written)."""
    if value is None and allow_null:
        return math.nan
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    if isinstance(value, str) and value.strip().lower() in _NON_FINITE:
        return float(value)
    raise SchemaError(f"{where} must be a number, got {value!r}")


def _numbers(value: Any, where: str, length: int | None = None) -> list[float]:
    if not isinstance(value, list):
        raise SchemaError(f"{where} must be a list of numbers, got {type(value).__name__}")
    if length is not None and len(value) != length:
        raise SchemaError(f"{where} has {len(value)} entries, expected {length} (one per grid)")
    return [_number(v, f"{where}[{i}]") for i, v in enumerate(value)]


def _study_from_dict(data: Any, i: int = 0) -> Any:
    """A :class:`ConvergenceStudy` from its dict, every field the gate and report read type-checked."""
    from ..convergence import NORMS, ConvergenceStudy

    if not isinstance(data, dict):
        raise SchemaError(f"convergence study {i} must be an object, got {type(data).__name__}")
    where = f"convergence study {i} ({data.get('problem')!r})"
    missing = {"problem", "stepper", "mesh", "steps", "errors", "fits", "floor", "timings"} - data.keys()
    if missing:
        raise SchemaError(f"{where} lacks {sorted(missing)}")
    for key in ("problem", "stepper"):
        if not isinstance(data[key], str):
            raise SchemaError(f"{where}: {key} must be a string, got {data[key]!r}")
    d = dict(data)
    d["mesh"] = _numbers(data["mesh"], f"{where}: mesh")
    if not all(math.isfinite(h) and h > 0 for h in d["mesh"]):
        raise SchemaError(f"{where}: mesh sizes must be finite and positive, got {data['mesh']!r}")
    n = len(d["mesh"])
    steps = data["steps"]
    if not (isinstance(steps, list) and len(steps) == n
            and all(isinstance(k, int) and not isinstance(k, bool) for k in steps)):
        raise SchemaError(f"{where}: steps must be {n} integers (one per grid), got {steps!r}")
    errors, fits = data["errors"], data["fits"]
    for key, value in (("errors", errors), ("fits", fits)):
        if not isinstance(value, dict) or not set(NORMS) <= value.keys():
            raise SchemaError(f"{where}: {key} must map each norm {list(NORMS)} to its values, got {value!r:.80}")
    d["errors"] = {norm: _numbers(e, f"{where}: errors[{norm!r}]", n) for norm, e in errors.items()}
    d["fits"] = {}
    for norm, fit in fits.items():
        w = f"{where}: fits[{norm!r}]"
        if not isinstance(fit, dict) or not {"slope", "low", "high", "used", "dropped", "local_slopes",
                                             "pre_asymptotic"} <= fit.keys():
            raise SchemaError(f"{w} must be an object with slope, low, high, used, dropped, local_slopes and "
                              f"pre_asymptotic, got {fit!r:.80}")
        f = dict(fit)
        for key in ("slope", "low", "high"):
            f[key] = _number(fit[key], f"{w}.{key}")
        f["local_slopes"] = _numbers(fit["local_slopes"], f"{w}.local_slopes")
        d["fits"][norm] = f
    exp = data.get("expected")
    if exp is not None and not (isinstance(exp, dict) and isinstance(exp.get("exact", False), bool)
                                and (exp.get("value") is None or isinstance(exp.get("value"), (int, float)))):
        raise SchemaError(f"{where}: expected must be null or an order object, got {exp!r:.80}")
    d["floor"] = _number(data["floor"], f"{where}: floor", allow_null=False)
    d["timings"] = _numbers(data["timings"], f"{where}: timings")
    try:
        return ConvergenceStudy.from_dict(d)
    except (TypeError, KeyError, ValueError) as exc:
        raise SchemaError(f"malformed {where}: {exc}") from None


def _record_from_dict(data: Any, i: int) -> CheckResult:
    """A :class:`CheckResult` from its dict, every field the gate and report read type-checked."""
    if not isinstance(data, dict):
        raise SchemaError(f"malformed result record {i}: expected an object, got {data!r:.80}")
    where = f"malformed result record {i} ({data.get('check')!r})"
    for key in ("check", "subject", "status"):
        if not isinstance(data.get(key), str):
            raise SchemaError(f"{where}: {key} must be a string, got {data.get(key)!r}")
    if not isinstance(data.get("details", {}), dict):
        raise SchemaError(f"{where}: details must be an object, got {data.get('details')!r:.80}")
    if not isinstance(data.get("message", ""), (str, type(None))):
        raise SchemaError(f"{where}: message must be a string, got {data.get('message')!r:.80}")
    seed = data.get("seed")
    if seed is not None and (not isinstance(seed, int) or isinstance(seed, bool)):
        raise SchemaError(f"{where}: seed must be an integer or null, got {seed!r}")
    d = dict(data)
    for key in ("worst", "bound", "duration"):
        if d.get(key) is not None:
            d[key] = _number(d[key], f"{where}: {key}")
    try:
        return CheckResult.from_dict(d)
    except (TypeError, ValueError, KeyError) as exc:
        raise SchemaError(f"{where}: {exc}") from None


def _check_meta(meta: dict[str, Any]) -> None:
    """The run facts the gate compares: command/target/profile strings, stages, calibration."""
    for key in ("command", "target", "profile"):
        if not isinstance(meta.get(key), (str, type(None))):
            raise SchemaError(f"meta.{key} must be a string or null, got {meta.get(key)!r:.80}")
    if meta.get("selection") is not None and not isinstance(meta["selection"], dict):
        raise SchemaError(f"meta.selection must be an object or null, got {meta['selection']!r:.80}")
    cal = meta.get("calibration")
    if cal is not None and not (isinstance(cal, (int, float)) and not isinstance(cal, bool)
                                and math.isfinite(cal) and cal > 0):
        raise SchemaError(f"meta.calibration must be a positive number of seconds or null, got {cal!r:.80}")
    stages = meta.get("stages")
    if stages is None:
        return
    if not isinstance(stages, list):
        raise SchemaError(f"meta.stages must be a list of stage objects, got {stages!r:.80}")
    for k, st in enumerate(stages):
        ok = (isinstance(st, dict) and isinstance(st.get("name"), str)
              and isinstance(st.get("duration"), (int, float)) and not isinstance(st.get("duration"), bool)
              and math.isfinite(st["duration"]) and st["duration"] >= 0)
        if not ok:
            raise SchemaError(f"meta.stages[{k}] must be an object with a name and a duration in seconds, "
                              f"got {st!r:.80}")


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
    _check_meta(data["meta"])


def report_from_dict(data: Any) -> Report:
    """Read a schema document back into a :class:`Report` (inverse of :func:`report_to_dict`)."""
    check_compatible(data)
    results = [_record_from_dict(r, i) for i, r in enumerate(data["results"])]
    studies = [_study_from_dict(s, i) for i, s in enumerate(data["studies"])]
    trajectories = data.get("trajectories") or []
    if not isinstance(trajectories, list):
        raise SchemaError(f"trajectories must be a list, got {type(trajectories).__name__}")
    meta = dict(data["meta"])
    meta["created"] = data.get("created")
    return Report(results, studies, meta, list(trajectories))


def loads(text: str, source: str = "<string>") -> Report:
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise SchemaError(f"{source} is not valid JSON ({exc})") from None
    except RecursionError:      # pathologically nested arrays/objects: unreadable, not a crash
        raise SchemaError(f"{source} is nested too deeply to be a verimono document") from None
    except (ValueError, MemoryError) as exc:
        raise SchemaError(f"{source} cannot be parsed ({type(exc).__name__}: {exc})") from None
    try:
        return report_from_dict(data)
    except RecursionError:
        raise SchemaError(f"{source} is nested too deeply to be a verimono document") from None
    except (TypeError, AttributeError, KeyError, IndexError, ValueError, OverflowError) as exc:
        # a field of an unexpected type that the type checks above did not anticipate: unreadable
        raise SchemaError(f"{source} is malformed ({type(exc).__name__}: {exc})") from None


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


__all__ = ["SCHEMA_NAME", "SCHEMA_VERSION", "VERSIONED", "OPTIONAL", "SchemaError", "environment",
           "report_to_dict", "report_from_dict", "check_compatible", "loads", "load"]
