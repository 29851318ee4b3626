"""The projections of Hoffman's law (:class:`verimono.checks.hoffman.ActiveSetProjector`): a cached active set
answers only on its KKT certificate, and then with the KKT-verified QP's projection (``Polyhedron.project``)."""

from __future__ import annotations

import numpy as np
import pytest

from verimono.checks.hoffman import ActiveSetProjector, hoffman_polyhedra
from verimono.core.sets import Polyhedron


def _projectors(seed):
    for name, Q, R, q in hoffman_polyhedra(seed):
        P = Polyhedron(Q, q, R, None if R is None else np.zeros(R.shape[0]))
        yield name, P, ActiveSetProjector(P, Q, q, R)


@pytest.mark.parametrize("seed", [0, 1])
def test_cached_active_sets_give_the_qp_projection(seed):
    """Points around every polyhedron of the law (the same directions at growing radii, so that active sets
    repeat): each projection equals the QP's to 1e-9 of the point's size, and most come from the cache —
    faces' equality-constrained solves and vertices' cones (more active rows than coordinates) both."""
    rng = np.random.default_rng(seed)
    hits = solves = vertices = 0
    for name, P, proj in _projectors(seed):
        n = P.dim
        u = rng.standard_normal((6, n))
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        for r in (0.5, 2.0, 10.0, 1e3, 3e3):
            for x in r * u:
                z = proj.project(x)
                assert np.linalg.norm(z - P.project(x)) <= 1e-9 * (1.0 + np.linalg.norm(x)), (name, x)
        hits, solves = hits + proj.hits, solves + proj.solves
        vertices += sum(s[-1] is not None for s in proj.sets)
    assert hits > 2 * solves and vertices > 0, (hits, solves, vertices)


def test_a_wrong_active_set_is_refused_by_its_certificate():
    """Planted: the triangle's projector is taught the active set of its vertex (0, 0) and of its hypotenuse;
    a point whose projection lies on the face ζ_2 = 0 is refused by both (a negative multiplier, or ``x − v``
    outside the vertex's cone) and goes to the QP, whose answer is returned: (0.5, 0)."""
    name, P, proj = next(_projectors(0))
    assert name == "triangle"
    proj._learn(np.array([0.0, 0.0]))           # the vertex: rows ζ_1 ≥ 0 and ζ_2 ≥ 0 active
    proj._learn(np.array([0.5, 0.5]))           # the hypotenuse ζ_1 + ζ_2 = 1
    assert len(proj.sets) == 2 and proj.hits == 0
    z = proj.project(np.array([0.5, -3.0]))
    assert proj.solves == 1 and proj.hits == 0
    assert z == pytest.approx([0.5, 0.0], abs=1e-12)
    # the vertex's cone does hold a point beyond it, and the cached set then answers without a QP
    z = proj.project(np.array([-1.0, -2.0]))
    assert proj.hits == 1 and proj.solves == 1 and z == pytest.approx([0.0, 0.0], abs=1e-12)


def test_norm_is_numpys_norm_bit_for_bit():
    """``hoffman._norm`` (the law's distances and residuals, branch units9) is ``float(np.linalg.norm(v))`` bit for
    bit on real vectors of every length and scale, strided ones too (their own path: ``w·w`` of the raveled copy)."""
    from verimono.checks.hoffman import _norm

    rng = np.random.default_rng(3)
    for k in range(400):
        n = int(rng.integers(0, 300))
        v = rng.standard_normal(2 * n) * 10.0 ** rng.uniform(-150, 150)
        for w in (v[:n], v[::2], -v[1::2]):
            assert _norm(w).hex() == float(np.linalg.norm(w)).hex(), (k, n)
