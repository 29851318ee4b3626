"""The diffrax recipes on the ODE references, run in a process of their own (JAX is not loaded into the test
workers: a loaded JAX makes verimono's executors spawn instead of fork).  Prints one JSON object: case ->
{"status", "message"}.  Used by tests/integrators/test_recipes.py."""

from __future__ import annotations

import json
import sys

import numpy as np


def main() -> None:
    import diffrax
    import jax.numpy as jnp

    from verimono.checks.orders import check_convergence_order
    from verimono.checks.own_steps import check_tolerance_rate
    from verimono.core.recipes import diffrax_stepper
    from verimono.reference import linear

    M = jnp.asarray(linear.M_DEFAULT)
    m, a, b, om = 1.0, 0.5, 0.2, 2.0

    def linear_field(t, y, args):
        return -M @ y

    def input_field(t, y, args):
        return -m * y - a * y + b + jnp.cos(om * t)

    def input_late(t, y, args):                       # planted: the input read 0.1 late
        return -m * y - a * y + b + jnp.cos(om * (t + 0.1))

    refs = {"linear": (linear.linear(), linear_field), "input": (linear.lipschitz_input(), input_field)}
    # (solver, reference, claimed PID rate): PID controls the error per step; a solver propagating a higher
    # order than its estimate (local extrapolation: Heun, Tsit5, Kvaerno5) gets rate 1, ImplicitEuler p/(p+1) = 1/2
    cases = [("Euler", "input", None), ("Heun", "linear", 1.0), ("Tsit5", "input", 1.0),
             ("ImplicitEuler", "linear", 0.5), ("Kvaerno5", "input", 1.0)]
    out = {}
    for name, ref, rate in cases:
        p, field = refs[ref]
        fixed = diffrax_stepper(getattr(diffrax, name)(), field)
        o = fixed.claim.order
        K = (10, 20, 40, 80) if o >= 5 else ((40, 80, 160, 320) if o >= 2 else (100, 200, 400, 800))
        rec = check_convergence_order.law.check(fixed, p, steps=[p.T / k for k in K])
        out[f"{name} fixed on {ref}"] = {"status": rec.status, "message": rec.message}
        if rate is not None:
            tols = tuple(10.0 ** -k for k in (np.arange(4, 9.01, 1) if o >= 5 else np.arange(3, 6.01, 1)))
            pid = diffrax_stepper(getattr(diffrax, name)(), field, adaptive=True, rate=rate, tolerances=tols)
            rec = check_tolerance_rate(pid, p)
            out[f"{name} PID on {ref}"] = {"status": rec.status, "message": rec.message}
    # planted bugs in the wrapper: the input evaluated late (fixed and PID), the tolerance not passed on
    p = linear.lipschitz_input()
    late = diffrax_stepper(diffrax.Heun(), input_late, name="heun, input late")
    rec = check_convergence_order.law.check(late, p, steps=[p.T / k for k in (40, 80, 160, 320)])
    out["planted: input late, fixed"] = {"status": rec.status, "message": rec.message}
    late_pid = diffrax_stepper(diffrax.Tsit5(), input_late, adaptive=True, name="tsit5, input late",
                               tolerances=(1e-4, 1e-5, 1e-6, 1e-7))
    rec = check_tolerance_rate(late_pid, p)
    out["planted: input late, PID"] = {"status": rec.status, "message": rec.message}
    fixed_tol = diffrax_stepper(diffrax.Tsit5(), input_field, adaptive=True, name="tsit5")
    ignores = type(fixed_tol)(lambda problem, T, tol: fixed_tol.fn(problem, T, 1e-4), rate=1.0,
                              name="tsit5 ignoring the tolerance", tolerances=(1e-4, 1e-5, 1e-6, 1e-7))
    rec = check_tolerance_rate(ignores, p)
    out["planted: tolerance ignored, PID"] = {"status": rec.status, "message": rec.message}
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
