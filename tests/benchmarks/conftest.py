"""Ratio gates for the performance benchmarks (issue 6).

The measurements are :mod:`verimono.run.performance`'s — the same functions, baselines and targets as the
``performance`` stage of ``verimono run`` — with pytest-benchmark timing the subject: verimono and its
bare baseline run interleaved round by round (the baseline in pytest-benchmark's untimed ``setup``,
verimono as the timed target), and the gate is the median of the per-round ratios, never absolute
times.  The record's details land in ``benchmark.extra_info`` and so in the ``--benchmark-json`` report.

With ``--benchmark-disable`` (the default ``addopts``: the suite then runs once inside the normal test run)
each benchmark uses a smaller size, checks its results, and gates only on a loose sanity bound
(``SANITY_FACTOR`` × the target); run ``pytest -m timing --benchmark-enable tests/benchmarks`` for the real
gates and numbers.  Every test here is marked ``timing`` (below), so none runs in the default ``pytest``.
"""

from __future__ import annotations

from typing import Any, Callable

import pytest

from verimono.run.performance import interleave, ratio_record
from verimono.records.results import CheckResult

#: in un-timed runs (--benchmark-disable) the gate is loosened by this factor (a gross-regression alarm)
SANITY_FACTOR = 3.0


class RatioGate:
    def __init__(self, benchmark) -> None:
        self.benchmark = benchmark

    @property
    def enabled(self) -> bool:
        return not getattr(self.benchmark, "disabled", False)

    def size(self, full, small):
        """``full`` when benchmarking, ``small`` in the normal (un-timed) test run."""
        return full if self.enabled else small

    def rounds(self, full: int, small: int) -> int:
        """Timing rounds: ``full`` when benchmarking, ``small`` in the normal test run."""
        return self.size(full, small)

    def runner(self, setup: Callable[[], Any], target: Callable[[], Any], rounds: int) -> None:
        """A :data:`verimono.run.performance.Runner` timing ``target`` with pytest-benchmark."""
        if not self.enabled:  # pedantic runs its target once when disabled: the other rounds by hand
            for _ in range(rounds - 1):
                setup()
                target()
        # pedantic's setup must return None or (args, kwargs): the baseline's own output is dropped
        self.benchmark.pedantic(target, setup=lambda: (setup(), None)[1], rounds=rounds, iterations=1,
                                warmup_rounds=0)

    def bound(self, target: float, *, speedup: bool = False) -> float:
        """``target`` when benchmarking; loosened by ``SANITY_FACTOR`` in the un-timed normal test run."""
        if self.enabled:
            return target
        return target / SANITY_FACTOR if speedup else target * SANITY_FACTOR

    def check(self, rec: CheckResult, *, sanity: bool = True) -> float:
        """Record ``rec``'s details in ``extra_info`` and gate its ratio (loosened by ``SANITY_FACTOR``
        when un-timed and ``sanity``); results that differ from the baseline's always fail."""
        d = rec.details
        self.benchmark.extra_info.update({**d, "timed": self.enabled, "status": rec.status})
        assert d.get("identical", True), rec.message
        ratio, target, speedup = d["ratio"], d["target"], d["direction"] == ">="
        bound = self.bound(target, speedup=speedup) if sanity else target
        if speedup:
            assert ratio >= bound, f"speed-up {ratio:.1f} < {bound:.1f} ({rec.message})"
        else:
            assert ratio <= bound, f"ratio {ratio:.3f} > {bound:.3f} ({rec.message})"
        return ratio

    def measure(self, subject: Callable[[], object], baseline: Callable[[], object], *, target: float,
                rounds: int = 5, rounds_disabled: int = 3, lower_is_better: bool = True) -> float:
        """Time ``subject`` against ``baseline`` round by round; record and gate the median ratio.

        ``target`` bounds ``subject/baseline`` from above (``lower_is_better``) or ``baseline/subject``
        from below (speed-ups: ``lower_is_better=False``).
        """
        subj_t, base_t, _ = interleave(subject, baseline, self.rounds(rounds, rounds_disabled), self.runner)
        return self.check(ratio_record("benchmark", self.benchmark.name, subj_t, base_t, target=target,
                                       speedup=not lower_is_better))


@pytest.fixture
def gate(benchmark) -> RatioGate:
    return RatioGate(benchmark)


def pytest_itemcollected(item: pytest.Item) -> None:
    """Every test in this folder times something: all are in the ``timing`` tier (``pytest -m timing``), out
    of the default run, whose verdicts must not depend on how busy the machine is."""
    item.add_marker(pytest.mark.timing)


def _timing_deselected(markexpr: str) -> bool:
    """True when ``-m markexpr`` deselects every ``timing`` test whatever its other markers (the default
    ``addopts``' "not slow and not timing and not sweep"): then nothing in this folder can run."""
    if not markexpr.strip():
        return False
    try:
        from _pytest.mark.expression import Expression   # pytest's own -m grammar (no public entry point)

        expr = Expression.compile(markexpr)
    except Exception:                   # an older pytest or an expression -m itself will report: collect as before
        return False
    names: set[str] = set()
    truth: dict[str, bool] = {}

    def matcher(name: str, /, **kwargs) -> bool:
        if kwargs:
            raise LookupError(name)     # `-m "marker(arg=...)"`: not decided here
        names.add(name)
        return truth.get(name, False)

    seen: set[str] = set()
    try:
        while True:                     # every truth assignment of the names the expression asks about, timing true
            for bits in range(2 ** len(seen)):
                truth = {n: bool(bits >> i & 1) for i, n in enumerate(sorted(seen))} | {"timing": True}
                if expr.evaluate(matcher):
                    return False
            if names <= seen:
                return True
            seen |= names
    except LookupError:
        return False


def pytest_ignore_collect(collection_path, config) -> bool | None:
    """This folder's modules are not imported when ``-m`` deselects the ``timing`` tier (the default ``pytest``):
    each pytest process and xdist worker would import and assertion-rewrite them for nothing (≈ 0.5–0.9 s CPU a
    process, docs/speed.md).  ``-m timing``, ``-m ""`` or no ``-m`` collect them as before."""
    if collection_path.suffix == ".py" and _timing_deselected(config.getoption("markexpr", "") or ""):
        return True
    return None
