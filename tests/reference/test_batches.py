"""A batch of initial states is a batch of problems: ``solve`` on ``x0`` of shape ``(B, n)`` equals ``B`` separate
solves, for every reference of the catalog and every manufactured example — so each field ``f``, input and
operator of theirs is written for batches of states (a field reversing ``x[::-1]`` reversed the batch axis of a
``(B, n)`` array: a batched solve differed from separate ones by 0.44, silently)."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.reference import catalog

#: the catalog by name, and the manufactured examples by their session fixture (tests/reference/conftest.py)
PROBLEMS = {**{p.name: p for p in catalog()}, "manufactured moving box": "box", "manufactured ∂(c(t)|x|)": "norm",
            "manufactured passive LCS": "lcs"}


def _starts(p, count):
    """``count`` distinct initial points in ``cl dom F(0)`` near ``x0`` (projected where the domain is closed;
    the catching-up problems keep their jump: their starts are moved the same way, off the domain)."""
    rng = np.random.default_rng(len(p.name))
    x0 = np.asarray(p.x0, float)
    out = [x0]
    for _ in range(count - 1):
        z = x0 + 0.3 * (1.0 + np.abs(x0)) * rng.uniform(-1.0, 1.0, x0.shape)
        if not p.initial_jump:
            try:
                z = np.asarray(p.operator.project_domain(z, 0.0), float)
            except NotImplementedError:
                z = x0 * (1.0 + 0.1 * rng.uniform())
        out.append(z)
    return np.stack(out)


@pytest.mark.parametrize("name", sorted(PROBLEMS))
@pytest.mark.parametrize("batch", [2, 3])
def test_a_batched_solve_is_the_separate_solves(name, batch, request):
    p = PROBLEMS[name]
    p = request.getfixturevalue(p) if isinstance(p, str) else p
    X0 = _starts(p, batch)
    t = vm.uniform_grid(p.T, steps=37)
    together = vm.solve(p.replace(x0=X0), t).x
    assert together.shape == (len(t), batch) + p.x0.shape
    for i in range(batch):
        alone = vm.solve(p.replace(x0=X0[i]), t).x
        scale = 1.0 + float(np.max(np.abs(alone)))
        assert np.max(np.abs(together[:, i] - alone)) <= 1e-12 * scale, (name, i)
