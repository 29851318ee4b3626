"""The paper's Example ``ex`` (Section 3.2; :mod:`verimono.reference.lcs_example`) checked against its closed
forms: the one-step solve of its complementarity system, the batched scheme, and its unbounded
pseudo-distance (Vladimirov's absolute continuity ``d:vlad`` fails for it while Theorem
``e: linear case-comp`` holds).  Each is a decorated evaluator ``check_<law>(*, seed, ...) -> Outcome`` whose
subject is the Example.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from verimono.reference.lcs_example import closed_form_resolvent, example_system, pseudo_distance_demo

from ..records.results import CheckResult
from ..core.tolerances import tolerance
from .core import Outcome, law, run

SUBJECT = "paper Example ex"


def run_example_law(decl: Any, **kw: Any) -> CheckResult:
    """A law of the Example (its subject is the Example itself)."""
    return run(decl, SUBJECT, lambda: decl.evaluate(**kw), seed=kw.get("seed"))


def example_law(name: str, label: str) -> Any:
    return law(name, label, subject="system", driver=run_example_law, battery=False)


@example_law("example_resolvent_closed_form", "ex: the resolvent of H")
def check_closed_form_resolvent(*, samples: int = 200, seed: int = 0) -> Outcome:
    """Example ``ex``: the system's one-step solve equals the closed form ``max(x + h max(−v1, 0), −v2)`` of
    ``J_{hH}`` at random ``(x, h, v)``."""
    rng = np.random.default_rng(seed)
    worst, counter = 0.0, None
    for _ in range(samples):
        x, h, v1, v2 = rng.uniform(-3, 3), rng.uniform(1e-3, 2.0), rng.uniform(-2, 2), rng.uniform(-2, 2)
        got = float(example_system(np.array([v1, v2])).operator().resolvent(np.array([x]), h, 0.0)[0])
        want = float(closed_form_resolvent(x, h, v1, v2))
        ratio = abs(got - want) / tolerance(x, h, v1, v2)
        if ratio > worst:
            worst, counter = ratio, {"x": x, "h": h, "v": [v1, v2], "got": got, "closed_form": want}
    message = f"{samples} one-step LCP solves against max(x + h max(-v1, 0), -v2)"
    return Outcome(worst, counter={**(counter or {}), "message": message}, message=message)


@example_law("example_batched_scheme", "ex: the scheme on a batch")
def check_batched_scheme(*, batch: int = 64, steps: int = 400, T: float = 4.0, seed: int = 0) -> Outcome:
    """Example ``ex``: ``batch`` initial points and inputs ``v_b(t) = (a_b sin t − c_b, d_b)`` stepped at once by
    ``LinearRelationSystem.simulate`` (θ = 1, ``x0`` of shape ``(B, 1)``, ``v`` returning ``(B, 2)``) equal, on
    every row and step, the closed-form scheme ``x_{k+1} = max(x_k + h max(−v1(t_{k+1}), 0), −v2(t_{k+1}))``."""
    rng = np.random.default_rng(seed)
    a, c, d = rng.uniform(0, 2, batch), rng.uniform(-1, 1, batch), rng.uniform(-1, 1, batch)
    x0 = rng.uniform(-2, 3, batch)

    def v(t):
        return np.column_stack([a * np.sin(t) - c, d])

    t = np.linspace(0.0, T, steps + 1)
    got = example_system(np.zeros(2)).simulate(x0[:, None], t, theta=1.0, v=v).x[:, :, 0]
    want = np.empty_like(got)
    want[0] = x0
    for k in range(steps):
        vk = v(t[k + 1])
        want[k + 1] = np.maximum(want[k] + (t[k + 1] - t[k]) * np.maximum(-vk[:, 0], 0.0), -vk[:, 1])
    err = np.abs(got - want)
    worst = float(err.max() / tolerance(want))
    k, b = np.unravel_index(int(err.argmax()), err.shape)
    message = (f"{batch} trajectories x {steps} steps in one batched simulate against the closed-form scheme "
               "max(x + h max(-v1, 0), -v2)")
    return Outcome(worst, counter={"row": int(b), "step": int(k), "x0": float(x0[b]), "got": float(got[k, b]),
                                   "closed_form": float(want[k, b]), "message": message}, message=message)


@example_law("example_pseudo_distance_unbounded", "d:vlad fails for ex")
def check_pseudo_distance_unbounded(*, rhos=(0.0, 1.0, 10.0, 100.0, 1000.0)) -> Outcome:
    """Example ``ex``: sampled lower bounds of ``dis(H(t1,·), H(t2,·))`` reach ``(ρ+1)/2`` for every ``ρ`` — the
    pseudo-distance is unbounded, so Vladimirov's absolute continuity (``d:vlad``) fails for the Example."""
    pairs = [(rho, float(bound)) for rho, bound in pseudo_distance_demo(rhos)]
    worst = max((rho + 1.0) / 2.0 / bound for rho, bound in pairs)
    message = ("dis(H(0,·), H(1,·)) ≥ " + ", ".join(f"{b:.4g}" for _, b in pairs)
               + f" for ρ = {', '.join(f'{r:g}' for r, _ in pairs)}: at least (ρ+1)/2, unbounded")
    return Outcome(worst, bound=1.0 + 1e-12, details={"rho": [r for r, _ in pairs], "bound": [b for _, b in pairs]},
                   counter={"message": message}, message=message)


__all__ = ["check_closed_form_resolvent", "check_batched_scheme", "check_pseudo_distance_unbounded", "SUBJECT"]
