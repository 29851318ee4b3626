"""Result records: what every check returns.

Checks never print or assert.  Each returns :class:`CheckResult` records — the check's name, its
subject, a status (``passed``, ``failed``, ``skipped``, ``xfail``, ``undecided``), the worst observed ratio
against the check's bound, and a counterexample that reproduces a failure.

``undecided`` is a limitation of the harness itself (the search engine cannot draw inputs of this size,
a stage ran out of memory): neither a pass nor a failure of the subject.  ``verimono`` exits 2 ("could
not decide") on it when nothing failed, the gate treats a record that passed and is now undecided as a
regression (it verifies nothing), and pytest reports it as a failure of the test run, never as a pass.
A record that claims ``passed`` with a non-finite ``worst`` is a contradiction (a NaN ratio compares false
against every bound); it is turned into ``failed`` on construction.  pytest, the HTML report and the CI gate
are thin consumers of these records, collected in a :class:`Report`.

Saving and loading: the JSON schema of ``results.json`` and ``baseline.json`` — one document, versioned.
This module is the only one that writes or reads it (:meth:`Report.save`, :func:`load`, ...);
:mod:`verimono.report.schema` re-exports its names.

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
        "executor": "serial" | "process:2" | ...,      #   where the stages' units ran (stage times compare
                                                       #   only between runs on the same executor)
        "calibrations": [0.012, 0.013],                #   the workload timed before and after the stages
        "calibration": 0.012,                          #   the faster of the two: the unit of stage times
        "duration": 93.5,                              #   seconds of the whole run (or pytest session)
        "data_dir": "/path/to/shared" | null,          #   Siconos reference data used, if any
        "environment": {...}                           #   see environment() below
      },
      "results": [CheckResult.to_dict(), ...],         # every record: check, subject, status, worst, bound,
                                                       #   counterexample, message, seed, details, duration
      "studies": [ConvergenceStudy.to_dict(), ...],    # every error of every grid, fits with intervals
      "trajectories": [{"problem", "stepper", "h", "t", "x", "exact"}, ...]   # samples for plots
    }

A record's ``details`` are free-form; keys that producers hand to consumers: ``study`` (a convergence-order
record's study, read back as a :class:`ConvergenceStudy`: ``CheckResult.study``), ``stage`` and ``reference``
(set by the run), ``reproduce``, ``reproduce_python``, ``example`` (what the report's reproduction shows),
``error`` and ``timing_ratio`` (compared by the gate).

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

import dataclasses
import datetime as _dt
import json
import math
import os
import platform
import sys
from collections import Counter
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator

from .atomic import write_text
from ._jsonable import to_jsonable
from .display import render
from .convergence import NORMS, ConvergenceStudy
from .errors import SchemaError

PASSED, FAILED, SKIPPED, XFAIL, UNDECIDED = "passed", "failed", "skipped", "xfail", "undecided"
STATUSES = (PASSED, FAILED, SKIPPED, XFAIL, UNDECIDED)


def _finite_number(x: Any) -> bool:
    try:
        return math.isfinite(float(x))
    except (TypeError, ValueError):
        return False


@dataclasses.dataclass
class CheckResult:
    """One check of one subject.

    ``worst`` is the worst observed value of the check's ratio, ``bound`` the value it must not exceed
    (so a check passes when ``worst <= bound``); both are ``None`` for checks without a ratio.
    ``counterexample`` holds the inputs that reproduce a failure (points, step sizes, times, seed).
    """

    check: str
    subject: str
    status: str
    worst: float | None = None
    bound: float | None = None
    counterexample: dict[str, Any] | None = None
    message: str = ""
    seed: int | None = None
    details: dict[str, Any] = dataclasses.field(default_factory=dict)
    duration: float | None = None

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise ValueError(f"status must be one of {STATUSES}, got {self.status!r}")
        if self.status == PASSED and self.worst is not None and not _finite_number(self.worst):
            # an unearned pass: a nan/inf ratio satisfies no bound
            self.status = FAILED
            self.message = (f"the check reported a pass with a non-finite worst ratio {self.worst!r}; "
                            f"a non-finite value is never a pass" + (f" ({self.message})" if self.message else ""))

    @property
    def ok(self) -> bool:
        """True unless the check failed or could not decide (skips and expected failures are not failures;
        an undecided record verified nothing, so it is not ok either)."""
        return self.status not in (FAILED, UNDECIDED)

    @property
    def key(self) -> str:
        """Stable identity of the record: ``check[subject]``."""
        return f"{self.check}[{self.subject}]"

    @property
    def study(self) -> ConvergenceStudy | None:
        """The :class:`ConvergenceStudy` a convergence-order record carries (``details["study"]``), if any."""
        study = self.details.get("study")
        return study if isinstance(study, ConvergenceStudy) else None

    def to_dict(self) -> dict[str, Any]:
        return to_jsonable({f.name: getattr(self, f.name) for f in dataclasses.fields(self)})

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> "CheckResult":
        """Inverse of :meth:`to_dict` (a study in ``details`` comes back as a :class:`ConvergenceStudy`)."""
        fields = {f.name for f in dataclasses.fields(cls)}
        kw = {k: v for k, v in data.items() if k in fields}
        for name in ("worst", "bound", "duration"):
            if isinstance(kw.get(name), str):
                kw[name] = float(kw[name])
        if isinstance(kw.get("details"), dict) and isinstance(kw["details"].get("study"), dict):
            kw["details"] = {**kw["details"], "study": ConvergenceStudy.from_dict(kw["details"]["study"])}
        return cls(**kw)

    def __str__(self) -> str:
        ratio = ""
        if self.worst is not None:
            ratio = f" worst={self.worst:.4g}" + (f" bound={self.bound:.4g}" if self.bound is not None else "")
        msg = f" — {self.message}" if self.message else ""
        return f"{self.status.upper():7s} {self.key}{ratio}{msg}"

    def __repr__(self) -> str:
        """One readable line: status, key, worst against bound, seed, message (details left out)."""
        return record_text(self)

    def _repr_html_(self) -> str | None:
        """Jupyter: the record as the HTML report shows it (counterexample, reproduction, study plot)."""
        return render("record_html", self)


class Report:
    """An ordered collection of :class:`CheckResult` records, plus convergence studies.

    Iterates over records; ``counts`` tallies statuses; ``ok`` is True when nothing failed.
    """

    def __init__(self, results: Iterable[CheckResult] = (), studies: Iterable[Any] = (),
                 meta: dict[str, Any] | None = None, trajectories: Iterable[dict[str, Any]] = ()) -> None:
        self.results: list[CheckResult] = list(results)
        self.studies: list[Any] = list(studies)
        self.meta: dict[str, Any] = dict(meta or {})
        #: sampled trajectories next to the exact solution, for plots: dicts with ``problem``,
        #: ``stepper``, ``h``, ``t`` (list), ``x`` (list of states), ``exact`` (list of states or None)
        self.trajectories: list[dict[str, Any]] = list(trajectories)

    def __iter__(self) -> Iterator[CheckResult]:
        return iter(self.results)

    def __len__(self) -> int:
        return len(self.results)

    def __getitem__(self, i: int) -> CheckResult:
        return self.results[i]

    def add(self, result: CheckResult) -> CheckResult:
        self.results.append(result)
        return result

    def extend(self, other: "Report | Iterable[CheckResult]") -> "Report":
        if isinstance(other, Report):
            self.results.extend(other.results)
            self.studies.extend(other.studies)
            self.trajectories.extend(other.trajectories)
        else:
            self.results.extend(other)
        return self

    @property
    def counts(self) -> dict[str, int]:
        c = Counter(r.status for r in self.results)
        return {s: c.get(s, 0) for s in STATUSES}

    @property
    def ok(self) -> bool:
        return all(r.ok for r in self.results)

    @property
    def failures(self) -> list[CheckResult]:
        return [r for r in self.results if r.status == FAILED]

    def by_check(self, name: str) -> list[CheckResult]:
        return [r for r in self.results if r.check == name]

    @property
    def undecided(self) -> list[CheckResult]:
        return [r for r in self.results if r.status == UNDECIDED]

    def summary(self) -> str:
        """``"N passed, N failed, N skipped, N xfail"`` (and ``", N undecided"`` when there are any)."""
        c = self.counts
        return ", ".join(f"{c[s]} {s}" for s in STATUSES if s != UNDECIDED or c[s])

    def __repr__(self) -> str:
        """``Report(N passed, N failed, N skipped, N xfail)``, then the counts and the failures."""
        return report_text(self)

    def _repr_html_(self) -> str | None:
        """Jupyter: the HTML report's own sections and plots, its stylesheet scoped to the output."""
        return render("report_html", self)

    # -- saving and loading (the schema: this module's docstring) --------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """The versioned JSON document of this report (see the module docstring)."""
        return report_to_dict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> "Report":
        """Inverse of :meth:`to_dict`; raises :class:`verimono.errors.SchemaError` on bad input."""
        return report_from_dict(data)

    def to_json(self, indent: int | None = 1) -> str:
        return json.dumps(self.to_dict(), indent=indent, allow_nan=False)

    @classmethod
    def from_json(cls, text: str) -> "Report":
        return loads(text)

    def save(self, path: str | Path) -> Path:
        """Write :meth:`to_json` to ``path`` atomically (parents created); returns the path."""
        return write_text(path, self.to_json())   # temporary file + rename: never a truncated document

    @classmethod
    def load(cls, path: str | Path) -> "Report":
        """Read a report written by :meth:`save`; :class:`SchemaError` if missing, garbled or incompatible."""
        return load(path)


# -- the document: writing and reading -------------------------------------------------------------
SCHEMA_NAME = "verimono.results"
SCHEMA_VERSION = "1.1"
_NON_FINITE = ("nan", "inf", "-inf", "+inf", "infinity", "-infinity")
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


def _study_from_dict(data: Any, i: int | str = 0) -> ConvergenceStudy:
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
    if "study" in d.get("details", {}):
        d["details"] = {**d["details"], "study": _study_from_dict(d["details"]["study"], f"{where}: details.study")}
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
        "studies": to_jsonable(report.studies),
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
    except SchemaError:
        raise
    except (TypeError, AttributeError, KeyError, IndexError, ValueError, OverflowError) as exc:
        # a field of an unexpected type that the type checks did not anticipate: unreadable
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



# -- readable repr -----------------------------------------------------------------------------------


def _short(text: str, limit: int = 160) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _g(x: Any) -> str:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return str(x)
    return f"{v:.4g}" if math.isfinite(v) else str(v)


def record_text(rec: CheckResult) -> str:
    """``CheckResult(passed convergence_order[solve on box], worst 0.9524 ≤ bound 1: measured …)``."""
    parts = [f"{rec.status} {rec.key}"]
    if rec.worst is not None:
        rel = "≤" if rec.bound is None or not (float(rec.worst) > float(rec.bound)) else ">"
        parts.append(f"worst {_g(rec.worst)}" + (f" {rel} bound {_g(rec.bound)}" if rec.bound is not None else ""))
    if rec.seed is not None:
        parts.append(f"seed {rec.seed}")
    text = ", ".join(parts)
    if rec.message:
        text += f": {_short(rec.message)}"
    if rec.counterexample:
        text += f" (counterexample: {', '.join(map(str, rec.counterexample))})"
    return f"CheckResult({text})"


def report_text(report: Report, limit: int = 10) -> str:
    """First line ``Report(10 passed, 0 failed, 5 skipped, 0 xfail)``, then the failures (at most ``limit``)
    and how many records, checks and studies there are."""
    lines = [f"Report({report.summary()})"]
    checks = len({r.check for r in report.results})
    lines.append(f"  {len(report)} records of {checks} checks, {len(report.studies)} convergence studies")
    for r in report.failures[:limit]:
        lines.append(f"  {r}")
    if len(report.failures) > limit:
        lines.append(f"  … and {len(report.failures) - limit} more failures")
    return "\n".join(lines)


# -- listeners: how records reach consumers that did not call the check (the pytest plugin) -------------
_LISTENERS: list[Callable[[Any], None]] = []


def emit(item: "CheckResult | Report") -> "CheckResult | Report":
    """Hand a record (or a whole report) to every active listener; returns ``item`` unchanged.

    Producers that run checks on a consumer's behalf (``verimono.testing.parametrize_with_checks``)
    call this once per record *before* turning a failure into a pytest failure, so the pytest plugin
    can put every record in its report.  Without listeners it does nothing.
    """
    for fn in list(_LISTENERS):
        fn(item)
    return item


@contextmanager
def listening(fn: Callable[[Any], None]) -> Iterator[None]:
    """Call ``fn`` with everything :func:`emit`-ted inside the ``with`` block."""
    _LISTENERS.append(fn)
    try:
        yield
    finally:
        _LISTENERS.remove(fn)


__all__ = ["PASSED", "FAILED", "SKIPPED", "XFAIL", "STATUSES", "CheckResult", "Report", "to_jsonable", "emit",
           "listening", "SCHEMA_NAME", "SCHEMA_VERSION", "VERSIONED", "OPTIONAL", "SchemaError", "environment",
           "report_to_dict", "report_from_dict", "check_compatible", "loads", "load"]
