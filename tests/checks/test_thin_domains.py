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


# -- a boundary point that is its own correctly rounded projection (float64) ---------------------------

A64, B64 = A.astype(float), 0.0       # through the origin: ±p is tangent to its boundary


def half64(x, lam=None, shift_ulps=0.0):
    """The projection onto ``{a·x ≤ b}`` in float64; ``shift_ulps``: moved outward that many ulps of ``1 + |x|∞``."""
    x = np.asarray(x, float)
    p = x - max(float(x @ A64) - B64, 0.0) / (A64 @ A64) * A64
    return p + shift_ulps * np.finfo(float).eps * (1 + float(np.abs(x).max())) * A64 / np.linalg.norm(A64)


def below(x):
    return 0.0 if float(np.asarray(x, float) @ A64) <= B64 else np.inf


def _own_projection_outside():
    """A point of norm ~30 on the boundary whose projection moves it by less than an ulp (``p = x``) although
    ``a·x`` rounds above ``b``: the correctly rounded projection, rejected by the strict indicator; the normal
    ``x − p`` is 0 and ``±p`` is tangent (the PyTorch float64 half-space's battery met such a point at seed 1, at
    ``|x| = 36.6`` with ``a·x − b = 9.4e-16``)."""
    rng = np.random.default_rng(7)
    for _ in range(200):
        y = 20.0 * rng.standard_normal(3)
        x = y - (y @ A64 - B64) / (A64 @ A64) * A64
        if below(x) == np.inf and np.array_equal(half64(x), x):
            return x
    raise AssertionError("no boundary point whose projection is itself and outside by round-off")


def test_a_float64_boundary_point_that_is_its_own_projection_is_no_sample():
    x = _own_projection_outside()
    op = vm.operator_from_prox(half64, value=below, shape=3, name="half-space64")
    for law in ("prox_inequality", "moreau_envelope", "yosida_in_graph"):
        rec = run_law(law, op, sample=_sample(x))
        assert rec.status in ("skipped", "passed") and rec.details["dtype"] == "float64", rec


def test_a_float64_half_space_projection_off_by_50_ulps_still_fails():
    x = _own_projection_outside()
    op = vm.operator_from_prox(lambda x, lam: half64(x, shift_ulps=50.0), value=below, shape=3, name="off by 50")
    for law in ("prox_inequality", "moreau_envelope", "yosida_in_graph"):
        assert run_law(law, op, sample=_sample(x)).status == "failed", law
