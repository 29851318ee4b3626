"""Thin domains judged at the subject's precision (issue 42, item 5): the indicator of an affine set (or of the
simplex's hyperplane) can only accept points within the round-off of the equality, and a float32 projection from
``|x| = 1e6`` leaves the set by ``~eps·|x| ≈ 0.1``, far beyond that band and missed by every probe along a few
directions.  The subject's own resolvent proposes the nearest point (``J_μ p``, whose round-off is ``eps·|p|``),
which the value function then accepts within the reach ``16·eps·(1 + |x|)`` of ``p``: no sample.  A projection
off by 50 ulps (of ``|x|``) stays failed: what it proposes is as far off, or beyond the reach."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.checks import operator_laws, prox_laws  # noqa: F401 - the laws join the registry on import
from verimono.checks.engine.search import run_law

A, B = np.array([1.0, -2.0, 0.5], np.float32), np.float32(0.3)
EPS32 = float(np.finfo(np.float32).eps)


def plane32(x, lam=None, shift_ulps=0.0):
    """The projection onto the plane ``{a·x = b}`` computed in float32; ``shift_ulps``: moved that many float32
    ulps of ``1 + |x|∞`` along the normal (a broken control)."""
    x = np.asarray(x, np.float32)
    p = x - (x @ A - B) / (A @ A) * A
    if shift_ulps:
        p = p + np.float32(shift_ulps * EPS32 * (1 + float(np.abs(x).max()))) * A / np.linalg.norm(A)
    return p


def on_plane(x):
    """The plane's indicator as a float32 user writes it: the equality within 4 units of its round-off."""
    x = np.asarray(x, np.float32)
    return 0.0 if abs(float(x @ A - B)) <= 4 * EPS32 * (1 + float(np.abs(A) @ np.abs(x)) + abs(float(B))) \
        else np.inf


def _far(radius):
    """``x`` at ``|x| = radius`` mostly along the normal, so that ``|J x| ≈ 1`` is far smaller than ``|x|``."""
    return radius * A.astype(float) / np.linalg.norm(A) + np.array([0.3, 0.2, -0.1])


def _sample(x):
    return {"x1": x.tolist(), "x2": (0.5 * x).tolist(), "lam": 0.5, "mu": 0.25, "nu": 1.0, "t": 0.0}


@pytest.mark.parametrize("radius", [1e3, 1e6])
@pytest.mark.parametrize("law", ["prox_inequality", "moreau_envelope", "yosida_in_graph"])
def test_a_correct_float32_projection_onto_a_plane_from_far_is_no_sample(law, radius):
    op = vm.operator_from_prox(plane32, value=on_plane, shape=3, dtype="float32", name="plane32")
    x = _far(radius)
    assert on_plane(plane32(x)) == np.inf, "the float32 projection leaves the band (else the test tests nothing)"
    rec = run_law(law, op, sample=_sample(x))
    assert rec.status in ("skipped", "passed") and rec.details["dtype"] == "float32", rec
    assert law == "yosida_in_graph" or "only by round-off" in rec.message, rec


@pytest.mark.parametrize("radius", [1e3, 1e6])
@pytest.mark.parametrize("law", ["prox_inequality", "moreau_envelope", "yosida_in_graph"])
def test_a_float32_projection_off_by_50_ulps_still_fails(law, radius):
    op = vm.operator_from_prox(lambda x, lam: plane32(x, shift_ulps=50.0), value=on_plane, shape=3, dtype="float32",
                               name="plane32 off by 50 ulps")
    rec = run_law(law, op, sample=_sample(_far(radius)))
    assert rec.status == "failed", rec


def test_the_proposal_is_judged_by_the_value_function_only():
    """A projection onto a parallel plane (``b`` off by 1e-3) proposes points of its own plane, which the value
    function rejects: failed at a unit-sized point, where round-off is 1e-7."""
    op = vm.operator_from_prox(lambda x, lam: plane32(x) + np.float32(1e-3) * A / (A @ A), value=on_plane, shape=3,
                               dtype="float32", name="parallel plane")
    rec = run_law("prox_inequality", op, sample=_sample(np.array([1.0, 0.5, -0.2])))
    assert rec.status == "failed", rec
