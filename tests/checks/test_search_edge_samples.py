"""Issue 43 item 1: the edge samples (:func:`verimono.checks.engine.sweep.edge_draws`) in place of hypothesis's
generate phase after NumPy draws that found nothing — the kinds of points it contributed (its simplest example,
extreme floats beside ordinary entries, repeated values), drawn by NumPy, seeded.  A plant broken only at such a
point is caught by them, and not without them; its lawful control passes."""

from __future__ import annotations

import numpy as np

from verimono import operator_from_resolvent
from verimono.checks.engine import search
from verimono.checks.engine.samples import Sample
from verimono.checks.engine.sweep import EDGE_CONSTANTS, EDGE_MIN, edge_count, edge_draws
from verimono.checks import run_law
from verimono.records.results import FAILED, PASSED

TINY = np.finfo(float).tiny      # the smallest normal float64: below it, subnormals


def _soft_threshold(sign, name):
    """``J_λ`` of ``F = ∂|·|₁`` on ``R^3`` (soft thresholding, ``sign(x) max(|x| - λ, 0)``) with ``sign`` given."""
    def res(x, lam, t):
        x = np.asarray(x, dtype=float)
        with np.errstate(invalid="ignore"):         # the plant's inf · 0 (its bug, not a warning of ours)
            return sign(x) * np.maximum(np.abs(x) - lam, 0.0)
    return operator_from_resolvent(res, 3, name=name)


def _overflowing_sign(x):
    """``x · (1/|x|)`` guarded at ``x = 0`` only: ``1/|x|`` overflows to ``inf`` exactly when ``x`` is subnormal,
    and ``sign · 0`` is then NaN — wrong at subnormal entries and nowhere else."""
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        return np.where(x == 0.0, 0.0, x * (1.0 / np.where(x == 0.0, 1.0, np.abs(x))))


def test_a_resolvent_wrong_only_at_subnormal_entries_is_caught_by_the_edge_samples_and_not_without(monkeypatch):
    plant = _soft_threshold(_overflowing_sign, "soft threshold, sign = x/|x| (overflows at subnormals)")
    control = _soft_threshold(np.sign, "soft threshold")
    for seed in (0, 1):
        bad = run_law("resolvent_nonexpansive", plant, seed=seed, examples=20)
        assert bad.status == FAILED, str(bad)
        x = np.abs(np.r_[bad.counterexample["x1"], bad.counterexample["x2"]])
        assert np.any((x > 0) & (x < TINY)), bad.counterexample            # it is met at a subnormal entry
        assert run_law("resolvent_nonexpansive", plant, sample=bad.counterexample).status == FAILED   # replays
        good = run_law("resolvent_nonexpansive", control, seed=seed, examples=20)
        assert good.status == PASSED and good.details["searched"]["edge_samples"] == edge_count(20), str(good)
    monkeypatch.setattr(search, "edge_draws", lambda *a, **k: [])      # the draws, sweep and coordinates alone
    # (the scale phase's whole subnormal points catch it too: tests/checks/test_search_scales.py)
    monkeypatch.setattr(search, "scale_samples", lambda *a, **k: ([], {"points": 0}))
    for seed in (0, 1):
        assert run_law("resolvent_nonexpansive", plant, seed=seed, examples=20).status == PASSED


def test_edge_draws_are_seeded_and_hold_hypothesis_kinds_of_points():
    """The simplest sample first, then identical points; subnormal, tiny (below 10^-10) and the named extreme
    entries beside ordinary ones; coordinates of x2 equal to x1's; steps in [10^-3, 10], times in [0, T]."""
    a = edge_draws(3, 5, 2.0, 64, Sample)
    assert [s.to_dict() for s in a] == [s.to_dict() for s in edge_draws(3, 5, 2.0, 64, Sample)]
    assert [s.to_dict() for s in a] != [s.to_dict() for s in edge_draws(3, 6, 2.0, 64, Sample)]
    s0 = a[0]
    assert not s0.x1.any() and not s0.x2.any() and (s0.lam, s0.mu, s0.nu, s0.t) == (1.0, 1.0, 1.0, 0.0)
    assert np.array_equal(a[1].x1, a[1].x2)
    x = np.abs(np.array([s.x1 for s in a]))
    assert np.mean((x > 0) & (x < TINY)) > 0.02 and np.mean((x >= TINY) & (x < 1e-10)) > 0.1
    assert np.mean(np.isin(x, EDGE_CONSTANTS)) > 0.05 and np.mean(x > 1e-3) > 0.4 and np.all(x <= 10.0)
    assert np.mean([np.any(s.x1 == s.x2) for s in a[2:]]) > 0.3        # repeated values
    steps = np.array([[s.lam, s.mu, s.nu] for s in a])
    assert np.all((steps >= 1e-3) & (steps <= 10.0)) and all(0.0 <= s.t <= 2.0 for s in a)
    assert any(0.0 < s.t < 1e-6 for s in a) and edge_count(1) == EDGE_MIN and edge_count(200) == 100
