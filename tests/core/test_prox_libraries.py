"""The recipes of docs/prox-libraries.md, exercised: one-line wrappers for PyProximal, proxop and prox-tv
pass the whole battery (value laws included), and a weight put on the wrong side of the convention is caught.
A library that is not installed skips its tests with the reason (counted by pytest -rs)."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm


def _ok(op):
    rep = vm.check_operator(op, seed=0)
    assert rep.ok, "\n".join(map(str, rep.failures))
    assert {r.check for r in rep if r.status == "passed"} >= {"prox_inequality", "prox_optimal", "moreau_envelope",
                                                            "yosida_in_graph"}
    return rep


# -- PyProximal: f.prox(x, tau) = prox_{tau·f}; weights (sigma) are inside f; f(x) is the value ------------------
def test_pyproximal_recipes():
    pyproximal = pytest.importorskip("pyproximal", reason="PyProximal is not installed (pip install pyproximal)")
    f = pyproximal.L1(sigma=2.0)
    _ok(vm.operator_from_prox(f.prox, value=f, shape=3, name="pyproximal.L1(sigma=2)"))
    N = pyproximal.Nuclear((2, 3))     # acts on flattened matrices: the adapter passes (2, 3), so ravel
    _ok(vm.operator_from_prox(lambda X, lam: N.prox(X.ravel(), lam).reshape(X.shape),
                              value=lambda X: N(X.ravel()), shape=(2, 3), name="pyproximal.Nuclear"))
    L21 = pyproximal.L21(ndim=2)
    _ok(vm.operator_from_prox(L21.prox, value=L21, shape=4, name="pyproximal.L21"))
    # the weight applied twice (sigma inside f AND in the step): the exact prox of 4|x|_1, not of 2|x|_1
    twice = vm.operator_from_prox(lambda x, lam: f.prox(x, 2.0 * lam), value=f, shape=3, name="sigma twice")
    assert "prox_inequality" in {r.check for r in vm.check_operator(twice, seed=0).failures}


# -- proxop: f.prox(x, gamma) = prox_{gamma·f}; parameters (Huber's w) inside f; indicators take no gamma ---------
def test_proxop_recipes():
    proxop = pytest.importorskip("proxop", reason="proxop is not installed (pip install proxop)")
    for f, n in ((proxop.L1Norm(), 3), (proxop.L2Norm(), 3), (proxop.Huber(w=2.0), 2)):
        _ok(vm.operator_from_prox(lambda x, lam, f=f: f.prox(x, gamma=lam), value=f, shape=n,
                                  name=f"proxop.{type(f).__name__}"))
    box = proxop.BoxConstraint(0.0, 1.0)
    _ok(vm.operator_from_prox(lambda x, lam: box.prox(x), value=box, shape=2, name="proxop.BoxConstraint"))
    # Huber's w put into gamma (as if w multiplied g): the exact prox of another Huber function
    h = proxop.Huber(w=2.0)
    wrong = vm.operator_from_prox(lambda x, lam: proxop.Huber(w=1.0).prox(x, gamma=2.0 * lam), value=h, shape=2,
                                  name="Huber w as a factor")
    assert "prox_inequality" in {r.check for r in vm.check_operator(wrong, seed=0).failures}


# -- prox-tv: tv1_1d(x, w) = argmin_z ½|z - x|² + w·TV(z); the step multiplies the weight: w = λ·weight ---------
def test_prox_tv_recipes():
    ptv = pytest.importorskip("prox_tv", reason="prox-tv is not installed: it does not build on this machine "
                                                "(pip install prox-tv fails; no wheel for this Python)")
    tv = lambda x: float(np.abs(np.diff(x)).sum())   # noqa: E731
    _ok(vm.operator_from_prox(lambda x, lam: ptv.tv1_1d(x, lam * 0.5), value=lambda x: 0.5 * tv(x), shape=5,
                              name="prox_tv.tv1_1d"))


# -- JAX and PyTorch: the recipes of docs/prox-libraries.md, executed from its code blocks ------------------------
def _recipes(heading):
    """The objects the first ``python`` code block under ``heading`` in docs/prox-libraries.md defines."""
    import pathlib
    import re

    doc = (pathlib.Path(__file__).parents[2] / "docs" / "prox-libraries.md").read_text()
    section = doc[doc.index(heading):]
    namespace: dict = {}
    exec(re.search(r"```python\n(.*?)```", section, re.S).group(1), namespace)   # noqa: S102 - the doc's recipe
    return namespace


def _float32_ok(op):
    rep = _ok(op)
    assert {r.details["dtype"] for r in rep if r.status == "passed"} == {"float32"}, "judged at float32"
    return rep


def test_jax_recipes():
    jax = pytest.importorskip("jax", reason="JAX is not installed (pip install 'verimono[arrays]')")
    pytest.importorskip("jaxopt", reason="jaxopt is not installed (pip install 'verimono[arrays]')")
    from jaxopt.prox import prox_lasso

    ns = _recipes("## JAX (jaxopt)")
    for name in ("lasso", "ball", "batched"):
        _float32_ok(ns[name])
    assert ns["lasso"].array == "jax" and ns["batched"].batched
    # the weight applied twice: the exact prox of 4|x|_1, not of the stated g = 2|x|_1 (jitted like the recipes,
    # and the one law that catches it, as check_operator runs it: the whole battery on the eager prox cost 10 s CPU)
    from verimono.checks.operator_battery import operator_checks

    twice = vm.operator_from_prox(jax.jit(lambda x, scaling: prox_lasso(x, 2.0, 2 * scaling)), step="scaling",
                                  value=ns["l1_value"], shape=3, name="weight twice")
    assert dict(operator_checks(twice, seed=0))["prox_inequality"](twice).status == "failed"


def test_pytorch_recipes():
    torch = pytest.importorskip("torch", reason="PyTorch is not installed (pip install 'verimono[arrays]')")
    pytest.importorskip("proxtorch", reason="ProxTorch is not installed (pip install 'verimono[arrays]')")
    from proxtorch.operators import L1

    ns = _recipes("## PyTorch (ProxTorch)")
    for name in ("torch_l1", "torch_ball", "torch_batched"):
        _float32_ok(ns[name])
    # the weight forgotten: L1(alpha=1) given the value of L1(alpha=2)
    forgot = vm.operator_from_prox(L1(alpha=1.0).prox, value=ns["value"], shape=3, array="torch", name="weight forgotten")
    assert "prox_inequality" in {r.check for r in vm.check_operator(forgot, seed=0).failures}
    # the prox receives tensors (declared), the laws float64 NumPy
    seen = []
    op = vm.operator_from_prox(lambda x, lam: seen.append(type(x)) or ns["l1"].prox(x, lam), shape=3, array="torch")
    assert op.resolvent([1.0, -2.0, 0.1], 0.5).dtype == np.float64 and seen == [torch.Tensor]


@pytest.mark.sweep      # seed 0 is test_jax_recipes / test_pytorch_recipes above
@pytest.mark.parametrize("heading, names, libs", [
    ("## JAX (jaxopt)", ("lasso", "ball", "batched"), ("jax", "jaxopt")),
    ("## PyTorch (ProxTorch)", ("torch_l1", "torch_ball", "torch_batched"), ("torch", "proxtorch"))], ids=["jax", "torch"])
def test_recipes_pass_every_law_at_seeds_1_to_19(heading, names, libs):
    for lib in libs:
        pytest.importorskip(lib, reason=f"{lib} is not installed (pip install 'verimono[arrays]')")
    ns = _recipes(heading)
    for seed in range(1, 20):
        for name in names:
            rep = vm.check_operator(ns[name], seed=seed)
            assert rep.ok, f"{name}, seed {seed}:\n" + "\n".join(map(str, rep.failures))
            assert {r.details["dtype"] for r in rep if r.status == "passed"} == {"float32"}


def test_a_membership_test_as_value_is_refused_with_the_fix():
    """PyProximal's indicators (``Box``, ``EuclideanBall``, ...) return a bool from ``__call__`` — ``True`` inside
    — not ``g``: passed as ``value`` they stated ``g = 1`` on the set and ``0`` outside, and the correct projection
    failed four or five value laws (branch probe5).  A bool is refused as a value, naming the indicator."""
    from verimono.checks import check_prox_inequality
    box = lambda x: bool(np.all(np.abs(x) <= 1.0))              # noqa: E731 - a membership test, as PyProximal's
    proj = lambda x, lam: np.clip(x, -1.0, 1.0)                 # noqa: E731
    sample = dict(x1=[0.0, 0.0, 3.0], x2=[0.5, 0.0, 0.0], lam=1.0, mu=1.0, nu=1.0, t=0.0)    # PyProximal's Box's failure
    for v in (box, lambda x: np.all(np.abs(x) <= 1.0)):
        op = vm.operator_from_prox(proj, value=v, shape=3, name="box, membership as value")
        with pytest.raises(vm.ProxOutputError, match="0.0 if"):
            op.value(np.zeros(3))
        rec = check_prox_inequality(op, sample=sample)
        assert rec.status == "failed" and "membership" in rec.message, rec.message
    lawful = vm.operator_from_prox(proj, value=lambda x: 0.0 if box(x) else np.inf, shape=3, name="box indicator")
    assert check_prox_inequality(lawful, sample=sample).status == "passed"
