"""Proxes nobody here wrote — ProxTorch's and torch's own ops, jaxopt's, PyProximal's — at float32 and float64,
at n = 3, 64 (the scale phase's largest, ``NUMPY_DIM``) and 10^4 (hypothesis's search alone, the laws' block
paths), through ``check_operator(..., profile="ci")`` as a user calls it (docs/prox-libraries.md): no failed
and no undecided record at seeds 0–2, every skip naming its reason; and the same libraries with the weight
forgotten are still failed at 64 and 10^4 coordinates.

A ``g`` computed in float32 judges its value laws at float32: ProxTorch's ``L1(alpha)(x)`` adds its smooth part
``torch.Tensor([0])`` (float32, shape (1,)) to the float64 norm, and torch's promotion makes the sum float32, so
a float64 ProxTorch ``L1`` has records at both precisions (``details["dtype"]``) — the coarser decides, as stated
in verimono/core/tolerances.py.

Tier: ``sweep`` (90 batteries of 2–8 s CPU each); skipped, counted, without a library."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm

SIZES = (3, 64, 10_000)
VALUE_LAWS = {"prox_inequality", "prox_optimal", "moreau_envelope", "yosida_in_graph"}


def _torch(prec, n, wrong=False):
    torch = pytest.importorskip("torch", reason="PyTorch is not installed (pip install 'verimono[arrays]')")
    pytest.importorskip("proxtorch", reason="ProxTorch is not installed (pip install 'verimono[arrays]')")
    from proxtorch.operators import L1

    dt = getattr(torch, prec)
    l1 = L1(alpha=1.0 if wrong else 2.0)                          # wrong: L1(1)'s prox given L1(2)'s value

    def l2norm(x, lam):                                             # prox of 1.5|x|_2: block soft thresholding
        return x * torch.clamp(1 - 1.5 * lam / torch.clamp(torch.linalg.norm(x), min=torch.finfo(x.dtype).tiny),
                               min=0.0)
    return [vm.operator_from_prox(l1.prox, value=lambda x: L1(alpha=2.0)(x)[0], shape=n, array="torch", dtype=dt,
                                  name=f"proxtorch L1 {prec}"),
            vm.operator_from_prox(l2norm, value=lambda x: (1.0 if wrong else 1.5) * torch.linalg.norm(x), shape=n,
                                  array="torch", dtype=dt, name=f"torch l2 norm {prec}")]


def _jax(prec, n, wrong=False):
    jax = pytest.importorskip("jax", reason="JAX is not installed (pip install 'verimono[arrays]')")
    pytest.importorskip("jaxopt", reason="jaxopt is not installed (pip install 'verimono[arrays]')")
    import jax.numpy as jnp
    from jaxopt.prox import prox_group_lasso, prox_lasso

    w = 1.0 if wrong else 2.0                                       # wrong: the prox of |x|_1 given g = 2|x|_1
    return [vm.operator_from_prox(jax.jit(lambda x, scaling: prox_lasso(x, w, scaling)), step="scaling",
                                  value=jax.jit(lambda x: 2.0 * jnp.sum(jnp.abs(x))), shape=n,
                                  name=f"jaxopt lasso {prec}"),
            vm.operator_from_prox(jax.jit(lambda x, scaling: prox_group_lasso(x, 0.75 * w, scaling)),
                                  step="scaling", value=jax.jit(lambda x: 1.5 * jnp.linalg.norm(x)), shape=n,
                                  name=f"jaxopt group lasso {prec}")]


def _pyproximal(prec, n, wrong=False):
    pyproximal = pytest.importorskip("pyproximal", reason="PyProximal is not installed (pip install pyproximal)")
    dt = np.dtype(prec)
    f, e = pyproximal.L1(sigma=2.0), pyproximal.Euclidean(sigma=1.5)
    k = 2.0 if wrong else 1.0                                       # wrong: sigma applied twice

    def cast(prox):
        return lambda x, lam: prox(np.asarray(x, dt), k * lam).astype(dt)
    return [vm.operator_from_prox(cast(f.prox), value=f, shape=n, dtype=dt, name=f"pyproximal L1 {prec}"),
            vm.operator_from_prox(cast(e.prox), value=e, shape=n, dtype=dt, name=f"pyproximal Euclidean {prec}")]


LIBS = {"torch": _torch, "jax": _jax, "pyproximal": _pyproximal}


def _x64(lib, prec):
    if lib == "jax" and prec == "float64":
        import jax
        return jax.enable_x64(True)
    import contextlib
    return contextlib.nullcontext()


@pytest.mark.sweep
@pytest.mark.parametrize("n", SIZES)
@pytest.mark.parametrize("prec", ("float32", "float64"))
@pytest.mark.parametrize("lib", sorted(LIBS))
def test_correct_foreign_proxes_pass_at_seeds_0_to_2(lib, prec, n):
    with _x64(lib, prec):
        for op in LIBS[lib](prec, n):
            for seed in range(3):
                rep = vm.check_operator(op, profile="ci", seed=seed)
                bad = [f"{op.name}, n = {n}, seed {seed}: {r}" for r in rep if r.status in ("failed", "undecided")]
                assert not bad, "\n".join(bad)
                assert all(r.message for r in rep if r.status == "skipped")
                passed = {r.check for r in rep if r.status == "passed"}
                assert VALUE_LAWS <= passed, (op.name, n, seed, VALUE_LAWS - passed)
                assert prec in {r.details["dtype"] for r in rep if r.status == "passed"}


@pytest.mark.sweep
@pytest.mark.parametrize("n", SIZES[1:])
@pytest.mark.parametrize("lib", sorted(LIBS))
def test_a_forgotten_weight_is_still_caught_at_large_n(lib, n):
    prec = "float32" if lib != "pyproximal" else "float64"
    with _x64(lib, prec):
        for op in LIBS[lib](prec, n, wrong=True):
            failed = {r.check for r in vm.check_operator(op, profile="ci", seed=0).failures}
            assert failed & VALUE_LAWS, (op.name, n, failed)
