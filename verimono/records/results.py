"""Result records: what every check returns.

Checks never print or assert.  Each returns :class:`CheckResult` records — the check's name, its
subject, a status (``passed``, ``failed``, ``skipped``, ``xfail``, ``undecided``), the worst observed ratio
against the check's bound, and a counterexample that reproduces a failure.

``undecided`` is a limitation of the harness itself (the search engine cannot draw inputs of this size,
verimono's own solvers gave no verified answer): neither a pass nor a failure of the subject.  ``verimono``
exits 2 ("could not decide") on it when nothing failed, the gate treats a record that passed and is now
undecided as a regression (it verifies nothing), and pytest reports it as a failure of the test run, never
as a pass.  A record that claims ``passed`` with a non-finite ``worst`` is a contradiction (a NaN ratio
compares false against every bound); it is turned into ``failed`` on construction, and
``details["unearned_pass"]`` says what it claimed (so a baseline holding one is refused by the gate).  An
``xfail`` record that was declared — by ``expected_failed_checks`` of :mod:`verimono.testing` (a pytest xfail)
or by Theorem ``thm:main`` needing only one of (LG), (YB) — carries the declaration's reason in
``details["xfail_declared"]``; the gate counts a passed record that became ``xfail`` without one as a
regression.  pytest, the HTML report and the CI gate are thin consumers of these records, collected in a
:class:`Report`.

Saving and loading: :meth:`Report.save` and :func:`load` write and read the versioned JSON document of
:mod:`verimono.records.schema` (its docstring states the layout).
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections import Counter
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator

from . import schema
from .atomic import write_text
from ..core._jsonable import to_jsonable
from ..core.display import render
from .environment import OPTIONAL, VERSIONED, environment
from ..core.errors import SchemaError
from .schema import SCHEMA_NAME, SCHEMA_VERSION, check_compatible

PASSED, FAILED, SKIPPED, XFAIL, UNDECIDED = "passed", "failed", "skipped", "xfail", "undecided"
STATUSES = (PASSED, FAILED, SKIPPED, XFAIL, UNDECIDED)
#: ``details`` key of an ``xfail`` record: the reason its failure was declared expected
XFAIL_DECLARED = "xfail_declared"
#: ``details`` key of a record that claimed ``passed`` with a non-finite worst ratio (now ``failed``)
UNEARNED_PASS = "unearned_pass"
#: ``meta`` key of a pytest session whose records of some tests are missing (an xdist worker crashed while
#: running them, or a runner kept them): ``{"crashed": [nodeid, ...], "hidden": [nodeid, ...]}``
MISSING_RECORDS = "missing_records"


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
            self.details = {**self.details, UNEARNED_PASS: f"passed with worst = {self.worst!r}"}
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
    def study(self) -> Any:
        """The :class:`verimono.ConvergenceStudy` a convergence-order record carries (``details["study"]``),
        if any."""
        study = self.details.get("study")
        return study if callable(getattr(study, "verdict", None)) else None

    def to_dict(self) -> dict[str, Any]:
        return to_jsonable({f.name: getattr(self, f.name) for f in dataclasses.fields(self)})

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> "CheckResult":
        """Inverse of :meth:`to_dict` (a study in ``details`` comes back as a :class:`ConvergenceStudy`);
        :class:`SchemaError` on a malformed record."""
        return cls(**schema.record_fields(data, 0))

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
        """True when the report verified something and nothing failed or was left undecided: at least one
        record passed, none failed or undecided.  An empty report, or one whose records were all skipped or
        expected failures, verified nothing, and a check that evaluated nothing is never a pass
        (:attr:`verified` says whether any record passed)."""
        return self.verified and all(r.ok for r in self.results)

    @property
    def verified(self) -> bool:
        """Whether any record passed: something was evaluated and held."""
        return any(r.status == PASSED for r in self.results)

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
        """Inverse of :meth:`to_dict`; raises :class:`verimono.core.errors.SchemaError` on bad input."""
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


# -- the document: writing and reading (layout and type checks: verimono.records.schema) --------------------

def report_to_dict(report: Report) -> dict[str, Any]:
    """The schema document of ``report``; fills ``meta.environment`` and ``created`` when absent."""
    return schema.document(report.meta, report.counts, [r.to_dict() for r in report.results], report.studies,
                           report.trajectories)


def report_from_dict(data: Any) -> Report:
    """Read a schema document back into a :class:`Report` (inverse of :func:`report_to_dict`)."""
    check_compatible(data)
    results = [CheckResult(**schema.record_fields(r, i)) for i, r in enumerate(data["results"])]
    studies = [schema.study_from_dict(s, i) for i, s in enumerate(data["studies"])]
    trajectories = data.get("trajectories") or []
    if not isinstance(trajectories, list):
        raise SchemaError(f"trajectories must be a list, got {type(trajectories).__name__}")
    meta = dict(data["meta"])
    meta["created"] = data.get("created")
    return Report(results, studies, meta, list(trajectories))


def loads(text: str, source: str = "<string>") -> Report:
    """The :class:`Report` of the JSON document ``text``; :class:`SchemaError` naming ``source`` if it is
    garbled, malformed or incompatible."""
    data = schema.parse(text, source)
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
    text = schema.read_text(path)
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


__all__ = ["PASSED", "FAILED", "SKIPPED", "XFAIL", "STATUSES", "XFAIL_DECLARED", "UNEARNED_PASS", "MISSING_RECORDS", "CheckResult",
           "Report", "to_jsonable", "emit",
           "listening", "SCHEMA_NAME", "SCHEMA_VERSION", "VERSIONED", "OPTIONAL", "SchemaError", "environment",
           "report_to_dict", "report_from_dict", "check_compatible", "loads", "load"]
