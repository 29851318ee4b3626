"""Issue 24: a stated constant is a claim about every t, and an undecided jump is never a pass.

Each test plants a violation that the seven fixed sample times ``k/6`` cannot see (a ball whose centre is
``0.5 sin 6πt``; ``F = (1 + 5 sin² 6πt)x``), a jump whose side cannot be decided, or a blip inside one cell
of the old jump grid, and requires the record to say so — and the honest variant to pass."""

from __future__ import annotations

import math

import numpy as np
import pytest

import verimono as vm
from verimono import Linear, Problem
from verimono.checks.assumptions import UNDECIDED_SIDE, check_assumptions
from verimono.checks.over_time import sup_over_time
from verimono.records.results import FAILED, PASSED, UNDECIDED


def _by(report):
    return {r.check: r for r in report}


def _wobbling_ball(amplitude=0.5):
    """A unit ball whose centre is ``amplitude·sin 6πt``: 0 at every sample time ``k/6`` of ``[0, 1]``."""
    centre = lambda t: np.array([amplitude * math.sin(6 * math.pi * t), 0.0])      # noqa: E731
    return Problem(vm.NormalCone(vm.sets.Ball(centre, 1.0)), [0.0, 0.0], 1.0, name="wobbling ball")


def test_phi_zero_for_a_ball_moving_between_sample_times_fails_A3():
    rec = _by(check_assumptions(_wobbling_ball().replace(phi=lambda t: 0.0), composite=False))["assumption_A3"]
    assert rec.status == FAILED, str(rec)
    c = rec.counterexample
    assert c["found_by"] == "search over time" and c["dist"] > 0.01
    assert all(abs(t * 6 - round(t * 6)) > 1e-9 for t in (c["s"], c["t"]))      # between the sample times
    assert rec.details["sup_search"]["evaluations"] > rec.details["sup_search"]["grid_nodes"]


def test_a_true_phi_for_the_moving_ball_passes_A3():
    # |centre'| ≤ 0.5·6π: φ(t) = 3πt bounds the motion
    rec = _by(check_assumptions(_wobbling_ball().replace(phi=lambda t: 3 * math.pi * t), composite=False))
    assert rec["assumption_A3"].status == PASSED, str(rec["assumption_A3"])


def _oscillating_gain(sigma=None, theta=None):
    c = lambda t: 1.0 + 5.0 * math.sin(6 * math.pi * t) ** 2                        # noqa: E731
    return Problem(Linear(lambda t: c(t) * np.eye(1)), [1.0], 1.0, sigma=sigma, theta=theta, name="oscillating gain")


def test_sigma_one_for_a_gain_peaking_between_sample_times_fails_LG():
    rec = _by(check_assumptions(_oscillating_gain(sigma=lambda t: 1.0), composite=False))["assumption_LG"]
    assert rec.status == FAILED, str(rec)
    sup = rec.details["sup_search"]
    # |F^0|/(1 + |z|) = c(t)|z|/(1 + |z|) peaks at t = 1/12 + k/6 (c = 6), never a sample time k/6
    assert sup["sup"] > 5.0 and abs(6 * sup["t"] - round(6 * sup["t"])) > 0.1
    assert "found by the search" in rec.message         # over time (and along the rays at that time)


def test_the_true_sigma_passes_LG():
    rec = _by(check_assumptions(_oscillating_gain(sigma=lambda t: 6.0), composite=False))["assumption_LG"]
    assert rec.status == PASSED, str(rec)
    assert 0.85 < rec.details["sup_search"]["sup"] <= 1.0     # c = 6 attained; |z|/(1 + |z|) ≈ 0.87 at the samples


def _bump(t):
    """1, and 1 + 5 sin²(π(t − 0.44)/0.05) on (0.44, 0.49): between the sample times 1/3 and 1/2."""
    return 1.0 + 5.0 * math.sin(math.pi * (t - 0.44) / 0.05) ** 2 if 0.44 < t < 0.49 else 1.0


def test_theta_zero_for_a_gain_growing_between_sample_times_fails_YB():
    # (YB) against θ ≡ 0 fails wherever c increases: on (0.44, 0.465), which no sampled s or s + λ reaches
    p = Problem(Linear(lambda t: _bump(t) * np.eye(1)), [1.0], 1.0, theta=lambda t: 0.0, name="bump")
    rec = _by(check_assumptions(p, composite=False))["assumption_YB"]
    assert rec.status == FAILED and rec.counterexample["found_by"] == "search over time", str(rec)
    c = rec.counterexample
    assert c["s"] + c["lambda"] > 0.44 and c["s"] < 0.465 and c["lhs"] > 0


def test_a_true_theta_for_the_bump_passes_YB():
    # |Y_λ(s+λ, z)| − |F^0(s, z)| ≤ (c(s+λ) − c(s))|z| ≤ (5π/0.05)·λ·|z| ≈ 314 λ|z|: θ(t) = 2000 t holds
    # for every sampled z (|z| < 6)
    p = Problem(Linear(lambda t: _bump(t) * np.eye(1)), [1.0], 1.0, theta=lambda t: 2000.0 * t, name="bump")
    assert _by(check_assumptions(p, composite=False))["assumption_YB"].status == PASSED


def test_sup_over_time_finds_a_peak_between_grid_nodes_and_only_raises():
    # one family, peak at t* = 0.123456 between the nodes k/16; refine=True reaches it to rounding
    peak = 0.123456
    sup = sup_over_time(lambda t, which: np.array([-abs(t - peak)]), 0.0, 1.0, refine=True)
    assert sup.grid_value < -1e-3 and sup.value > -1e-12 and abs(sup.t - peak) < 1e-12
    flat = sup_over_time(lambda t, which: np.array([0.0, -1.0]), 0.0, 1.0)
    assert flat.value == 0.0 and flat.family == 0


# -- an undecided jump is never a pass; blips are found ---------------------------------------------------------

def _scaled_identity(c):
    return Problem(Linear(lambda t: c(t) * np.eye(2)), [0.5, 0.2], 1.0)


@pytest.mark.parametrize("closed", [True, False], ids=["c=1 for t<=tau", "c=1 for t<tau"])
def test_a_jump_between_adjacent_floats_with_no_shorter_decimal_is_undecided(closed):
    tau = 2 ** -0.5          # no float near it has a shorter decimal than its neighbour
    c = (lambda t: 1.0 if t <= tau else 2.0) if closed else (lambda t: 1.0 if t < tau else 2.0)
    rep = _by(check_assumptions(_scaled_identity(c)))
    rec = rep["assumption_A2"]
    assert rec.status == UNDECIDED and not rec.ok, str(rec)
    assert rec.details["undecided_jumps"] == 1 and rec.details["jumps"][0]["side"] == UNDECIDED_SIDE
    a, b = rec.details["jumps"][0]["bracket"]
    assert a <= tau <= b and np.nextafter(a, 2.0) == b
    assert rep["assumptions_thm_main"].status == UNDECIDED and not rep["assumptions_thm_main"].ok


def test_a_blip_inside_one_cell_of_the_old_grid_fails_A2():
    # c = 2 on (0.45, 0.46] only: inside one cell of a 32-cell grid; it jumps right after 0.45 and after 0.46
    rec = _by(check_assumptions(_scaled_identity(lambda t: 2.0 if 0.45 < t <= 0.46 else 1.0)))["assumption_A2"]
    assert rec.status == FAILED, str(rec)
    assert sorted(j["t"] for j in rec.details["jumps"]) == [0.45, 0.46]
    assert rec.counterexample["t"] in (0.45, 0.46)


def test_a_domain_blip_fails_A3_without_a_stated_phi():
    centre = lambda t: np.array([3.0 if 0.45 < t <= 0.46 else 0.0, 0.0])             # noqa: E731
    p = Problem(vm.NormalCone(vm.sets.Ball(centre, 1.0)), [0.0, 0.0], 1.0, name="blipping ball")
    rec = _by(check_assumptions(p, composite=False))["assumption_A3"]
    assert rec.status == FAILED, str(rec)
    assert rec.counterexample["t"] in (0.45, 0.46)
