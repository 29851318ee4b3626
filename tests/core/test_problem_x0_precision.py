"""``Problem(...)`` judges ``x0 ∈ cl dom F(0,·)`` at the precision the operator computes in (probe8).

A user's float32 box given by its projection (``operator_from_resolvent``, n = 10^4) and ``x0`` clipped into it
in float64: the projection rounds ``x0`` to float32, 3e-8 away, and the wrapped operator hands back float64, so
the check saw float64 and refused ``x0`` as outside the domain (``OutsideDomain``, the advice to state a
data_scale) before any law ran.
"""

import numpy as np
import pytest

import verimono as vm

N = 10_000


def _box(dtype):
    def proj(x, lam, t):
        return np.clip(np.asarray(x, dtype=dtype), dtype(-1.0), dtype(1.0))
    return vm.operator_from_resolvent(proj, N, name=f"box {np.dtype(dtype).name}",
                                      project_domain=lambda x, t: proj(x, 1.0, t))


def _x0():
    return np.clip(np.random.default_rng(0).standard_normal(N), -1.0, 1.0)


def test_a_float32_projection_of_x0_in_the_domain_is_its_rounding_not_a_distance():
    x0 = _x0()
    moved = np.max(np.abs(x0.astype(np.float32).astype(float) - x0))
    assert 1e-8 < moved < 1e-7                     # the premise: float32 rounding, beyond float64's tolerance
    p = vm.Problem(_box(np.float32), x0=x0, T=1.0)
    assert p.dim == N


def test_x0_outside_is_still_refused_and_float64_is_judged_at_float64():
    x0 = _x0()
    with pytest.raises(vm.OutsideDomain):
        vm.Problem(_box(np.float32), x0=x0 * 1.001, T=1.0)       # 1e-3 outside: no rounding of float32
    off = x0.copy()
    off[0] = 1.0 + 3e-8                                           # float64: 3e-8 outside is outside
    with pytest.raises(vm.OutsideDomain):
        vm.Problem(_box(np.float64), x0=off, T=1.0)
    vm.Problem(_box(np.float64), x0=x0, T=1.0)
