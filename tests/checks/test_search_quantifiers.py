"""The quantifiers of the operator laws searched as coordinates: the direction of ``x2 − x1`` over the whole
sphere (:mod:`verimono.checks.engine.directions`) and the step ``λ`` over every decade the precision represents
(:func:`verimono.core.tolerances.current_step_range`).  Each plant is seen failing beside a lawful control
within a few percent of it, and each plant passes when its coordinate is not searched (the coordinate, not
luck, finds it)."""

from __future__ import annotations

import numpy as np
import pytest

from verimono import operator_from_resolvent
from verimono.checks import operator_laws  # noqa: F401 - the laws register on import
from verimono.checks.engine import coordinates
from verimono.checks.engine.search import run_law
from verimono.checks.engine.supremum import budgets
from verimono.execution.config import chosen
from verimono.core.tolerances import STEP_RANGE_BY_PRECISION
from verimono.records.results import FAILED, PASSED


def linear(a: np.ndarray, name: str, step=lambda lam: lam):
    """``F = A`` linear, given by its resolvent ``(I + step(λ)A)^{-1}`` (``step(λ) = λ``: the right one), with
    its minimal section ``Ax`` and membership ``y = Ax``."""
    n = a.shape[0]

    def contains(x, y, t, tol):
        return bool(np.linalg.norm(np.asarray(y) - a @ np.asarray(x)) <= tol)

    return operator_from_resolvent(lambda x, lam, t: np.linalg.solve(np.eye(n) + step(lam) * a, np.asarray(x, float)),
                                   n, name=name, min_norm=lambda x, t: a @ np.asarray(x, float), contains=contains)


def near_plane(n: int, mu: float, seed: int) -> np.ndarray:
    """A symmetric ``A`` with eigenvalue ``mu`` on a random 2-plane of ``R^n`` and 1 elsewhere: for ``mu < 0``
    ``⟨Ad, d⟩ < 0`` only for directions ``d`` within ``atan(sqrt(|mu|))`` of that plane (10° for ``mu = −0.03``),
    a fraction ``~10^-8`` of the sphere in ``R^12``."""
    q, _ = np.linalg.qr(np.random.default_rng(seed).standard_normal((n, n)))
    return q @ np.diag(np.r_[mu, mu, np.ones(n - 2)]) @ q.T


@pytest.mark.parametrize("n,plane", [(12, 1), (40, 2), (20, 3)])
@pytest.mark.parametrize("law", ["monotone", "yosida_monotone"])
def test_monotonicity_lost_only_near_one_plane_is_found_over_the_sphere(law, n, plane, monkeypatch):
    with chosen("dev"):     # the dev profile's effort (ci's larger one meets one plane without the direction)
        _plane_case(law, n, plane, monkeypatch)


def _plane_case(law, n, plane, monkeypatch):
    plant = linear(near_plane(n, -0.02, plane), "non-monotone near a plane")
    control = linear(near_plane(n, 0.0, plane), "monotone (a 2-dimensional kernel)")
    rec = run_law(law, plant, seed=0)
    assert rec.status == FAILED, str(rec)
    assert run_law(law, plant, sample=rec.counterexample).status == FAILED      # it replays
    good = run_law(law, control, seed=0)
    assert good.status == PASSED, str(good)
    found = {c["coordinate"]: c for c in good.details["searched"]["coordinates"]}
    assert found["direction"]["read"] and found["direction"]["sphere"] == f"S^{n - 1}"
    monkeypatch.setattr(coordinates, "COORDINATES", tuple(c for c in coordinates.COORDINATES if c != "direction"))
    assert run_law(law, plant, seed=0).status == PASSED      # without the direction: not found


BIG = np.diag([1e9, 3e9])


@pytest.mark.parametrize("where,a", [
    (lambda lam: lam < 1e-7, BIG),                                  # wrong only below 10^-7
    (lambda lam: 1e-40 < lam < 1e-30, BIG * 1e26),                 # only in ten decades far below
    (lambda lam: lam > 40.0, np.diag([1.0, 3.0])),                  # only above 40
])
def test_a_resolvent_wrong_only_at_far_decades_of_lambda_fails(where, a, monkeypatch):
    # the step 1.05λ where `where(λ)`: Y_λx = 1.05 A J_λx is not in F(J_λx) = {A J_λx} (Prop. v)
    plant = linear(a, "step 1.05λ far out", step=lambda lam: 1.05 * lam if where(lam) else lam)
    control = linear(a, "step 1.01λ nowhere", step=lambda lam: lam)
    with budgets(coordinate=27):         # the ci profile's: every third decade (dev's sixth misses 40 < λ < 10^4)
        rec = run_law("yosida_in_graph", plant, seed=0)
        good = run_law("yosida_in_graph", control, seed=0)
    assert rec.status == FAILED and where(rec.counterexample["lam"]), str(rec)
    assert good.status == PASSED, str(good)
    found = {c["coordinate"]: c for c in good.details["searched"]["coordinates"]}
    # every third decade at least (ci's; a law with a vectorised form, as yosida_in_graph now, is searched denser)
    assert found["lam decades"]["stride"] <= 3 and found["lam decades"]["range"] == list(STEP_RANGE_BY_PRECISION["float64"])
    monkeypatch.setattr(coordinates, "current_step_range", lambda: (1e-4, 10.0))     # today's range alone
    with budgets(coordinate=27):
        assert run_law("yosida_in_graph", plant, seed=0).status == PASSED


def test_the_step_range_spans_the_decades_each_precision_represents():
    # from sqrt(tiny) up to RTOL/eps (the relative error of a backward-stable solve of I + λA stays within RTOL)
    lo, hi = STEP_RANGE_BY_PRECISION["float64"]
    assert lo == 1e-153 and hi == 1e7
    lo32, hi32 = STEP_RANGE_BY_PRECISION["float32"]
    assert lo32 == 1e-18 and hi32 == 1e3
    assert all(lo <= 1e-4 and hi >= 10.0 for lo, hi in STEP_RANGE_BY_PRECISION.values())
