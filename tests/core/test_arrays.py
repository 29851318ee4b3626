"""Array libraries at verimono's boundary (issue 23, item 2): conversions that keep the precision, the
step passed as the prox takes it, and the batched hook — a prox mapping ``(B, n)`` is called once per batch
of samples, its batched values compared with single calls."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.core.arrays import as_float64, library_of, precision_of, to_numpy
from verimono.checks import check_operator, run_law
from verimono.core.tolerances import judged_precision


def _soft(X, lams):
    return np.sign(X) * np.maximum(np.abs(X) - np.asarray(lams).reshape(-1, *([1] * (np.ndim(X) - 1))), 0.0)


class Counting:
    """A vectorised soft-thresholding prox ``(B, n), (B,) -> (B, n)`` that counts its calls and rows."""

    def __init__(self, wrong_step=False):
        self.calls, self.rows, self.wrong_step, self.sizes = 0, 0, wrong_step, []

    def __call__(self, X, lams):
        self.calls += 1
        self.rows += X.shape[0]
        self.sizes.append(X.shape[0])
        if self.wrong_step:            # a vectorisation bug: every row gets the first row's step
            lams = np.full_like(lams, lams[0])
        return _soft(X, lams)


def test_conversions_keep_and_report_the_precision():
    x32 = np.array([1.0, 2.0], np.float32)
    assert library_of(x32) == "numpy" and precision_of(x32) == "float32" and precision_of(1.0) == "float64"
    assert to_numpy(x32).dtype == np.float32
    with judged_precision() as p:
        y = as_float64(x32)
    assert y.dtype == np.float64 and p.name == "float32"
    with pytest.raises(TypeError):
        as_float64(np.array([1j]))


def test_step_keyword_and_projection_without_step():
    op = vm.operator_from_prox(lambda x, scaling: _soft(x[None], [scaling])[0], step="scaling", shape=2)
    assert np.allclose(op.resolvent(np.array([2.0, -0.5]), 1.0), [1.0, 0.0])
    box = vm.operator_from_prox(lambda x: np.clip(x, -1.0, 1.0), step=False, shape=2, name="box")
    assert np.allclose(box.resolvent(np.array([3.0, 0.5]), 7.0), [1.0, 0.5])
    with pytest.raises(vm.InvalidProblem):
        vm.operator_from_prox(lambda x: x, step="not a name", shape=2)


def test_a_batched_prox_is_called_once_per_batch(monkeypatch):
    from verimono.checks.engine import search as L
    from verimono.checks.engine.batches import batch_sizes

    monkeypatch.setattr(L, "_coordinates", lambda *a, **k: None)     # the phases that know their samples only
    # and not the scale phase: above |x| = 1e6 it judges finiteness only (inconclusive samples) where the evaluator
    # runs, as for a declared batch, while the law's vectorised form, used for a one-point subject, counts the rows
    # it accepts at their ratio: both pass, their counts differ by design (verimono.checks.engine.scales)
    monkeypatch.setattr(L, "_scales", lambda *a, **k: {})
    one = Counting()
    batched = vm.operator_from_prox(one, batched=True, shape=2, value=lambda x: float(np.abs(x).sum()), name="batched")
    rec = run_law("resolvent_nonexpansive", batched, seed=0, examples=20)
    assert rec.status == "passed", str(rec)
    per_point = Counting()
    single = vm.operator_from_prox(lambda x, lam: per_point(x[None], np.array([lam]))[0], shape=2, name="single")
    assert run_law("resolvent_nonexpansive", single, seed=0, examples=20).worst == rec.worst   # same values
    assert one.calls < per_point.calls / 2, (one.calls, per_point.calls)
    assert one.rows > 20                     # the draws and the sweep came in batches
    assert {1, 2, 3, 5, 7} <= set(one.sizes) and max(one.sizes) > 8     # of every size, odd ones included
    assert len(batch_sizes(120, 2)) <= 10
    monkeypatch.undo()
    assert check_operator(batched, seed=0).ok


def test_a_batch_that_disagrees_with_single_calls_is_caught():
    bad = vm.operator_from_prox(Counting(wrong_step=True), batched=True, shape=2, name="wrong step in a batch")
    rec = run_law("resolvent_single_valued", bad, seed=0, examples=20)
    assert rec.status == "failed", str(rec)


def test_a_batched_resolvent_of_a_user_operator():
    op = vm.operator_from_resolvent(lambda X, lams, ts: _soft(X, lams), 2, batched=True, name="batched resolvent")
    X = np.array([[2.0, -3.0], [0.5, 0.0], [1.0, 1.0]])
    assert np.allclose(op.resolvent_batch(X, np.array([1.0, 1.0, 0.5]), np.zeros(3)), [[1, -2], [0, 0], [0.5, 0.5]])
    assert run_law("resolvent_firmly_nonexpansive", op, seed=0, examples=10).status == "passed"


def test_jax_arrays_without_conversion():
    jax = pytest.importorskip("jax", reason="JAX is not installed (pip install 'verimono[arrays]')")
    import jax.numpy as jnp

    seen = []

    def prox(x, lam):
        seen.append(type(x).__module__.split(".")[0])
        return jnp.sign(x) * jnp.maximum(jnp.abs(x) - lam, 0.0)
    op = vm.operator_from_prox(prox, shape=2, name="jax soft")
    rep = check_operator(op, seed=0, examples=5)
    assert rep.ok and op.array == "jax" and seen[0] == "numpy" and set(seen[1:]) == {"jaxlib"}
    assert {r.details["dtype"] for r in rep if r.status == "passed"} == {"float32"}
    # a stepper on a JAX operator
    traj = vm.solve(vm.Problem(op, np.array([1.0, -2.0]), 1.0), vm.uniform_grid(1.0, steps=4))
    assert traj.precision == "float32" and np.allclose(traj.x[-1], [0.0, -1.0], atol=1e-6)
    assert jax is not None


def test_array_api_namespace_declared():
    xp = pytest.importorskip("array_api_strict", reason="array-api-strict is not installed")
    op = vm.operator_from_prox(lambda x, lam: x / (1.0 + lam), shape=2, array=xp, name="array-api scaled")
    assert check_operator(op, seed=0, examples=5).ok
