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
