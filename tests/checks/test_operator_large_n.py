"""The operator battery at large n: the coordinate budget falls above ``LARGE_N`` coordinates as a count
(:func:`verimono.execution.profiles.large_n_count`), the record states it, and a broken operator still fails.

Each design row of an operator law costs O(n); above ``LARGE_N = 2^14`` coordinates the coordinate search's
budget is ``min(count, max(LARGE_FLOOR, count * LARGE_N // n))`` — the same on every machine — so that the
battery at ``n = 10^6`` ends with a verdict.  Nothing changes for ``n <= LARGE_N``.
"""

from __future__ import annotations

import pytest

import verimono as vm
from verimono.checks.operator_battery import LAWS as OPERATOR_LAWS
from verimono.checks.engine.search import run_law
from verimono.checks.engine.supremum import budgets
from verimono.execution.config import current
from verimono.execution.profiles import LARGE_FLOOR, LARGE_N, get_profile, large_n_count
from verimono.records.results import FAILED, PASSED, SKIPPED, UNDECIDED


def test_the_cap_is_a_count_of_n_only():
    ci = get_profile("ci").search["coordinate"]
    # nothing changes up to LARGE_N, whatever the count
    for count in (1, 15, 27, 729):
        for n in (1, 3, 50, 2000, LARGE_N):
            assert large_n_count(count, n) == count
    # above it: count * LARGE_N // n, at least the floor, never more than the count
    assert large_n_count(ci, 2 * LARGE_N) == ci // 2
    assert large_n_count(729, 10 ** 5) == 729 * LARGE_N // 10 ** 5 == 119
    assert large_n_count(ci, 10 ** 6) == LARGE_FLOOR
    assert large_n_count(2, 10 ** 6, floor=3) == 2          # a budget below the floor is not raised
    assert all(large_n_count(ci, n) >= large_n_count(ci, n + 1) for n in range(LARGE_N, LARGE_N + 3000, 97))


def _block_factor(n: int, factor: float) -> vm.Operator:
    """``∂|·|`` on R^n whose resolvent multiplies its first quarter of coordinates by ``factor`` (a bug
    confined to one coordinate block: for ``factor > 1`` the resolvent expands there; ``factor = 1`` is
    the correct operator, through the same wrapper)."""
    F = vm.NormSubdifferential(1.0, n)
    k = max(1, n // 4)

    def resolvent(x, lam, t):
        p = F.resolvent(x, lam, t)
        p[..., :k] *= factor
        return p
    return vm.operator_from_resolvent(resolvent, n, min_norm=F.min_norm, project_domain=F.project_domain,
                                      contains=F.contains, name=f"block_factor_{factor}")


def test_the_record_states_the_cap_above_large_n():
    n = LARGE_N + 1          # the first n capped: 4 * LARGE_N // n = 3
    with budgets(coordinate=4):
        rec = run_law("resolvent_nonexpansive", vm.NormSubdifferential(1.0, n), seed=0, examples=10)
    assert rec.status == PASSED, rec.message
    assert rec.details["searched"]["budget"] == (
        f"coordinate budget capped at 3 points for n = {n} ({current().profile} promises 4 for n <= {LARGE_N})")
    small = run_law("resolvent_nonexpansive", vm.NormSubdifferential(1.0, 50), seed=0, examples=10)
    assert "budget" not in small.details["searched"]


def test_a_block_factor_fails_above_large_n_and_its_control_passes():
    n = LARGE_N + 1
    bad = run_law("resolvent_nonexpansive", _block_factor(n, 1.02), seed=0, examples=10)
    good = run_law("resolvent_nonexpansive", _block_factor(n, 1.0), seed=0, examples=10)
    assert bad.status == FAILED, bad.message
    assert good.status == PASSED, good.message


@pytest.mark.slow
def test_the_battery_at_a_million_coordinates():
    n = 10 ** 6
    rep = vm.check_operator(vm.NormSubdifferential(lambda t: 1.0 + t, dim=n), seed=0, profile="ci")
    assert rep.counts["failed"] == 0 and rep.counts["undecided"] == 0, rep.summary()
    skipped = {r.check for r in rep.results if r.status == SKIPPED}
    # prox_minimiser: n <= 4 only; yosida_member: NormSubdifferential states no yosida() of its own
    assert skipped == {"prox_minimiser", "yosida_member"}, rep.summary()
    assert rep.counts["passed"] == len(OPERATOR_LAWS) - len(skipped), rep.summary()
    assert all(f"capped at {LARGE_FLOOR} points for n = 1000000" in r.details["searched"]["budget"]
               for r in rep.results if r.status == PASSED and r.details.get("coordinate"))
    broken = vm.check_operator(_block_factor(n, 1.5), seed=0, profile="ci")
    failed = {r.check for r in broken.results if r.status == FAILED}
    assert {"resolvent_nonexpansive", "resolvent_firmly_nonexpansive"} <= failed, broken.summary()
    assert not [r for r in broken.results if r.status == UNDECIDED], broken.summary()


def test_norm_unscaled_above_unscaled_n_only_where_safe():
    """Above ``UNSCALED_N`` entries :func:`verimono.checks.members.norm` is ``sqrt(v·v)`` when ``|v|_inf`` lies in
    ``SAFE_SQUARES``: within a few ulps of the scaled norm (the exact norm to ~n·eps) at every scale, never 0
    for differences of 1e-250 nor inf for points of 1e300 (there it scales, as at or below ``UNSCALED_N``)."""
    import math
    import numpy as np
    from verimono.checks.members import UNSCALED_N, norm
    rng = np.random.default_rng(0)
    for n in (UNSCALED_N, UNSCALED_N + 1):
        v = rng.standard_normal(n)
        for scale in (1e-300, 1e-250, 1e-120, 1.0, 1e120, 1e300):
            w = scale * v
            m = float(np.max(np.abs(w)))
            scaled = m * float(np.linalg.norm(w / m))
            got = norm(w)
            assert math.isfinite(got) and got > 0, (n, scale, got)
            assert abs(got - scaled) <= 8 * np.finfo(float).eps * scaled, (n, scale, got, scaled)
            if n == UNSCALED_N or not 2.0 ** -400 < m < 2.0 ** 400:
                assert got == scaled, (n, scale)        # at or below UNSCALED_N, or outside the safe range: scaled
