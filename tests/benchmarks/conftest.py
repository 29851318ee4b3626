"""Ratio gates for the performance benchmarks (issue 6).

Every benchmark times verimono and a bare baseline *in the same run*, interleaved round by round (the
baseline in pytest-benchmark's untimed ``setup``, verimono as the timed target), and gates on the median
of the per-round ratios — never on absolute times, which vary with the machine and its load.  The ratio
is recorded in ``benchmark.extra_info`` (``ratio``, ``target``, the per-round times), so it lands in the
``--benchmark-json`` report.

With ``--benchmark-disable`` (the default ``addopts``: the suite then runs once inside the normal test run)
each benchmark uses a smaller size, checks its results, and gates only on a loose sanity bound
(``SANITY_FACTOR`` × the target) so that an overloaded machine does not fail the ordinary test run; run
``pytest tests/benchmarks --benchmark-enable`` for the real gates and numbers.
"""

from __future__ import annotations

import statistics
import time
from typing import Callable

import pytest

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

    def measure(self, subject: Callable[[], object], baseline: Callable[[], object], *, target: float,
                rounds: int = 5, rounds_disabled: int = 3, lower_is_better: bool = True) -> float:
        """Time ``subject`` against ``baseline`` round by round; record and gate the median ratio.

        ``target`` bounds ``subject/baseline`` from above (``lower_is_better``) or ``baseline/subject``
        from below (speed-ups: ``lower_is_better=False``).
        """
        base_t: list[float] = []
        subj_t: list[float] = []

        def setup():
            start = time.perf_counter()
            baseline()
            base_t.append(time.perf_counter() - start)

        def target_fn():
            start = time.perf_counter()
            out = subject()
            subj_t.append(time.perf_counter() - start)
            return out

        n = rounds if self.enabled else rounds_disabled
        if not self.enabled:  # pedantic runs its target once when disabled: the other rounds by hand
            for _ in range(n - 1):
                setup()
                target_fn()
        self.benchmark.pedantic(target_fn, setup=setup, rounds=n, iterations=1, warmup_rounds=0)
        if len(base_t) < len(subj_t):  # a plugin version that skips setup when disabled
            setup()
        pairs = list(zip(subj_t, base_t))
        if lower_is_better:
            ratio = statistics.median(s / b for s, b in pairs)
        else:
            ratio = statistics.median(b / s for s, b in pairs)
        info = self.benchmark.extra_info
        info.update({"ratio": ratio, "target": target, "direction": "<=" if lower_is_better else ">=",
                     "subject_s": subj_t, "baseline_s": base_t, "timed": self.enabled})
        bound = target if self.enabled else (target * SANITY_FACTOR if lower_is_better else target / SANITY_FACTOR)
        if lower_is_better:
            assert ratio <= bound, f"ratio {ratio:.3f} > {bound:.3f} (subject {subj_t}, baseline {base_t})"
        else:
            assert ratio >= bound, f"speed-up {ratio:.1f} < {bound:.1f} (subject {subj_t}, baseline {base_t})"
        return ratio


@pytest.fixture
def gate(benchmark) -> RatioGate:
    return RatioGate(benchmark)
