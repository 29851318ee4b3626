"""The members besides the resolvent, judged against the resolvent's own values (verimono/checks/operator_laws.py):
``yosida_member`` (an override of ``Operator.yosida`` equals ``(x - J_λx)/λ``), ``contains_rejects`` (the declared
membership rejects a pair that breaks monotonicity with a graph point) and ``project_domain_nearest`` (the nearest
point of ``cl dom F``), and ``resolvent_single_valued`` across input forms — each seen failing on a broken subject
and passing on its twin, the same code a percent or two away or with the fault off."""

from __future__ import annotations

import numpy as np
import pytest

import zoo
import verimono as vm
from verimono.checks import run_law
from verimono.checks.operator_laws import CONTAINS_BREAK, CONTAINS_DECIDABLE, _breaking_pair

EX = 12


@pytest.mark.parametrize("factor,status", [(0.5, "failed"), (0.99, "failed"), (1.0, "passed")])
def test_a_yosida_member_off_by_one_percent_fails_and_the_exact_one_passes(factor, status):
    r = run_law("yosida_member", zoo.yosida_member_halved(factor), seed=0, examples=EX)
    assert r.status == status, str(r)
    if status == "failed":      # |Y_member - Y| = (1 - factor)|Y|, far beyond the slack 4·RTOL(1 + |x|)/λ
        cex = r.counterexample
        assert cex["lhs"] == pytest.approx((1 - factor) * np.linalg.norm(cex["Y_from_J"]), rel=1e-6)


def test_yosida_member_is_skipped_where_the_operator_has_no_yosida_of_its_own():
    r = run_law("yosida_member", vm.L1Subdifferential(1.0, 2), seed=0, examples=EX)
    assert r.status == "skipped" and "yosida" in r.message


def test_the_breaking_pair_breaks_monotonicity_by_its_factor():
    """(u1, v2 - c(u1 - u2)) against (u2, v2): ⟨Δu, Δv⟩ = -c|Δu|², and the ratio is that over the tolerances."""
    x1, x2, lam = np.array([3.0, -1.0]), np.array([0.5, 2.0]), 0.5
    F = vm.L1Subdifferential(1.0, 2)
    u1, u2 = F.resolvent(x1, lam), F.resolvent(x2, lam)
    v, q, ndu, tx = _breaking_pair(2, x1, x2, u1, u2, lam, 1e-8)
    v2 = (x2 - u2) / lam
    c = CONTAINS_BREAK * (1 + np.linalg.norm((x1 - u1) / lam) + np.linalg.norm(v2) + 4 * 1e-8 * 4 / lam) / ndu
    assert float((u1 - u2) @ (v - v2)) == pytest.approx(-c * ndu ** 2, rel=1e-12)
    assert q > 1e3 * CONTAINS_DECIDABLE and tx < 1e-5 * ndu      # decided by a wide margin at |Δu| ~ 1
    assert not F.contains(u1, v, 0.0, 1e-8)         # a correct membership test rejects it


@pytest.mark.parametrize("make,status", [(zoo.contains_accepts_everything, "failed"),
                                         (lambda: vm.L1Subdifferential(1.0, 2), "passed"),
                                         (lambda: vm.NormalCone(vm.sets.Ball([0.0, 0.0], 1.0)), "passed")],
                         ids=["accepts_everything", "l1", "ball"])
def test_a_membership_test_accepting_everything_fails_and_the_catalogs_pass(make, status):
    r = run_law("contains_rejects", make(), seed=0, examples=EX)
    assert r.status == status, str(r)
    if status == "failed":
        assert r.worst >= 2.0


@pytest.mark.parametrize("shrink,status", [(None, "failed"), (0.98, "failed"), (1.0, "passed")])
def test_a_projection_onto_the_domain_that_is_not_the_nearest_point_fails(shrink, status):
    """The box [-1, 1]^3: the radial retraction and the clip onto [-0.98, 0.98]^3 (both inside the domain, neither
    nearest) fail; the clip itself passes."""
    if shrink is None:
        op = zoo.project_domain_radial()
    else:
        box = vm.sets.Box([-1.0] * 3, [1.0] * 3)
        cone = vm.NormalCone(box)
        op = vm.operator_from_resolvent(cone.resolvent, 3, min_norm=cone.min_norm, contains=cone.contains,
                                        project_domain=lambda x, t=0.0: np.clip(np.asarray(x, float), -shrink, shrink),
                                        name=f"clip {shrink}")
    r = run_law("project_domain_nearest", op, seed=0, examples=EX)
    assert r.status == status, str(r)


def test_a_resolvent_depending_on_the_layout_fails_and_its_twin_passes():
    bad = run_law("resolvent_single_valued", zoo.layout_dependent(), seed=0, examples=EX)
    assert bad.status == "failed" and bad.counterexample["form"] in ("strided", "slice"), str(bad)
    assert "contiguous" in bad.message
    again = run_law("resolvent_single_valued", zoo.layout_dependent(), sample=bad.counterexample)
    assert again.status == "failed"
    assert run_law("resolvent_single_valued", zoo.lawful_layout(), seed=0, examples=EX).status == "passed"


def _far_sign_shortcut(exact: bool):
    """The unit ball's projection with a shortcut for |x| > 1e5: sign(x)/|sign(x)| (on the sphere; the projection
    only on the coordinate axes and the diagonals); ``exact``: x/|x| there, the lawful twin."""
    def J(x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        r = float(np.linalg.norm(x))
        if r > 1e5:
            s = x if exact else np.sign(x)
            return s / float(np.linalg.norm(s))
        return x / max(1.0, r)
    def contains(x, y, t=0.0, tol=None):       # y ∈ N_B(x) up to tol, absolutely (the catalog's reads it relatively)
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        r = float(np.linalg.norm(x))
        if r > 1.0 + tol:
            return False
        if r < 1.0 - tol:
            return float(np.linalg.norm(y)) <= tol
        return float(np.linalg.norm(y - (y @ x) / r ** 2 * x)) <= tol and float(y @ x) >= -tol
    cone = vm.NormalCone(vm.sets.Ball([0.0, 0.0, 0.0], 1.0))
    return vm.operator_from_resolvent(J, 3, project_domain=cone.project_domain, contains=contains,
                                      name="far shortcut" if not exact else "far branch x/|x|")


def test_the_sweep_evaluates_far_points_off_the_axes():
    """The sweep's far decade (|x1| = 10^6, every 12th sample) fell on the axes and into the range of J every time
    (12 ≡ 0 mod 3 and 4): every other far sample is now in a general direction, evaluated as drawn; the stream of the
    other samples is unchanged.  A far shortcut exact on the axes fails on seeds 0-2; its twin passes."""
    from verimono.checks.engine.samples import Sample
    from verimono.checks.engine.sweep import FAR, _sweep_draws, far_general, sweep_samples
    op = vm.NormalCone(vm.sets.Ball([0.0, 0.0, 0.0], 1.0))
    ss = sweep_samples(op, 0, 1.0, 33, Sample)
    far = [s for s in ss if np.linalg.norm(s.x1) >= FAR]
    assert far and all(np.count_nonzero(s.x1) == 3 for s in far)     # evaluated as drawn, off the axes
    X1 = _sweep_draws(3, 0, 1.0, 33, 1e300)[0]
    axis_far = [i for i in range(33) if np.linalg.norm(X1[i]) >= FAR and not far_general(i, 1e300, 3)]
    assert axis_far and all(np.count_nonzero(X1[i]) == 1 for i in axis_far)     # the axes kept
    for seed in (0, 1, 2):
        assert run_law("yosida_in_graph", _far_sign_shortcut(False), seed=seed, examples=EX).status == "failed"
        assert run_law("yosida_in_graph", _far_sign_shortcut(True), seed=seed, examples=EX).status == "passed"


def test_a_yosida_record_states_the_smallest_step_it_can_judge():
    """A soft threshold at 1.5λ only for λ in [1e-9, 1e-8) (blind set 7, miss 1): |Y_λx| = 1.5 > |F^0x| = 1 there, but
    the Yosida laws' slack 6·rtol(1 + |x|)/λ (an iterative resolvent within rtol of |x| must pass) exceeds the
    violation below λ ≈ 1.2e-7: the law passes, and its record says that a violation of |Y| is judgeable only from
    λ = 1.2e-7 on (at |x| = |Y| = 1), above the band; the same law on a step wrong at λ = 1 fails."""
    def build(lo, hi):
        def J(x, lam, t=0.0):
            x = np.asarray(x, dtype=float)
            thr = 1.5 * lam if lo <= lam < hi else lam
            return np.sign(x) * np.maximum(np.abs(x) - thr, 0.0)
        F = vm.L1Subdifferential(1.0, 3)
        return vm.operator_from_resolvent(J, 3, min_norm=F.min_norm, contains=F.contains, name=f"1.5λ on [{lo}, {hi})")
    r = run_law("yosida_bounded_by_min_norm", build(1e-9, 1e-8), seed=0, examples=EX)
    res = r.details["searched"]["yosida_resolution"]
    assert r.status == "passed" and res["lambda_min_at_unit"] == pytest.approx(12 * 1e-8) and res["lambda_min_at_unit"] > 1e-8
    assert "judgeable only for λ ≥" in r.message and res["lambda_min_at_largest_x"] >= res["lambda_min_at_unit"]
    assert run_law("yosida_bounded_by_min_norm", build(0.5, 2.0), seed=0, examples=EX).status == "failed"
    assert "yosida_resolution" not in run_law("resolvent_nonexpansive", build(0.5, 2.0), seed=0,
                                              examples=EX).details["searched"]


# -- contains_rejects at float32 and large n (branch f32power): the tol handed to contains is 2·tolerance/sqrt(n) per
# coordinate, so its Euclidean reach is the pair's own error, not sqrt(n) times it --------------------------------

def _decided(r) -> int:
    """The samples of a record that were not inconclusive ("N samples (K inconclusive)")."""
    import re
    m = re.match(r"(\d+) samples(?: \((\d+) inconclusive\))?", r.message)
    assert m, r.message
    return int(m.group(1)) - int(m.group(2) or 0)


BIG = 10_000


def _cone_float32(contains, name):
    """The normal cone of the box ``[-1, 1]^n``, n = 10^4, computing in float32 (tests/zoo_precision.py), with the
    membership test ``contains`` (made from the float32 operator)."""
    from zoo_precision import float32
    F32 = float32(vm.NormalCone(vm.sets.Box(-np.ones(BIG), np.ones(BIG))))
    return vm.operator_from_resolvent(F32.resolvent, BIG, contains=contains(F32), name=name)


@pytest.mark.parametrize("contains,status", [
    (lambda F: (lambda x, y, t=0.0, tol=None: True), "failed"),        # the zoo's contains_accepts_everything
    (lambda F: F.contains, "passed"),                                   # the same operator, its own contains
    # the loosest reading the law grants: tol per coordinate and relative to |y| (a subgradient test's)
    (lambda F: (lambda x, y, t=0.0, tol=None: F.contains(x, y, t, tol * (1.0 + np.linalg.norm(y)))), "passed"),
], ids=["accepts_everything", "own", "relative_reach"])
def test_contains_rejects_decides_at_float32_in_ten_thousand_dimensions(contains, status):
    """Was skipped (all samples inconclusive) for every float32 operator at n >= 10^3: with 2·tolerance per coordinate
    the reach of contains, sqrt(n)·2·rtol·(1 + |v|), bounded the break's ratio by 1/(2·sqrt(n)·rtol) ≈ 2 (float32,
    n = 10^4).  Now the membership that says yes to everything fails there, by the recorded factor, and the correct
    ones — even one reading its tol relative to |y| — pass with most samples decided."""
    r = run_law("contains_rejects", _cone_float32(contains, status), seed=0, examples=EX)
    assert r.status == status and r.details["dtype"] == "float32", str(r)
    if status == "failed":
        assert r.worst >= CONTAINS_DECIDABLE
    else:
        assert _decided(r) > 0, str(r)


def test_a_contains_taking_no_tol_keeps_the_protocols_reach_and_is_not_failed():
    """``contains(x, y, t)`` decides at its own tolerance, which the law cannot shrink: its reach is taken as the
    protocol's default per coordinate (the rule before), sqrt(n) times the pair's error at n = 10^4, where no sample of
    the cone is decidable — a counted skip that says why, never a pass, while the same test taking the law's tol
    decides."""
    own = run_law("contains_rejects", _cone_float32(lambda F: F.contains, "own"), seed=0, examples=EX)
    no_tol = run_law("contains_rejects", _cone_float32(lambda F: (lambda x, y, t=0.0: F.contains(x, y, t)), "no tol"),
                     seed=0, examples=EX)
    assert own.status == "passed" and _decided(own) > 0, str(own)
    assert no_tol.status == "skipped" and "inconclusive" in no_tol.message, str(no_tol)
