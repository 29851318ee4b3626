"""Messages that point at the cause (issue 33, item 5): a torch prox wrapped without ``array="torch"``, and a
stepper that refuses fine grids, which was reported ok (its order record skipped, its stage passed)."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.reference import get


def _root_cause(op) -> str:
    rep = vm.check_operator(op, seed=0, examples=5)
    (rec,) = [r for r in rep.results if r.check == "resolvent_single_valued"]
    assert rec.status == "failed"
    return rec.message


def test_a_torch_prox_wrapped_without_array_torch_is_told_the_option():
    torch = pytest.importorskip("torch")

    def soft(x, lam):
        return torch.sign(x) * torch.clamp(torch.abs(x) - lam, min=0.0)

    msg = _root_cause(vm.operator_from_prox(soft, shape=3, name="torch l1"))
    assert "must be Tensor" in msg and 'array="torch"' in msg
    # declared, it runs: no root cause at all
    rep = vm.check_operator(vm.operator_from_prox(soft, shape=3, name="torch l1", array="torch"), seed=0, examples=5)
    assert not any(r.check == "resolvent_single_valued" and r.status == "failed" for r in rep.results)


@pytest.mark.parametrize("error, lib", [
    (TypeError("sign(): argument 'input' (position 1) must be Tensor, not numpy.ndarray"), "torch"),
    (AttributeError("'numpy.ndarray' object has no attribute 'clamp'; expected a torch.Tensor"), "torch"),
    (TypeError("Argument to jax.numpy.sign must be a jax Array'"), "jax"),
])
def test_the_hint_names_the_library_the_error_names(error, lib):
    """Without torch installed too: a function standing for a tensor library's, raising what it raises when
    given NumPy arrays."""
    def prox(x, lam):
        raise error

    msg = _root_cause(vm.operator_from_prox(prox, shape=2, name="stand-in"))
    assert f'array="{lib}"' in msg


def test_no_hint_for_an_error_of_numpys_own():
    def prox(x, lam):
        raise ValueError("operands could not be broadcast together")

    assert "array=" not in _root_cause(vm.operator_from_prox(prox, shape=2, name="broken"))


@pytest.mark.parametrize("limit", [100, 300])
def test_a_stepper_that_refuses_fine_grids_fails_its_order(limit):
    problem = get("moving box")

    def coarse_only(p, t):
        if len(t) > limit:
            raise NotImplementedError("fine grids are not supported yet")
        return vm.solve(p, t)

    (rec,) = vm.check_stepper(coarse_only, [problem], laws=False).results
    assert rec.status == "failed" and "refuses fine grids" in rec.message and "not supported yet" in rec.message


def test_a_stepper_that_refuses_every_grid_is_not_available_as_before():
    def never(p, t):
        raise NotImplementedError("this problem's operator is not supported")

    (rec,) = vm.check_stepper(never, [get("moving box")], laws=False).results
    assert rec.status == "skipped"


def test_the_correct_stepper_still_passes_its_order():
    (rec,) = vm.check_stepper(vm.solve, [get("moving box")], laws=False).results
    assert rec.status == "passed" and np.isfinite(rec.worst)
