"""pytest integration: run verimono's check batteries on your operators and steppers.

Three lines run the whole battery on your own operator (or stepper)::

    from verimono.testing import parametrize_with_checks

    @parametrize_with_checks([my_operator, my_stepper])
    def test_verimono(subject, check):
        check(subject)

One pytest case per (subject, check), with stable readable ids ``<subject>-<check>`` (so
``pytest -k firmly_nonexpansive`` or ``-k "selections and t_x"`` selects checks).

**One source of checks.**  The cases come from the same generators as the plain runners — the protocol
is a function of the subject yielding ``(name, check)`` pairs with ``check(subject) -> CheckResult``
(or a :class:`~verimono.records.results.Report`):

* operators (anything with ``.resolvent`` and ``.dim``): ``verimono.checks.operator_battery.operator_checks(op)``,
  the generator of :func:`verimono.check_operator`;
* problems (:class:`verimono.Problem`): ``verimono.checks.assumptions.problem_checks(problem)``, the
  records of :func:`verimono.check_assumptions` (evidence for (A1)–(A3), (LG), (YB) and ``thm:main``);
* steppers (any other callable ``stepper(problem, t_grid)``; a :class:`verimono.Stepper` states its claim):
  ``verimono.checks.stepper_battery.stepper_checks(stepper)``, the generator of
  :func:`verimono.check_stepper` (convergence orders on the references, trajectory laws on the references
  and on seeded sample problems).

**Outcomes.**  ``check(subject)`` hands every record to :func:`verimono.records.results.emit` (for report plugins),
raises ``AssertionError`` with the record's text when a record failed, and calls ``pytest.skip`` with the
reason when every record was skipped — pytest counts the skip and ``-rs`` lists why.
``expected_failed_checks`` maps a check name (``"selections"``, the full ``"selections[t|x| (n=1)]"``, or a
case id) to the reason, and turns those cases into **strict** xfails: a check that starts passing fails the
run as ``XPASS(strict)``.  A name that matches no check is an error, and so is a subject yielding no
checks or a battery smaller than the full registry for its subjects (:func:`registry_size`; ``min_checks``
may raise that floor): a battery must not shrink silently.  Without ``examples`` the operator laws search
with the active profile's effort (``dev``/``ci``/``thorough``: :func:`verimono.execution.profiles.get_profile`).

**Counting.**  With this module loaded as a pytest plugin (``-p verimono.testing``, or
``from verimono.testing import pytest_configure`` in a ``conftest.py`` as ``properties/conftest.py`` does) the
terminal summary gets a ``verimono checks`` section: how many checks were collected, ran, passed, failed,
were skipped (grouped by reason), xfailed and xpassed.  Under pytest-xdist (``-n N``) each worker tells
the controller which battery cases it collected (``workeroutput["verimono_battery"]``) and the outcomes
arrive with the workers' reports, so the section is the one a serial run prints.
"""

from __future__ import annotations

import re
from collections import Counter
from typing import Any, Callable, Iterable, Mapping

import pytest

from .checks.core import laws_of
from .checks.sample_problems import valid_count
from .checks.core import subject_name as core_subject_name
from .checks.subjects import kind_of
from .execution.config import current as current_config
from .execution.profiles import load_hypothesis_profile as _load
from .execution.profiles import register_hypothesis_profiles as _register
from .records.results import FAILED, SKIPPED, UNDECIDED, CheckResult, Report, to_jsonable

try:  # the listener hook of the results module (present when a report plugin is installed)
    from .records.results import emit as _emit
except ImportError:  # pragma: no cover - older results module
    def _emit(item):
        return item


# -- hypothesis profiles ----------------------------------------------------------------------------

def register_hypothesis_profiles() -> None:
    """Register the hypothesis profiles ``dev``, ``ci`` (derandomized, no deadline, no database) and
    ``thorough`` — one definition, in :mod:`verimono.execution.profiles`, shared with ``verimono run``."""
    _register()


def load_hypothesis_profile(name: str | None = None) -> str:
    """Register the profiles and load ``name`` (default: the run configuration's profile,
    :func:`verimono.execution.config.current` — the pytest plugin's, else ``$HYPOTHESIS_PROFILE``, else ``ci``
    when ``$CI`` is set, else ``dev``); returns the name loaded."""
    return _load(name or current_config().profile)


# -- subjects and their checks ----------------------------------------------------------------------

def subject_name(subject: Any) -> str:
    """The subject's name, the one every record of it carries (:func:`verimono.checks.core.subject_name`)."""
    return core_subject_name(subject)


def _slug(text: str) -> str:
    """A pytest-id and ``-k`` friendly form: runs of other characters become one ``_``."""
    return re.sub(r"_+", "_", re.sub(r"[^A-Za-z0-9_.=+]+", "_", str(text))).strip("_") or "x"


def check_id(name: str) -> str:
    """``"selections[t|x| (n=1)]"`` → ``"selections-t_x_n=1"``; ``"monotone"`` → ``"monotone"``."""
    law, _, rest = name.partition("[")
    return _slug(law) + (f"-{_slug(rest.rstrip(']'))}" if rest else "")


def checks_for(subject: Any, *, seed: int | None = None, examples: int | None = None,
               problems: Iterable | None = None, generated: int = 4) -> list[tuple[str, Callable]]:
    """The ``(name, check)`` pairs of ``subject`` from its kind's battery (see the module docstring); what is
    not a subject is refused (:class:`verimono.InvalidCheckArgument`, naming the wrapper that makes one)."""
    kind = kind_of(subject)
    if kind == "operator":
        from .checks.operator_battery import operator_checks

        return list(operator_checks(subject, seed=seed, examples=examples))
    if kind == "problem":
        from .checks.assumptions import problem_checks

        return list(problem_checks(subject, seed=0 if seed is None else seed))
    from .checks.stepper_battery import stepper_checks

    return list(stepper_checks(subject, problems, seed=0 if seed is None else seed, generated=generated))


def registry_size(subject: Any, *, problems: Iterable | None = None, generated: int = 4) -> int:
    """How many checks the full registry gives ``subject`` — counted from the registry, not from the
    generator, so that a generator or registry that lost a law shows as a shrunk battery: the operator laws
    for an operator, the problem laws for a problem; for a stepper ``(1 + len(CHECKS))`` per reference
    (``problems``, or the reference catalog) plus ``len(CHECKS)`` per generated problem."""
    kind = kind_of(subject)
    if kind in ("operator", "problem"):
        return len(laws_of(kind, battery=True))
    generated = valid_count(generated)
    from .checks.stepper_battery import CHECKS

    if problems is not None:
        return len(list(problems)) * (1 + len(CHECKS))
    from verimono.reference import catalog

    return len(catalog()) * (1 + len(CHECKS)) + int(generated) * len(CHECKS)


def _records(out: Any) -> list[CheckResult]:
    if isinstance(out, CheckResult):
        return [out]
    if isinstance(out, Report):
        return list(out.results)
    return list(out)


def describe(record: CheckResult) -> str:
    """The record's line plus its counterexample and seed: what a failing test prints."""
    lines = [str(record)]
    if record.counterexample:
        cx = to_jsonable(record.counterexample)
        lines.append("counterexample: " + ", ".join(f"{k}={_short(v)}" for k, v in cx.items()))
    if record.seed is not None:
        lines.append(f"seed: {record.seed}")
    return "\n".join(lines)


def _short(v: Any, limit: int = 400) -> str:
    s = repr(v)
    return s if len(s) <= limit else s[:limit] + f"... ({len(s)} chars)"


class BoundCheck:
    """One check of the battery, called by the test as ``check(subject)``."""

    def __init__(self, name: str, fn: Callable[[Any], Any], subject_id: str) -> None:
        self.name, self.fn, self.subject_id = name, fn, subject_id

    def __call__(self, subject: Any) -> list[CheckResult]:
        records = _records(self.fn(subject))
        for r in records:
            _emit(r)
        failed = [r for r in records if r.status == FAILED]
        if failed:
            raise AssertionError("\n\n".join(describe(r) for r in failed))
        undecided = [r for r in records if r.status == UNDECIDED]
        if undecided:   # a limitation of the harness: not a pass, and not a failure of the subject
            pytest.fail("undecided (a limitation of verimono, not a failure of your code): " +
                        "; ".join(f"{self.name}: {r.message}" for r in undecided), pytrace=False)
        if not records:
            raise AssertionError(f"check {self.name} produced no record")
        if all(r.status == SKIPPED for r in records):
            pytest.skip("; ".join(f"{self.name}: {r.message or 'skipped'}" for r in records))
        return records

    def __repr__(self) -> str:
        return check_id(self.name)


# -- the decorator ----------------------------------------------------------------------------------

_BATTERIES: list[dict[str, Any]] = []


def _law_of(name: str) -> str:
    return name.partition("[")[0]


def parametrize_with_checks(subjects: Iterable[Any], expected_failed_checks: Mapping[str, str] | Callable | None
                            = None, *, min_checks: int | None = None, seed: int | None = None,
                            examples: int | None = None, problems: Iterable | None = None,
                            generated: int = 4) -> Callable:
    """Parametrize ``test(subject, check)`` with one case per (subject, check) of each subject's battery.

    ``expected_failed_checks``: ``{name: reason}`` (or a function ``subject -> {name: reason}``); a name is
    a law (``"selections"``), a full check name (``"selections[t|x| (n=1)]"``) or a case id
    (``"my_stepper-selections-t_x_n=1"``).  Matching cases become strict xfails (``raises=AssertionError``,
    so an exception other than a failed check still fails).  Raises ``ValueError`` at collection when a
    name matches no check, when a subject has no checks, or when fewer cases result than the full registry
    gives the subjects (:func:`registry_size`, summed over the subjects) — a battery that silently shrinks
    is a failure; ``min_checks`` can only raise that floor.
    ``seed``/``examples`` are passed to the operator laws (``seed=None``: a fresh recorded seed per check,
    ``0`` under a derandomized profile; ``examples=None``: the active profile's effort);
    ``problems``/``generated`` to the stepper battery.
    """
    subjects = list(subjects)
    if problems is not None:
        problems = list(problems)
    if seed is None:
        effort = current_config().effort    # the run configuration's profile (the plugin's, or the environment's)
        seed = 0 if effort is not None and effort.derandomize else None
    cases, used, seen_ids = [], set(), Counter()
    all_keys: set[str] = set()
    for subject in subjects:
        sid = _slug(subject_name(subject))
        seen_ids[sid] += 1
        if seen_ids[sid] > 1:
            sid = f"{sid}_{seen_ids[sid]}"
        checks = checks_for(subject, seed=seed, examples=examples, problems=problems, generated=generated)
        if not checks:
            raise ValueError(f"subject {sid} yields no checks: an empty battery is an error, not a pass")
        xf = expected_failed_checks(subject) if callable(expected_failed_checks) else (expected_failed_checks or {})
        all_keys |= set(xf)
        for name, fn in checks:
            case_id = f"{sid}-{check_id(name)}"
            key = next((k for k in (case_id, name, _law_of(name)) if k in xf), None)
            marks = []
            if key is not None:
                used.add(key)
                marks.append(pytest.mark.xfail(strict=True, raises=AssertionError, reason=xf[key]))
            cases.append(pytest.param(subject, BoundCheck(name, fn, sid), marks=marks, id=case_id))
    unknown = sorted(all_keys - used)
    if unknown:
        raise ValueError(f"expected_failed_checks names checks that do not exist: {unknown}")
    full = sum(registry_size(s, problems=problems, generated=generated) for s in subjects)
    floor = full if min_checks is None else max(full, int(min_checks))
    if len(cases) < floor:
        why = (f"the full registry for these subjects ({full})" if floor == full
               else f"the {floor} declared (min_checks)")
        raise ValueError(f"the battery has {len(cases)} checks, fewer than {why}: checks were lost")
    _BATTERIES.append({"subjects": [subject_name(s) for s in subjects], "cases": len(cases),
                       "xfail": len(used)})

    def decorator(test: Callable) -> Callable:
        return pytest.mark.parametrize("subject, check", cases)(test)

    return decorator


# -- pytest plugin: count the battery's outcomes ----------------------------------------------------

_PLUGIN_NAME = "verimono-battery-counter"


def _is_battery_item(item: Any) -> bool:
    callspec = getattr(item, "callspec", None)
    return callspec is not None and isinstance(callspec.params.get("check"), BoundCheck)


class BatteryCounter:
    """Counts the outcomes of battery cases and writes the ``verimono checks`` summary section."""

    def __init__(self) -> None:
        self.collected: set[str] = set()
        self.outcome: dict[str, str] = {}
        self.reason_of: dict[str, str] = {}

    def pytest_collection_modifyitems(self, session: Any, config: Any, items: list) -> None:
        self.collected = {it.nodeid for it in items if _is_battery_item(it)}
        if hasattr(config, "workeroutput"):  # a pytest-xdist worker: tell the controller what it collected
            config.workeroutput["verimono_battery"] = sorted(self.collected)

    @pytest.hookimpl(optionalhook=True)
    def pytest_testnodedown(self, node: Any, error: Any) -> None:
        """pytest-xdist controller: the battery cases a worker collected (every worker collects all)."""
        self.collected |= set((getattr(node, "workeroutput", None) or {}).get("verimono_battery", ()))

    def pytest_runtest_logreport(self, report: Any) -> None:
        # every test's outcome is noted, and only battery cases are counted: under pytest-xdist the
        # controller learns which tests are battery cases only when the workers finish
        if not (report.when == "call" or (report.when == "setup" and (report.skipped or report.failed))):
            return
        if hasattr(report, "wasxfail"):
            outcome = "xfailed" if report.skipped else "xpassed"
        elif report.skipped:
            outcome = "skipped"
            reason = report.longrepr[2] if isinstance(report.longrepr, (tuple, list)) else str(report.longrepr)
            reason = reason.removeprefix("Skipped: ")
            # "law[problem]: why" -> group by why (the per-case list is in pytest's -rs section)
            self.reason_of[report.nodeid] = reason.split("]: ", 1)[-1] if "]: " in reason else reason
        elif report.failed and "XPASS(strict)" in str(report.longrepr):
            outcome = "xpassed"
        else:
            outcome = report.outcome
        self.outcome[report.nodeid] = outcome

    @property
    def reasons(self) -> Counter:
        """Skip reasons of the battery cases, with how many cases gave each."""
        return Counter(r for nodeid, r in self.reason_of.items() if nodeid in self.collected)

    def counts(self) -> dict[str, int]:
        c = Counter(o for nodeid, o in self.outcome.items() if nodeid in self.collected)
        return {"collected": len(self.collected), "ran": sum(c.values()), "passed": c["passed"],
                "failed": c["failed"], "skipped": c["skipped"], "xfailed": c["xfailed"], "xpassed": c["xpassed"]}

    def pytest_terminal_summary(self, terminalreporter: Any, exitstatus: int, config: Any) -> None:
        if not self.collected:
            return
        c = self.counts()
        tr = terminalreporter
        tr.write_sep("-", "verimono checks")
        tr.write_line(f"{c['collected']} collected, {c['ran']} ran: {c['passed']} passed, {c['failed']} failed, "
                      f"{c['skipped']} skipped, {c['xfailed']} xfailed (expected), {c['xpassed']} xpassed "
                      "(strict: reported as failures)")
        for reason, n in sorted(self.reasons.items(), key=lambda kv: (-kv[1], kv[0])):  # not arrival order
            tr.write_line(f"  skipped x{n}: {reason}")
        if c["ran"] < c["collected"]:
            tr.write_line(f"  {c['collected'] - c['ran']} collected checks did not run (deselected or interrupted)")


def pytest_configure(config: Any) -> None:
    """Register the :class:`BatteryCounter` once per pytest run (idempotent: conftest import and ``-p``)."""
    if not config.pluginmanager.has_plugin(_PLUGIN_NAME):
        config.pluginmanager.register(BatteryCounter(), _PLUGIN_NAME)


def battery_counts(config: Any) -> dict[str, int] | None:
    """The counts of the current run (``None`` when the plugin is not active)."""
    plugin = config.pluginmanager.get_plugin(_PLUGIN_NAME)
    return None if plugin is None else plugin.counts()


__all__ = ["parametrize_with_checks", "checks_for", "BoundCheck", "describe", "check_id",
           "subject_name", "registry_size", "register_hypothesis_profiles", "load_hypothesis_profile", "battery_counts",
           "BatteryCounter", "pytest_configure"]
