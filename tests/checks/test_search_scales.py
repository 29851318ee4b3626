"""The scale phase (:mod:`verimono.checks.engine.scales`): whole points scaled over every decade of the precision
(float64's smallest subnormal to ``10^99``), whole points of one shape at the landmarks.  A projection wrong only
when *every* entry of ``x`` is below ``2^-1024`` (blind set 8, ``ball_reciprocal_scale_subnormal``) is caught on
every seed through a non-finite output of a finite input (failed, never undecided), missed without the phase, and
its twin (the same code dividing instead of multiplying by a reciprocal) passes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from verimono import operator_from_resolvent
from verimono.checks import run_law
from verimono.checks.engine import search
from verimono.checks.engine.samples import Sample
from verimono.checks.engine.scales import SMALLEST, landmarks, scale_samples, scale_top
from verimono.records.results import FAILED, PASSED


def _ball(reciprocal: bool):
    """Projection onto the unit ball of ``R^3`` scaled by ``s = max|x_i|`` first (overflow-safe); ``reciprocal``
    multiplies by ``1/s``, which is ``+inf`` when every entry is below ``2^-1024``: NaN out there only."""
    def res(x, lam, t=0.0):
        x = np.asarray(x, dtype=float)
        s = float(np.max(np.abs(x), initial=0.0))
        if s == 0.0:
            return x.copy()
        with np.errstate(over="ignore", invalid="ignore"):
            y = x * (1.0 / s) if reciprocal else x / s
            ny = float(np.linalg.norm(y))
            return x.copy() if s * ny <= 1.0 else y / ny
    return operator_from_resolvent(res, 3, name="ball, x·(1/max|x|)" if reciprocal else "ball, x/max|x|")


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_resolvent_wrong_only_on_all_subnormal_points_is_failed_by_the_scale_phase(seed):
    bad = run_law("resolvent_nonexpansive", _ball(True), seed=seed, examples=20)
    assert bad.status == FAILED, str(bad)
    cex = bad.counterexample
    x1, x2 = np.asarray(cex["x1"]), np.asarray(cex["x2"])
    assert np.all(np.isfinite(x1)) and np.all(np.isfinite(x2)) and "non-finite" in bad.message
    assert any(0 < np.abs(x).max() < 2.0 ** -1024 for x in (x1, x2)), cex      # a whole point below 1/largest
    assert bad.worst == math.inf and run_law("resolvent_nonexpansive", _ball(True), sample=cex).status == FAILED
    good = run_law("resolvent_nonexpansive", _ball(False), seed=seed, examples=20)
    assert good.status == PASSED, str(good)
    scales = good.details["searched"]["scales"]
    assert scales["range"] == [SMALLEST, 1e99] and scales["stride"] <= 20 and scales["points"] >= 30
    assert good.details["searched"]["x_range"][1] >= 1e99


def test_without_the_scale_phase_the_all_subnormal_point_is_missed(monkeypatch):
    monkeypatch.setattr(search, "scale_samples", lambda *a, **k: ([], {"points": 0}))
    assert run_law("resolvent_nonexpansive", _ball(True), seed=0, examples=20).status == PASSED


def test_scale_samples_cover_every_decade_and_the_shapes():
    start = Sample(np.array([3.0, -1e-300, 0.5]), np.array([2.0, 0.0, -4.0]), 0.5, 2.0, 1.0, 0.25)
    out, covered = scale_samples(start, 27, 3, Sample)
    tops = sorted({max(np.abs(s.x1).max(), np.abs(s.x2).max()) for s in out})
    assert tops[0] == SMALLEST and tops[-1] == 1e99
    gaps = np.diff(np.log10(tops))
    assert gaps.max() <= covered["stride"] <= 20                   # no decade gap wider than the stated stride
    scaled = [s for s in out if s.lam == 0.5]
    assert all(np.all(np.isfinite(s.x1)) for s in out)
    assert max(max(np.abs(s.x1).max(), np.abs(s.x2).max()) for s in scaled) == 1e99 / 4    # |x|/λ, (μ/λ)x finite
    assert any(np.all(s.x1 == s.x1[0]) and 0 < s.x1[0] < 2.0 ** -1024 for s in out)     # every entry subnormal
    assert any(np.count_nonzero(s.x1) == 1 and np.abs(s.x1).max() == SMALLEST for s in out)  # zero but one
    assert len({id(s.x1) for s in out} | {id(s.x2) for s in out}) == 2 * len(out)          # each owns its points
    assert all(s.x1.flags.writeable for s in out)
    assert scale_top(np.finfo(np.float32).max) == 1e9 and scale_top(65504.0) == 65504.0 / 64
    assert float(np.finfo(np.float32).smallest_subnormal) in landmarks(float(np.finfo(np.float32).max))
    capped, c2 = scale_samples(start, 27, 3, Sample, cap=8)
    assert len(capped) == 8 == c2["points"] and min(np.abs(s.x1).max() for s in capped) == SMALLEST


def test_beyond_the_sweeps_scale_only_a_non_finite_output_is_judged():
    """Above |x| = 10^6 a scale sample is judged on J_λ finite there only (the laws' round-off allowance is stated at
    the points they compute: a projection of 10^17 e_1 carries eps·10^17 ≈ 11); the law's own overflow (a side not
    finite) is inconclusive at any scale; below 10^6 the law itself judges."""
    from verimono.checks.core import Outcome
    from verimono.checks.engine.scales import FINITE_ONLY, JUDGED_TOP, beyond_judgement, judged_by
    from verimono.checks.engine.search import evaluate_sample
    from verimono.checks.operator_laws import check_resolvent_nonexpansive as law

    def at(v):
        return Sample(np.array([v, 0.0, 0.0]), np.zeros(3), 1.0, 1.0, 1.0, 0.0)
    assert judged_by(law, at(1e17)) is FINITE_ONLY and judged_by(law, at(JUDGED_TOP)) is law
    assert judged_by(law, at(1e-320)) is law
    for op in (_ball(False), _ball(True)):
        held = evaluate_sample(FINITE_ONLY, op, at(1e99))
        assert held.ratio == 0.0 and held.inconclusive          # finite: no verdict on the law itself
    assert evaluate_sample(FINITE_ONLY, _ball(True), at(1e-320)).ratio == math.inf      # NaN out: failed
    overflow = Outcome.compare(-5e299, 0.0, math.inf, "e_λ(x2) ≤ ...")
    assert "not finite" in beyond_judgement(overflow, at(1.0))
    assert beyond_judgement(Outcome.compare(12.0, 0.0, 1e-6, "dist"), at(1e-320)) is None
