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
"""

from __future__ import annotations

import dataclasses
import math
from collections import Counter
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator

import numpy as np

PASSED, FAILED, SKIPPED, XFAIL, UNDECIDED = "passed", "failed", "skipped", "xfail", "undecided"
STATUSES = (PASSED, FAILED, SKIPPED, XFAIL, UNDECIDED)


def _finite_number(x: Any) -> bool:
    try:
        return math.isfinite(float(x))
    except (TypeError, ValueError):
        return False


def to_jsonable(value: Any) -> Any:
    """Convert numpy values (recursively) to plain JSON types; non-finite floats become strings."""
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return to_jsonable(value.tolist())
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return v if math.isfinite(v) else repr(v)
    if value is None or isinstance(value, (int, str)):
        return value
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return to_jsonable(dataclasses.asdict(value))
    return repr(value)


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

    def to_dict(self) -> dict[str, Any]:
        return to_jsonable(dataclasses.asdict(self))

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> "CheckResult":
        fields = {f.name for f in dataclasses.fields(cls)}
        kw = {k: v for k, v in data.items() if k in fields}
        for name in ("worst", "bound", "duration"):
            if isinstance(kw.get(name), str):
                kw[name] = float(kw[name])
        return cls(**kw)

    def __str__(self) -> str:
        ratio = ""
        if self.worst is not None:
            ratio = f" worst={self.worst:.4g}" + (f" bound={self.bound:.4g}" if self.bound is not None else "")
        msg = f" — {self.message}" if self.message else ""
        return f"{self.status.upper():7s} {self.key}{ratio}{msg}"


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
        return f"Report({self.summary()})"

    # -- serialization (schema: verimono.report.schema) ------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """The versioned JSON document of this report (see :mod:`verimono.report.schema`)."""
        from .report.schema import report_to_dict

        return report_to_dict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> "Report":
        """Inverse of :meth:`to_dict`; raises :class:`verimono.report.schema.SchemaError` on bad input."""
        from .report.schema import report_from_dict

        return report_from_dict(data)

    def to_json(self, indent: int | None = 1) -> str:
        import json

        return json.dumps(self.to_dict(), indent=indent, allow_nan=False)

    @classmethod
    def from_json(cls, text: str) -> "Report":
        from .report.schema import loads

        return loads(text)

    def save(self, path: str | Path) -> Path:
        """Write :meth:`to_json` to ``path`` atomically (parents created); returns the path."""
        from .atomic import write_text

        return write_text(path, self.to_json())   # temporary file + rename: never a truncated document

    @classmethod
    def load(cls, path: str | Path) -> "Report":
        """Read a report written by :meth:`save`; :class:`SchemaError` if missing, garbled or incompatible."""
        from .report.schema import load

        return load(path)


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
