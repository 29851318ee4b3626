"""The JSON document of ``results.json`` and ``baseline.json``: its layout, its version, and the type
checks every field the gate and the report read passes when it is read back.

Layout (schema ``verimono.results``, version ``SCHEMA_VERSION`` = ``MAJOR.MINOR``)::

    {
      "schema": "verimono.results",
      "schema_version": "1.4",
      "created": "2025-01-01T12:00:00+00:00",          # UTC, when the document was first written
      "summary": {"passed": 12, "failed": 0, "skipped": 0, "xfail": 0},   # derived, for humans
      "meta": {                                        # free-form facts about the run; keys verimono writes:
        "command": "run" | "check" | "pytest",         #   what produced the records
        "target": "verimono.stepping:solve" | null,     #   the object a `verimono check` verified
        "profile": "ci",                               #   dev | ci | thorough
        "seed": 0 | null,
        "config": {"profile", "source", "budget",      #   the run configuration the entry point chose
                   "seed", "executor", "unit_budget"},  #   (verimono.execution.config) and the unit budget
        "selection": {"stages": [...] | null,          #   the --stage and --reference choices (null: all)
                      "references": [...] | null},
        "stages": [{"name", "status", "records", "duration", "message",     # one per stage, in order
                    "cpu",                             #   CPU seconds of the stage's work (all processes)
                    "calibration_cpu": [0.07, ...],    #   the calibration's CPU seconds, sampled beside it
                    "subject_cpu", "subject_calls",    #   the part in the subject's calls (verimono check)
                    "units": [{"label", "cpu", "wall"}],   # each unit's times
                    "overlapped": [...], "group_duration",  #   ran at once with these stages (their units in
                                                       #   one queue): "duration" is then its span among them,
                                                       #   "group_duration" their wall together
                    "cpu_waiting", "foreign_cpu", "loadavg"}],   # how busy the machine was
        "executor": "serial" | "process:2" | ...,      #   where the stages' units ran (stage times compare
                                                       #   only between runs on the same executor)
        "calibrations": [0.012, 0.013],                #   the workload timed before and after the stages (the start's alone: no record timed)
        "calibration": 0.012,                          #   the faster of the two: the unit of stage times
        "calibrations_cpu": [0.011, 0.011],            #   their CPU seconds (median of the repeats)
        "duration": 93.5,                              #   seconds of the whole run (or pytest session)
        "data_dir": "/path/to/shared" | null,          #   Siconos reference data used, if any
        "environment": {...},                          #   :func:`verimono.records.environment.environment`
        "run_id": "3f2a9c0d1e4b5a67",                  #   shared with report.html (and the in-progress mark)
        "incomplete": true, "finished_stages": [...],  #   only in an interrupted run's results
        "resumed_from": "9b8a..."                      #   the run id a `--resume` continued
      },
      "results": [CheckResult.to_dict(), ...],         # every record: check, subject, status, worst, bound,
                                                       #   counterexample, message, seed, details, duration
      "studies": [ConvergenceStudy.to_dict(), ...],    # every error of every grid, fits with intervals
      "trajectories": [{"problem", "stepper", "h", "t", "x", "exact"}, ...]   # samples for plots
    }

A record's ``details`` are free-form; keys that producers hand to consumers: ``study`` (a convergence-order
record's study, read back as a :class:`ConvergenceStudy`), ``stage`` and ``reference`` (set by the run),
``reproduce``, ``reproduce_python``, ``example`` (what the report's reproduction shows), ``error`` and
``timing_ratio`` (compared by the gate), ``xfail_declared`` (why an ``xfail`` was expected) and
``unearned_pass`` (a pass claimed with a non-finite worst ratio, turned into a failure).  A record's key
``check[subject]`` is unique in a document: the gate refuses one that repeats a key.

Non-finite floats are written as the strings ``"inf"``, ``"-inf"``, ``"nan"`` (strict JSON has no such
numbers) and read back as floats where the field is numeric; ``null`` in a numeric list (errors, slopes)
reads as ``nan``.  Compatibility: a reader accepts the same MAJOR version and any MINOR (minor versions only
add optional keys; 1.1 added ``environment.blas`` and the optional solvers' versions, 1.2 a study's
``floors`` and ``solve_tol``, 1.3 the stages' CPU times: the gate refuses a baseline with stage times
but without them, :func:`verimono.run.gate.baseline_uncalibrated`; 1.4 a stage's ``overlapped`` and
``group_duration``, the stages that ran at once, whose walls the gate compares together); anything else, and
any malformed field, is a :class:`SchemaError`, which the gate turns into exit status 2.  Writing and
reading whole reports: :mod:`verimono.records.results` (``Report.save``, ``load``).
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import stat
from pathlib import Path
from typing import Any

from ..core._jsonable import to_jsonable
from ..core.convergence import NORMS, ConvergenceStudy
from .environment import environment
from ..core.errors import SchemaError

SCHEMA_NAME = "verimono.results"
SCHEMA_VERSION = "1.4"
_NON_FINITE = ("nan", "inf", "-inf", "+inf", "infinity", "-infinity")
#: the fields of a result record
RECORD_FIELDS = frozenset({"check", "subject", "status", "worst", "bound", "counterexample", "message", "seed",
                           "details", "duration"})


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


def study_from_dict(data: Any, i: int | str = 0) -> ConvergenceStudy:
    """A :class:`ConvergenceStudy` from its dict, every field the gate and report read type-checked
    (``i``: its index in ``studies``, or where else it was found)."""
    label = f"convergence study {i}" if isinstance(i, int) else str(i)
    if not isinstance(data, dict):
        raise SchemaError(f"{label} must be an object, got {type(data).__name__}")
    where = f"{label} ({data.get('problem')!r})"
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
    if data.get("floors") is not None:
        d["floors"] = _numbers(data["floors"], f"{where}: floors", n)
    if data.get("solve_tol") is not None:
        d["solve_tol"] = _number(data["solve_tol"], f"{where}: solve_tol", allow_null=False)
    try:
        return ConvergenceStudy.from_dict(d)
    except (TypeError, KeyError, ValueError) as exc:
        raise SchemaError(f"malformed {where}: {exc}") from None


def record_fields(data: Any, i: int) -> dict[str, Any]:
    """The fields of result record ``i`` (``CheckResult`` keyword arguments), every field the gate and the
    report read type-checked, a convergence study in ``details`` read back as a :class:`ConvergenceStudy`."""
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
    if "study" in d.get("details", {}):
        d["details"] = {**d["details"], "study": study_from_dict(d["details"]["study"], f"{where}: details.study")}
    unknown = set(d) - RECORD_FIELDS
    if unknown:
        raise SchemaError(f"{where}: unknown fields {sorted(unknown)}")
    return d


def check_meta(meta: dict[str, Any]) -> None:
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
        for key in ("cpu", "subject_cpu"):
            v = st.get(key)
            if v is not None and not (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                                      and v >= 0):
                raise SchemaError(f"meta.stages[{k}].{key} must be a number of CPU seconds, got {v!r:.80}")
        cals = st.get("calibration_cpu")
        if cals is not None and not (isinstance(cals, list) and cals and all(
                isinstance(c, (int, float)) and not isinstance(c, bool) and math.isfinite(c) and c > 0 for c in cals)):
            raise SchemaError(f"meta.stages[{k}].calibration_cpu must be a list of positive CPU seconds, "
                              f"got {cals!r:.80}")


def document(meta: dict[str, Any], counts: dict[str, int], results: list[dict[str, Any]], studies: list[Any],
             trajectories: list[Any], *, converted: bool = False) -> dict[str, Any]:
    """The schema document of a run; ``meta.environment`` and ``created`` are filled in when absent (and
    written back into ``meta``).  ``converted``: ``studies`` and ``trajectories`` are JSON values already
    (:func:`verimono.core._jsonable.to_jsonable`'s), taken as they are."""
    if "environment" not in meta:     # not setdefault: that measured it again for a run that had (0.02 s)
        meta["environment"] = environment()
    if not meta.get("created"):
        meta["created"] = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
    written = {k: v for k, v in meta.items() if k != "created"}
    return {
        "schema": SCHEMA_NAME,
        "schema_version": SCHEMA_VERSION,
        "created": meta["created"],
        "summary": counts,
        "meta": to_jsonable(written),
        "results": results,
        "studies": studies if converted else to_jsonable(studies),
        "trajectories": trajectories if converted else to_jsonable(trajectories),
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
    check_meta(data["meta"])


def parse(text: str, source: str = "<string>") -> Any:
    """The JSON value of ``text``; :class:`SchemaError` naming ``source`` when it is not JSON."""
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise SchemaError(f"{source} is not valid JSON ({exc})") from None
    except RecursionError:      # pathologically nested arrays/objects: unreadable, not a crash
        raise SchemaError(f"{source} is nested too deeply to be a verimono document") from None
    except (ValueError, MemoryError) as exc:
        raise SchemaError(f"{source} cannot be parsed ({type(exc).__name__}: {exc})") from None


#: largest document :func:`read_text` reads, in MiB (``$VERIMONO_MAX_DOCUMENT_MIB`` overrides it): the
#: committed baseline of a ci run is 0.6 MiB and a results file with its plot samples a few MiB, so this
#: leaves room for the largest runs while a wrong path (a device, a log) cannot exhaust memory
MAX_DOCUMENT_MIB = 256
MAX_DOCUMENT_ENV = "VERIMONO_MAX_DOCUMENT_MIB"


def max_document_bytes() -> int:
    """The size limit of a document in bytes: ``$VERIMONO_MAX_DOCUMENT_MIB`` (a positive number of MiB) or
    :data:`MAX_DOCUMENT_MIB`; :class:`SchemaError` on a value that is not a positive number."""
    raw = os.environ.get(MAX_DOCUMENT_ENV, "").strip()
    if not raw:
        return MAX_DOCUMENT_MIB << 20
    try:
        mib = float(raw)
    except ValueError:
        mib = math.nan
    if not (math.isfinite(mib) and mib > 0):
        raise SchemaError(f"${MAX_DOCUMENT_ENV} must be a positive number of MiB, got {raw!r}")
    return max(1, int(mib * (1 << 20)))


def read_text(path: str | Path) -> str:
    """The text of the document at ``path``; :class:`SchemaError` (with the path) if it cannot be read.

    Only a regular file is read (a FIFO, ``/dev/zero`` or a folder is refused without reading or blocking:
    it is opened non-blocking and checked with ``fstat`` first), and at most :func:`max_document_bytes`
    of it: a larger file is refused, never read whole."""
    path = Path(path)
    limit = max_document_bytes()
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0))
    except FileNotFoundError:
        raise SchemaError(f"{path} does not exist") from None
    except (OSError, ValueError) as exc:   # ValueError: an embedded NUL byte
        raise SchemaError(f"{path} cannot be read: {getattr(exc, 'strerror', None) or exc}") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            kind = "a folder" if stat.S_ISDIR(st.st_mode) else "not a regular file (a device, FIFO or socket)"
            raise SchemaError(f"{path} is {kind}: a verimono document is a JSON file")
        if st.st_size > limit:
            raise SchemaError(f"{path} is {st.st_size / (1 << 20):.1f} MiB, larger than the limit of "
                              f"{limit / (1 << 20):.4g} MiB for a verimono document (${MAX_DOCUMENT_ENV} raises it)")
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        if size > limit:      # it grew while being read
            raise SchemaError(f"{path} is larger than the limit of {limit / (1 << 20):.4g} MiB for a verimono "
                              f"document (${MAX_DOCUMENT_ENV} raises it)")
        return b"".join(chunks).decode("utf-8")
    except OSError as exc:
        raise SchemaError(f"{path} cannot be read: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise SchemaError(f"{path} cannot be read: {exc}") from None
    finally:
        os.close(fd)


__all__ = ["SCHEMA_NAME", "SCHEMA_VERSION", "RECORD_FIELDS", "SchemaError", "document", "check_compatible",
           "check_meta", "record_fields", "study_from_dict", "parse", "read_text", "max_document_bytes",
           "MAX_DOCUMENT_MIB", "MAX_DOCUMENT_ENV"]
