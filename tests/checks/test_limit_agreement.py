"""convergence_order's limit on problems without an exact solution (verimono.checks.agreement): a scheme
claiming ``scheme="any"`` is held to the limit of verimono.solve (thm:main) — each limit estimated from its own
4-fold refinements — whatever order it claims.  A stepper dropping f passed before (the review's probe,
docs/speed.md: "A pass not earned"); correct schemes of orders 1 and 4 must pass, planted wrong limits fail."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.checks.agreement import LIMIT_RESOLUTION
from verimono.checks.orders import check_convergence_order
from zoo_integrators import rk4_on_grid
from zoo_steppers import _scheme, midpoint_time, random_substeps

ROTATION = np.array([[0.0, -1.0], [1.0, 0.0]])


def rotating_ball(seed: int) -> vm.Problem:
    """x' ∈ −N_{C(t)}(x) + c·Rx + u(t): a unit ball moving on a circle, a rotation field, an input — no exact
    solution; drawn by ``seed`` (c, the input's amplitude, x0 in the ball)."""
    rng = np.random.default_rng(seed)
    c, a, r0, th = rng.uniform(0.5, 1.5), rng.uniform(0.5, 1.5), rng.uniform(0.0, 0.9), rng.uniform(0, 2 * np.pi)
    ball = vm.NormalCone(vm.sets.Ball(lambda t: 0.3 * np.array([np.cos(t), np.sin(t)]), 1.0))
    x0 = np.array([0.3, 0.0]) + r0 * np.array([np.cos(th), np.sin(th)])
    return vm.Problem(ball, x0, 2.0, f=lambda x: c * (ROTATION @ np.asarray(x)), lipschitz=c,
                      u=lambda t: a * np.array([np.cos(3 * t), 0.0]), name=f"rotating field in a moving ball #{seed}")


def rotating_linear(seed: int) -> vm.Problem:
    """x' = −Mx + c·Rx + u(t), M symmetric positive definite (F smooth): no exact solution stated."""
    rng = np.random.default_rng(seed)
    B = rng.normal(size=(2, 2))
    c = rng.uniform(0.5, 1.5)
    return vm.Problem(vm.Linear(B @ B.T + 0.1 * np.eye(2)), rng.normal(size=2), 2.0,
                      f=lambda x: c * (ROTATION @ np.asarray(x)), lipschitz=c,
                      u=lambda t: np.array([np.sin(2 * t), 1.0]), name=f"linear with rotation #{seed}")


def drop_f(problem, t):
    """The catching-up loop that forgets f (README's loop without its f line)."""
    dU = problem.input_increments(np.asarray(t))
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(1, len(t)):
        z = x[-1] if dU is None else x[-1] + dU[k - 1]
        x.append(problem.operator.resolvent(z, t[k] - t[k - 1], t[k]))
    return np.array(x)


def theta_scheme(problem, t, theta=0.5):
    """f by the θ-rule on a catching-up predictor, x_{k+1} = J(x_k + h((1−θ)f(x_k) + θ f(x̃)) + ∫u): order 1
    (θ = 1/2: Crank–Nicolson-like in f)."""
    h, dU = np.diff(t), problem.input_increments(np.asarray(t))
    x = [np.asarray(problem.x0, dtype=float)]
    for k in range(len(h)):
        fx = np.asarray(problem.f(x[-1]))
        pred = problem.operator.resolvent(x[-1] + h[k] * fx + dU[k], h[k], t[k + 1])
        z = x[-1] + h[k] * ((1 - theta) * fx + theta * np.asarray(problem.f(pred))) + dU[k]
        x.append(problem.operator.resolvent(z, h[k], t[k + 1]))
    return np.array(x)


def ivp(problem, t):
    """SciPy's DOP853 on x' = −F x + f(x) + u(t) (F single-valued), read at the nodes."""
    from scipy.integrate import solve_ivp

    def rhs(s, x):
        return -np.asarray(problem.operator.min_norm(x, s)) + problem.f(x) + problem.u(s)
    return solve_ivp(rhs, (0.0, problem.T), problem.x0, t_eval=t, rtol=1e-11, atol=1e-13, method="DOP853").y.T


def _solved(problem, t, **changes):
    return vm.solve(problem.replace(**changes) if changes else problem, t).x


def off_by(problem, t, delta=1e-3):
    """verimono.solve's solution moved by ``delta`` after t = 0: it converges, to a limit ``delta`` off."""
    x = _solved(problem, t).copy()
    x[1:, 0] += delta
    return x


CORRECT = {"solve": (_solved, 1), "catching-up loop": (lambda p, t: _scheme(p, t), 1),
           "theta 1/2": (theta_scheme, 1), "theta 1": (lambda p, t: theta_scheme(p, t, 1.0), 1),
           "midpoint time": (midpoint_time, 1), "random substeps": (random_substeps, 1)}
SMOOTH = {"rk4": (rk4_on_grid, 4), "solve_ivp DOP853": (ivp, 4)}
PLANTED = {"f dropped": drop_f,
           "f with the wrong sign": lambda p, t: _solved(p, t, f=lambda x: -p.f(x)),
           "f scaled by 1.1": lambda p, t: _solved(p, t, f=lambda x: 1.1 * p.f(x)),
           "u dropped": lambda p, t: _solved(p, t, u=None, U=None),
           "limit off by 1e-3": off_by}


def _record(fn, order, problem, name):
    return check_convergence_order(vm.Stepper(fn, scheme="any", order=order, name=name), problem)


@pytest.mark.heavy
def test_the_probe_dropping_f_fails_at_every_claimed_order():
    """The probe's case: x' ∈ −N_B(x) + 3Rx in a still unit ball from (0.5, 0): the loop without f stays at x0
    (its errors at round-off, the study coarsens to K = 10), and passed claiming order 2 (1.5 ≤ 2.36 on K = 10)."""
    ball = vm.NormalCone(vm.sets.Ball(lambda t: np.zeros(2), 1.0))
    p = vm.Problem(ball, [0.5, 0.0], 2.0, f=lambda x: 3.0 * (ROTATION @ np.asarray(x)), lipschitz=3.0, name="probe")
    for order in (1, 2, 3):
        rec = _record(drop_f, order, p, "drops f")
        lim = rec.details["limit"]
        assert rec.status == "failed" and "not to the solution" in rec.message, rec.message
        assert lim["distance"] > lim["bound"] and lim["levels"][:3] == [10, 40, 160] and rec.worst > 1


@pytest.mark.heavy
@pytest.mark.parametrize("name", sorted(PLANTED))
def test_planted_wrong_limits_fail(name):
    for problem in (rotating_ball(0), rotating_linear(0)):
        rec = _record(PLANTED[name], 1, problem, name)
        lim = rec.details["limit"]
        assert rec.status == "failed", (problem.name, rec.message)
        assert lim["distance"] - lim["stepper_tail"] - lim["solve_tail"] > lim["round_off"]


@pytest.mark.heavy
@pytest.mark.parametrize("name", sorted(CORRECT))
def test_correct_schemes_reach_the_limit_of_solve(name):
    fn, order = CORRECT[name]
    rec = _record(fn, order, rotating_ball(0), name)
    lim = rec.details["limit"]
    assert rec.status == "passed", rec.message
    assert lim["upper"] <= lim["resolution"] + lim["round_off"]
    assert lim["resolution"] >= LIMIT_RESOLUTION and lim["levels"][-1] <= 40960


@pytest.mark.heavy
@pytest.mark.parametrize("name", sorted(SMOOTH))
def test_high_order_schemes_on_a_smooth_operator_pass(name):
    fn, order = SMOOTH[name]
    rec = _record(fn, order, rotating_linear(0), name)
    assert rec.status == "passed", rec.message


@pytest.mark.heavy
def test_a_limit_not_resolved_is_undecided_never_passed(monkeypatch):
    """Two levels short of what the tails need: neither within the resolution nor provably apart."""
    import verimono.checks.agreement as agreement

    monkeypatch.setattr(agreement, "MAX_AGREEMENT_CELLS", 640)
    rec = _record(*CORRECT["theta 1"], rotating_ball(0), "theta 1")
    assert rec.status == "undecided" and "not resolved" in rec.message, rec.message
    assert rec.details["limit"]["levels"] == [10, 40, 160, 640]


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(5))
def test_seeds_correct_pass_and_planted_fail(seed):
    for problem in (rotating_ball(seed), rotating_linear(seed)):
        for name, (fn, order) in {**CORRECT, **(SMOOTH if "linear" in problem.name else {})}.items():
            rec = _record(fn, order, problem, name)
            assert rec.status == "passed", (problem.name, name, rec.message)
        for name, fn in PLANTED.items():
            rec = _record(fn, 1, problem, name)
            assert rec.status == "failed", (problem.name, name, rec.message)
