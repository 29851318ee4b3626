"""glibc's allocator keeps the blocks a battery in a large dimension frees (:func:`verimono.execution.heap.heap_kept`):
fresh n-vectors made and freed sample after sample are no longer faulted in again page by page.  Counted, not
timed: minor page faults of a fresh process (glibc's thresholds are process-wide state, so the count without runs
first, in its own interpreter)."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from verimono.execution import heap
from verimono.execution.heap import heap_kept
from verimono.execution.profiles import LARGE_N

_PROBE = textwrap.dedent("""
    import resource
    import numpy as np
    from verimono.execution.heap import heap_kept

    def faults(reps=10, k=4, n=10 ** 6):
        # a sample's pattern at n = 10^6: k fresh 8 MB arrays written, then all freed
        r0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        for _ in range(reps):
            arrs = [np.full(n, float(i)) for i in range(k)]
            del arrs
        return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - r0

    without = faults()
    with heap_kept(10 ** 6) as kept:
        inside = faults()
    print(without, int(kept), inside)
""")

glibc = pytest.mark.skipif(heap._glibc() is None, reason="glibc's mallopt only (the C library here is another)")


@pytest.mark.slow
@glibc
def test_freed_blocks_are_kept_inside_a_large_battery():
    """Ten rounds of four 8 MB arrays: 4 x 1954 pages each.  Without (glibc's dynamic thresholds trim the heap's top
    after each round: ~2 x 10^4 faults measured) against one round's faults inside; seen failing with the ``mallopt``
    calls removed (the count inside then equals the count without)."""
    out = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    without, kept, inside = map(int, out.stdout.split())
    one_round = 4 * (8 * 10 ** 6 // 4096 + 1)
    assert kept == 1
    assert inside <= 1.5 * one_round, (without, inside)        # the first round faults, the nine others reuse it
    assert without >= 2 * inside, (without, inside)            # what the kept heap saves (the planted control)


@glibc
def test_inside_a_large_battery_a_round_of_fresh_arrays_is_faulted_in_once():
    """In this process (whatever an earlier battery left): inside, three rounds of three 8 MB arrays fault about one
    round's pages (the slow test above sees the count without, in a fresh interpreter)."""
    import resource

    import numpy as np
    with heap_kept(10 ** 6):
        r0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        for _ in range(3):
            arrs = [np.full(10 ** 6, float(i)) for i in range(3)]
            del arrs
        inside = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - r0
    assert inside <= 1.5 * 3 * (8 * 10 ** 6 // 4096 + 1), inside


def test_nothing_changes_at_or_below_large_n():
    with heap_kept(LARGE_N) as kept:
        assert kept is False
    with heap_kept(3) as kept:
        assert kept is False


@glibc
def test_nested_batteries_share_one_setting(monkeypatch):
    calls = []
    monkeypatch.setattr(heap, "_glibc", lambda: (lambda p, v: calls.append((p, v)) or 1,
                                                 lambda pad: calls.append(("trim", pad)) or 1))
    with heap_kept(LARGE_N + 1):
        with heap_kept(LARGE_N + 1):
            pass
        assert calls == [(heap.M_MMAP_THRESHOLD, heap.KEPT_MMAP), (heap.M_TRIM_THRESHOLD, heap.KEPT_TRIM)]
    assert calls[2:] == [(heap.M_TRIM_THRESHOLD, heap.AFTER_TRIM), (heap.M_MMAP_THRESHOLD, heap.AFTER_MMAP), ("trim", 0)]


class _Entered(Exception):
    pass


def _refuse(n):
    raise _Entered(n)


def test_both_batteries_keep_the_heap_for_their_largest_subject(monkeypatch):
    """``check_operator`` and ``check_stepper`` (in this process) enter ``heap_kept`` with the subject's number of
    coordinates — the operator's ``dim``, the largest problem's initial state — before any law runs."""
    import numpy as np

    import verimono as vm
    from verimono.checks import operator_battery, stepper_battery
    monkeypatch.setattr(operator_battery, "heap_kept", _refuse)
    monkeypatch.setattr(stepper_battery, "heap_kept", _refuse)
    with pytest.raises(_Entered) as got:
        vm.check_operator(vm.NormSubdifferential(1.0, 7), seed=0)
    assert got.value.args == (7,)
    problems = [vm.Problem(vm.NormSubdifferential(1.0, dim=n), np.linspace(-1.0, 1.0, n), 1.0) for n in (3, 11)]
    with pytest.raises(_Entered) as got:
        vm.check_stepper(vm.solve, problems, orders=False, generated=0)
    assert got.value.args == (11,)


def test_a_c_library_ctypes_cannot_open_by_none_keeps_nothing(monkeypatch):
    """Where ``ctypes.CDLL(None)`` cannot open the process's own C library (Windows: ``LoadLibrary`` needs a name
    and raises ``TypeError``), the battery runs with nothing changed, as on any other non-glibc C library (probe2:
    the ``TypeError`` escaped ``heap_kept`` and a battery above ``LARGE_N`` raised before its first law)."""
    def no_handle(name, *args, **kwargs):
        raise TypeError("LoadLibrary() argument 1 must be str, not None")
    monkeypatch.setattr(heap.ctypes, "CDLL", no_handle)
    assert heap._glibc() is None
    with heap_kept(LARGE_N + 1) as kept:
        assert kept is False
