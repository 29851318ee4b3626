"""The direction search never hands the subject a point it made non-finite itself
(:func:`verimono.checks.engine.directions.sketch_directions`): a correct operator was failed for the NaN it returned
at ``x2 = x1 + r·NaN``."""

from __future__ import annotations

import numpy as np

import verimono.strategies as vs
from verimono.checks import check_yosida_monotone
from verimono.checks.engine.directions import sketch_directions
from verimono.checks.engine.samples import Sample
from verimono.execution.config import using


class _Steep:
    """A resolvent whose difference map is finite (entries ~1e200) while its squares overflow."""

    def resolvent(self, x, lam=1.0, t=0.0):
        return 1e200 * np.asarray(x, dtype=float)


def test_the_sketch_skips_forms_that_overflow():
    s = Sample(x1=np.array([0.3, -0.2, 0.1]), x2=np.array([0.3, -0.2, 0.1]), lam=1.0, mu=1.0, nu=1.0, t=0.0)
    dirs = sketch_directions(_Steep(), s, 1e-2, np.random.default_rng(0))
    # sym M is finite (its two eigenvectors, both extremes), the squared forms overflow: no direction from them
    assert len(dirs) == 2 and all(np.isfinite(d).all() for d in dirs)


def test_logbarrier_at_the_seed_that_found_the_nan_passes_yosida_monotone():
    """The dev profile's draw, seed 2853691650, that failed the correct ∂(-log) barrier of R^2 (worst inf:
    x2 = [0, nan] from the sketch's overflowed forms)."""
    op = next(o for o in vs.catalog(2) if "LogBarrier" in str(o))
    with using(None, profile="dev"):
        rec = check_yosida_monotone(op, seed=2853691650, examples=5, horizon=1.0)
    assert rec.status == "passed", rec
