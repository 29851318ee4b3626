"""The recipes of docs/integrators.md: SciPy's solve_ivp (Radau, BDF) and diffrax's Euler, Heun, Tsit5,
ImplicitEuler and Kvaerno5 (fixed step and PIDController) at their advertised orders or tolerance rates on
the ODE references, and planted bugs in such wrappers failing.  diffrax runs in a process of its own
(tests/integrators/diffrax_cases.py); without it the tests are counted skips with the reason."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import verimono as vm
from verimono.checks.own_steps import check_tolerance_rate
from verimono.core.recipes import solve_ivp_stepper
from verimono.reference import linear

HERE = Path(__file__).resolve().parent
TOLS = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8)


@pytest.mark.slow
@pytest.mark.parametrize("problem", [linear.linear(), linear.lipschitz_input()], ids=["linear", "input"])
@pytest.mark.parametrize("method, rate, order", [("Radau", 1.0, 5), ("BDF", 5 / 6, None)])
def test_solve_ivp_recipes(problem, method, rate, order):
    """Radau (order 5) is tolerance-proportional at its nodes (measured rate 1.16-1.26) and its dense output
    (1.00); BDF, variable order 1-5 controlling the error per step, p/(p+1) ≤ 5/6 (measured 0.82-0.90)."""
    stepper = solve_ivp_stepper(method, rate=rate, order=order, tolerances=TOLS)
    rec = check_tolerance_rate(stepper, problem)
    assert rec.status == "passed", rec
    study = rec.details["tolerance_study"]
    assert "dense" in study["errors"]


@pytest.mark.slow
def test_solve_ivp_wrapper_with_the_input_late_fails():
    p = linear.lipschitz_input()

    def late(problem, T, tol):
        from scipy.integrate import solve_ivp

        sol = solve_ivp(lambda t, x: -1.5 * x + 0.2 + np.cos(2.0 * (t + 0.1)), (0.0, T), problem.x0, method="Radau",
                        rtol=tol, atol=tol)
        return sol.t, sol.y.T

    rec = check_tolerance_rate(vm.Adaptive(late, rate=1.0, tolerances=TOLS, name="radau, input late"), p)
    assert rec.status == "failed" and "stall" in rec.message


def _diffrax_cases() -> dict:
    out = subprocess.run([sys.executable, str(HERE / "diffrax_cases.py")], capture_output=True, text=True,
                         timeout=900)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def diffrax_results(tmp_path_factory, worker_id):
    """The diffrax cases (a subprocess of 44 s), run once per session: under pytest-xdist the first worker to
    ask runs them and the others read its file (pytest-xdist's documented pattern for a fixture run once)."""
    if importlib.util.find_spec("diffrax") is None or importlib.util.find_spec("jax") is None:
        pytest.skip("diffrax and JAX are not installed (pip install 'verimono[integrators]')")
    if worker_id == "master":       # no xdist: this process is the session
        return _diffrax_cases()
    import fcntl

    shared = tmp_path_factory.getbasetemp().parent      # this session's directory, common to its workers
    path = shared / "diffrax_results.json"
    with open(shared / "diffrax_results.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not path.exists():
            path.write_text(json.dumps(_diffrax_cases()))
        return json.loads(path.read_text())


PASSING = ["Euler fixed on input", "Heun fixed on linear", "Heun PID on linear", "Tsit5 fixed on input",
           "Tsit5 PID on input", "ImplicitEuler fixed on linear", "ImplicitEuler PID on linear",
           "Kvaerno5 fixed on input", "Kvaerno5 PID on input"]
PLANTED = ["planted: input late, fixed", "planted: input late, PID", "planted: tolerance ignored, PID"]


@pytest.mark.slow
@pytest.mark.parametrize("case", PASSING)
def test_diffrax_at_its_advertised_order_or_rate(diffrax_results, case):
    assert diffrax_results[case]["status"] == "passed", diffrax_results[case]


@pytest.mark.slow
@pytest.mark.parametrize("case", PLANTED)
def test_diffrax_planted_wrapper_bugs_fail(diffrax_results, case):
    assert diffrax_results[case]["status"] == "failed", diffrax_results[case]
