"""Issue 43 item 1 (branch opl): the engine's fixed work per law hoisted out of the laws' searches — the seeded
draws of a battery (:func:`verimono.checks.engine.sweep.law_draws`, :func:`~verimono.checks.engine.sweep.edge_draws`,
the seeded part of :func:`~verimono.checks.engine.sweep.sweep_samples`) drawn once per (seed, dimension, count) —
with the samples unchanged: the same as drawn afresh, each owning its points."""

from __future__ import annotations

import numpy as np

from verimono import NormalCone
from verimono.checks.engine import sweep
from verimono.checks.engine.samples import Sample
from verimono.core.sets import Box


def _dicts(samples):
    return [s.to_dict() for s in samples]


def test_cached_draws_are_the_fresh_draws_and_each_sample_owns_its_points():
    op = NormalCone(Box(-np.ones(3), np.ones(3)))
    draws = {"law": lambda: sweep.law_draws(3, 7, 2.0, 20, Sample), "edge": lambda: sweep.edge_draws(3, 7, 2.0, 16, Sample),
             "sweep": lambda: sweep.sweep_samples(op, 7, 2.0, 33, Sample)}
    for name, draw in draws.items():
        sweep._DRAWS.clear()
        fresh = _dicts(draw())
        first = draw()                          # from the cache
        assert _dicts(first) == fresh, name
        for s in first:                         # a subject (or law) writing into its sample's points ...
            s.x1[:] = np.nan
            s.x2[:] = np.nan
        assert _dicts(draw()) == fresh, name   # ... changes no later law's samples
        assert len({id(s.x1) for s in first} | {id(s.x2) for s in first}) == 2 * len(first)
        assert all(s.x1.base is None or s.x1.base.shape == s.x1.shape for s in first)   # no view of a shared block


def _record(law, op, seed):
    from verimono.checks import run_law
    from verimono.execution.config import using
    with using(profile="ci"):
        d = run_law(law, op, seed=seed).to_dict()
    d.pop("duration", None)
    return d


def _band(x, lam, t):
    """Soft thresholding (``F = ∂|·|₁``) that uses ``3λ`` for ``λ ∈ [0.031, 0.036]`` only: broken in a band of one
    coordinate, which the step designs meet (not the draws)."""
    x = np.asarray(x, dtype=float)
    return np.sign(x) * np.maximum(np.abs(x) - (3 * lam if 0.031 <= lam <= 0.036 else lam), 0.0)


def test_one_pass_for_the_lists_known_together_gives_the_records_of_a_pass_per_list(monkeypatch):
    """``_Search.prefetch``: the draws with the edge samples, and every coordinate's design after the direction, in
    one vectorised pass — the same records field by field (status, worst ratio and sample, evaluations, what was
    searched, the counterexample) as a pass per list, in fewer passes; on a lawful operator and on one broken in a
    band of step sizes that the coordinate phase catches."""
    from verimono import operator_from_resolvent
    from verimono.checks.engine import search

    box, band = NormalCone(Box(-np.ones(3), np.ones(3))), operator_from_resolvent(_band, 3, name="band")
    cases = [(band, "resolvent_identity"), (band, "monotone"), (box, "resolvent_firmly_nonexpansive"),
             (box, "min_norm_least")]
    passes = [0]
    real = search._Search._pass

    def counted(self, *a, **k):
        passes[0] += 1
        return real(self, *a, **k)
    monkeypatch.setattr(search._Search, "_pass", counted)
    got = {}
    for merged in (True, False):
        if not merged:
            monkeypatch.setattr(search._Search, "prefetch", lambda self, lists: None)
        passes[0] = 0
        got[merged] = [_record(law, op, 3) for op, law in cases]
        got[merged, "passes"] = passes[0]
    assert got[True] == got[False]
    assert [r["status"] for r in got[True]] == ["failed", "passed", "passed", "passed"]
    assert "coordinate" in got[True][0]["counterexample"]["found_by"]         # met by the step designs
    assert got[True, "passes"] < got[False, "passes"], (got[True, "passes"], got[False, "passes"])
