"""The two batch kernels of ``LinearRelationSystem.simulate`` (issue 43, item 4): the compiled one (numba,
optional: ``pip install verimono[fast]``) and the NumPy one give the **same bits** — states, multipliers,
outputs, failed rows and their steps — since both make, row by row, the same multiply-adds in the same order
(no fused multiply-add: numba's ``fastmath`` is off) and the same pattern changes; and a batch under either equals
its rows' single runs bit for bit.  The choice (``kernel.BATCH_KERNEL``, ``batch_backend``) falls back to NumPy
when numba is absent, and the run says which kernel ran (``StepKernel.last_backend``).

The tests that compile need numba (each new shape compiles for ~10 s once per machine, then loads from the
disk cache): they skip without it — CI does not install it — and are marked slow."""

from __future__ import annotations

import numpy as np
import pytest

from verimono import InfeasibleStep, SolverFailure
from verimono.lcs import Complementarity, LinearRelationSystem
from verimono.lcs import kernel as K
from verimono.lcs.siconos_cases import diode_bridge, filippov, relay_oscillator

from test_lcs_system import random_passive


def _same(a, b):
    return np.array_equal(a, b, equal_nan=True)


def _run(sys, X0, t, backend, monkeypatch, **kw):
    """``(trajectory, failures or None, kernel that ran)`` under ``backend``."""
    monkeypatch.setattr(K, "BATCH_KERNEL", backend)
    try:
        tr, fails = sys.simulate(X0, t, **kw), None
    except K.BatchStepError as exc:
        tr, fails = exc.trajectory, [(f.row, f.step, type(f.error)) for f in exc.failures]
    kern = [k for k in sys._kernels.values() if k.last_backend is not None]
    return tr, fails, kern[-1].last_backend if kern else None


def test_without_numba_the_numpy_kernel_runs_and_says_so(monkeypatch):
    """numba absent (its loader unavailable): every setting falls back to the NumPy kernel, which the run names;
    small batches take NumPy under "auto" whether or not numba is installed."""
    monkeypatch.setattr(K, "_NUMBA", [None])
    for setting in ("auto", "numba", "numpy"):
        monkeypatch.setattr(K, "BATCH_KERNEL", setting)
        assert K.batch_backend(4, 10 ** 9) == "numpy"
    monkeypatch.setattr(K, "_NUMBA", [])
    monkeypatch.setattr(K, "BATCH_KERNEL", "auto")
    assert K.batch_backend(4, K.NUMBA_MIN_WORK - 1) == "numpy"
    assert K.batch_backend(K.NUMBA_MAX_M + 1, 10 ** 9) == "numpy"
    monkeypatch.setattr(K, "_NUMBA", [None])
    sys = diode_bridge()
    t = np.arange(51) * 1e-6
    X0 = np.array([[10.0, 0.0], [-3.0, 2.0]])
    tr, fails, ran = _run(sys, X0, t, "numba", monkeypatch, theta=0.5)
    assert ran == "numpy" and fails is None
    assert _same(tr.x[:, 1], sys.simulate(X0[1], t, theta=0.5).x)


def _cases():
    rng = np.random.default_rng(3)
    A, B, C, D = random_passive(rng)
    rp = LinearRelationSystem(A, B, C, D, Complementarity())
    amp = np.array([0.5, 1.0, 2.0])
    gen = np.random.default_rng(11)
    return {
        # DiodeBridge: rows through zero current (degenerate steps, Python's certificate) and every pattern
        "diode_bridge": (diode_bridge(), np.vstack([[[10.0, 0.0], [0.0, 0.0], [1e-3, -7.0]],
                                                    gen.normal(size=(61, 2)) * 10]), np.arange(301) * 1e-6,
                         {"theta": 0.5}),
        "diode_bridge_gamma": (diode_bridge(), gen.normal(size=(20, 2)) * 5, np.arange(201) * 1e-6,
                               {"theta": 0.5, "gamma": 0.5}),
        "relay": (relay_oscillator(), gen.normal(size=(16, 3)), np.arange(301) * 1e-2, {"theta": 0.5}),
        "filippov": (filippov(), gen.normal(size=(16, 2)) * 3, np.arange(301) * 1e-3, {"theta": 0.5}),
        # exogenous terms: per-row u and v, then shared u with a per-row constant v
        "inputs_per_row": (rp, rng.normal(size=(3, 3)), np.linspace(0.0, 3.0, 301),
                           {"u": lambda s: np.outer(amp, [np.sin(s), 0.0, np.cos(s)]),
                            "v": lambda s: np.outer(amp, [np.cos(2 * s), -0.3])}),
        "inputs_shared": (rp, rng.normal(size=(3, 3)), np.linspace(0.0, 3.0, 301),
                          {"u": lambda s: np.array([np.sin(s), 0.0, 1.0]), "v": rng.normal(size=(3, 2))}),
        # rows that fail (infeasible from step 4, at once) beside rows that do not
        "infeasible_rows": (LinearRelationSystem([[0.0]], [[1.0]], [[0.0]], [[0.0]], Complementarity()),
                            np.array([[0.1], [0.2], [0.3], [0.4]]), np.linspace(0.0, 1.0, 11),
                            {"v": lambda s: np.array([[1.0], [0.45 - s], [2.0], [-1.0]])}),
        # a row that overflows (SolverFailure) beside one that stays at 0
        "overflow_rows": (LinearRelationSystem([[1e300]], [[1.0]], [[1.0]], [[1.0]], Complementarity()),
                          np.array([[0.0], [1e10], [0.0]]), np.linspace(0.0, 1.0, 4), {"theta": 0.0}),
    }


needs_numba = pytest.mark.skipif(K._numba_advance() is None, reason="numba is not installed (verimono[fast])")


@pytest.mark.slow
@needs_numba
@pytest.mark.parametrize("name", list(_cases()))
def test_the_compiled_batch_kernel_gives_the_numpy_kernels_bits(name, monkeypatch):
    sys, X0, t, kw = _cases()[name]
    a, fa, ra = _run(sys, X0, t, "numba", monkeypatch, **kw)
    b, fb, rb = _run(sys, X0, t, "numpy", monkeypatch, **kw)
    assert (ra, rb) == ("numba", "numpy")
    assert _same(a.x, b.x) and _same(a.extras["z"], b.extras["z"]) and _same(a.extras["w"], b.extras["w"])
    assert fa == fb
    if name == "infeasible_rows":
        assert fa == [(1, 4, InfeasibleStep), (3, 0, InfeasibleStep)]
    if name == "overflow_rows":
        assert [(r, e) for r, _, e in fa] == [(1, SolverFailure)]
    # and a row equals its single run (the NumPy kernel's bits are tested against single runs elsewhere too)
    if "inputs" not in name and fa is None:
        one = sys.simulate(X0[-1], t, **kw)
        assert _same(a.x[:, -1], one.x) and _same(a.extras["w"][:, -1], one.extras["w"])


@pytest.mark.slow
@needs_numba
def test_a_compiled_kernel_that_skips_the_sign_test_is_seen_failing(monkeypatch, tmp_path):
    """The Example's batched-scheme record under the compiled kernel: passes; with the generated kernel's
    acceptance test replaced by ``ok = True`` (every guess accepted unchecked) it fails."""
    from verimono.checks import example as example_checks
    from verimono.lcs import _batch_numba as NB

    monkeypatch.setattr(K, "BATCH_KERNEL", "numba")
    good = example_checks.check_batched_scheme()
    assert good.status == "passed" and good.worst <= 1.0
    orig = NB.advance_source

    def unchecked(n, L, Lf, ne):
        src = orig(n, L, Lf, ne)
        lines = [ln.split("ok = ")[0] + "ok = True" if ln.strip().startswith("ok = -inf") else ln
                 for ln in src.split("\n")]
        assert lines != src.split("\n")
        return "\n".join(lines)

    monkeypatch.setattr(NB, "advance_source", unchecked)
    monkeypatch.setattr(NB, "_LOADED", {})
    monkeypatch.setenv("VERIMONO_NUMBA_DIR", str(tmp_path))
    bad = example_checks.check_batched_scheme()
    assert bad.status == "failed" and bad.worst > 1e3 and {"row", "step"} <= set(bad.counterexample)


def test_the_performance_record_names_the_kernel_and_its_bound(monkeypatch):
    """``performance_lcs_batch`` states the kernel that ran and applies its bound (0.25x NumPy, 0.05x compiled)."""
    from verimono.run import performance as perf

    monkeypatch.setattr(K, "BATCH_KERNEL", "numpy")
    rec = perf.check_lcs_batch(batch=8, steps=10, rounds=1, max_rounds=1)
    assert rec.details["kernel"] == "numpy" and rec.details["target"] == perf.LCS_BATCH_TARGET == 0.25
    assert rec.details["identical"] and "judged as" not in rec.message


@pytest.mark.slow
def test_a_record_judged_for_a_kernel_that_did_not_run_fails(monkeypatch):
    """A planted ``batch_backend`` claiming numba while the compiled kernel cannot load (so NumPy runs): the
    record is judged against 0.05x but fails, naming the kernel that ran."""
    from verimono.run import performance as perf

    monkeypatch.setattr(K, "batch_backend", lambda m=1, work=0: "numba")
    monkeypatch.setattr(K, "_numba_advance", lambda: None)
    bad = perf.check_lcs_batch(batch=8, steps=10, rounds=1, max_rounds=1)
    assert bad.status == "failed" and bad.details["target"] == perf.LCS_BATCH_TARGET_COMPILED == 0.05
    assert "ran the numpy kernel, judged as numba's" in bad.message


@pytest.mark.slow
@needs_numba
def test_the_performance_record_under_the_compiled_kernel(monkeypatch):
    from verimono.run import performance as perf

    monkeypatch.setattr(K, "BATCH_KERNEL", "numba")
    rec = perf.check_lcs_batch(batch=8, steps=10, rounds=1, max_rounds=1)
    assert rec.details["kernel"] == "numba" and rec.details["target"] == 0.05 and rec.details["identical"]
    assert "judged as" not in rec.message
