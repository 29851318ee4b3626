"""Bad input gets a typed error, never a silent wrong answer or an unearned pass (issue 14).

Each case below is one *kind* of bad input found by a reliability probe; before the fix each one either
returned a value (a pass over nothing, a projection of NaN, a resolvent at λ < 0, a trajectory through an
empty set), raised a bare ``ZeroDivisionError``/``ValueError``, or was broadcast silently.  Every case
must now raise the stated :class:`verimono.VerimonoError` subclass with the stated words in its message.
"""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono import errors, sets
from verimono.core.operators import resolvent_kernel

# resolved by name so that this file also runs (and fails case by case) against a verimono without them
InvalidCheckArgument = getattr(errors, "InvalidCheckArgument", type("Missing", (Exception,), {}))
G = vm.uniform_grid(1.0, 0.01)


def _solve(op, x0, f=None, T=1.0, grid=None):
    return vm.solve(vm.Problem(op, x0=x0, T=T, f=f), vm.uniform_grid(T, 0.01) if grid is None else grid)


def _scalar_from_step(k, n=2, value=lambda: np.float64(1.0)):
    """A resolvent of the right shape for k-1 calls, then ``value()`` (a scalar: broadcast before)."""
    calls = [0]

    def res(x, lam, t):
        calls[0] += 1
        return 0.5 * np.asarray(x) if calls[0] < k else value()
    return vm.operator_from_resolvent(res, n, name="scalar later")


def _f_scalar_from_step(k):
    calls = [0]

    def f(x):
        calls[0] += 1
        return -np.asarray(x) if calls[0] < k else np.float64(1.0)
    return f


class Moving(vm.Operator):
    """A user subclass whose resolvent returns a Python float from the third call on."""

    def __init__(self):
        super().__init__(2, "returns a float")
        self.calls = 0

    def resolvent(self, x, lam, t=0.0):
        self.calls += 1
        return np.asarray(x, dtype=float) / (1 + lam) if self.calls < 3 else 0.25


def _lcs_check(T=1.0, samples=64):
    from verimono.lcs import check_hypotheses
    from verimono.reference import lcs_example as E

    return check_hypotheses(E.example_system(lambda t: np.array([-t, 0.0])), T, samples=samples)


NSUB = vm.NormSubdifferential(1.0, dim=2)
X = np.array([1.0, -2.0])

# (kind, thunk, error class, words in the message)
CASES = [
    # -- 1. checks asked to verify nothing ---------------------------------------------------------------
    ("examples=0", lambda: vm.check_operator(NSUB, examples=0, seed=0), InvalidCheckArgument, "examples"),
    ("examples<0", lambda: vm.check_operator(NSUB, examples=-3, seed=0), InvalidCheckArgument, "examples"),
    ("examples fractional", lambda: vm.check_operator(NSUB, examples=2.5, seed=0), InvalidCheckArgument,
     "examples"),
    ("run_law examples=0", lambda: __import__("verimono.checks.engine.search", fromlist=["x"]).run_law(
        "monotone", NSUB, examples=0, seed=0), InvalidCheckArgument, "examples"),
    ("horizon<0", lambda: vm.check_operator(NSUB, examples=2, seed=0, horizon=-1.0), InvalidCheckArgument,
     "horizon"),
    ("horizon nan", lambda: vm.check_operator(NSUB, examples=2, seed=0, horizon=float("nan")),
     InvalidCheckArgument, "horizon"),
    ("check_stepper problems=[]", lambda: vm.check_stepper(vm.solve, problems=[]), InvalidCheckArgument,
     "empty list of problems"),
    ("check_stepper selects nothing", lambda: vm.check_stepper(
        vm.solve, problems=[__import__("verimono.reference", fromlist=["x"]).get("t|x| (n=1)")], laws=[],
        orders=False), InvalidCheckArgument, "no check"),
    ("check_hypotheses T<0", lambda: _lcs_check(T=-1.0), InvalidCheckArgument, "T > 0"),
    ("check_hypotheses T=0", lambda: _lcs_check(T=0.0), InvalidCheckArgument, "T > 0"),
    ("check_hypotheses T=nan", lambda: _lcs_check(T=float("nan")), InvalidCheckArgument, "T > 0"),
    ("check_hypotheses samples=0", lambda: _lcs_check(samples=0), InvalidCheckArgument, "samples"),
    # -- 2. solve: a step's output of the wrong shape ----------------------------------------------------
    ("resolvent scalar from step 2", lambda: _solve(_scalar_from_step(2), [1.0, 2.0]), vm.SolverFailure,
     "at step 2"),
    ("resolvent shape (1,) from step 5", lambda: _solve(_scalar_from_step(5, value=lambda: np.ones(1)),
                                                         [1.0, 2.0]), vm.SolverFailure, "at step 5"),
    ("resolvent float from step 3 (subclass)", lambda: _solve(Moving(), [1.0, 2.0]), vm.SolverFailure,
     "a float"),
    ("f scalar from step 2", lambda: _solve(vm.NormSubdifferential(0.1, dim=2), [1.0, 2.0],
                                            f=_f_scalar_from_step(2)), vm.SolverFailure, "f returned shape ()"),
    # -- 2. time-dependent data invalid at a later time ------------------------------------------------
    ("Linear M(t) loses monotonicity", lambda: _solve(vm.Linear(lambda t: [[1 - 20 * t]]), [1.0]),
     vm.NotMonotone, "at t = "),
    ("Linear M(t) changes shape", lambda: _solve(vm.Linear(lambda t: np.eye(1) if t < 0.5 else np.eye(2)),
                                                 [1.0]), vm.InvalidProblem, "1x1"),
    ("NormSubdifferential c(t) < 0", lambda: _solve(vm.NormSubdifferential(lambda t: 1 - 5 * t, dim=2),
                                                    [1.0, 0.0]), vm.NotMonotone, "c(t)"),
    ("NormSubdifferential c(t) nan", lambda: _solve(vm.NormSubdifferential(
        lambda t: 1.0 if t < 0.5 else float("nan"), dim=2), [1.0, 0.0]), vm.NotMonotone, "c(t)"),
    ("L1Subdifferential c(t) < 0", lambda: _solve(vm.L1Subdifferential(lambda t: [1.0, 1 - 5 * t], dim=2),
                                                  [1.0, 1.0]), vm.NotMonotone, "c(t)"),
    ("LogBarrier c(t) <= 0", lambda: _solve(vm.LogBarrier(lambda t: 1 - 2 * t), [1.0]), vm.InvalidProblem,
     "c(t)"),
    ("Box becomes empty", lambda: _solve(vm.NormalCone(sets.Box(lambda t: [t], lambda t: [0.5])), [0.0]),
     vm.InvalidProblem, "box is empty"),
    ("Ball radius crosses 0", lambda: _solve(vm.NormalCone(sets.Ball(lambda t: [0.0, 0.0], lambda t: 0.5 - t)),
                                             [0.0, 0.0]), vm.InvalidProblem, "radius(t)"),
    ("HalfSpace normal vanishes", lambda: _solve(vm.NormalCone(sets.HalfSpace(lambda t: [0.5 - t, 0.0], 0.0)),
                                                 [-1.0, 0.0]), vm.InvalidProblem, "normal(t)"),
    ("Ball.project, radius < 0 at t", lambda: sets.Ball([0.0], lambda t: 1 - t).project([3.0], 2.0),
     vm.InvalidProblem, "t = 2.0"),
    ("Box.project, empty at t", lambda: sets.Box(lambda t: [t], lambda t: [0.5]).project([0.0], 0.9),
     vm.InvalidProblem, "t = 0.9"),
    # -- 2. the step size λ on every resolvent / Yosida path -----------------------------------------------
    ("resolvent λ < 0", lambda: NSUB.resolvent(X, -1.0), vm.InvalidProblem, "step size λ"),
    ("resolvent λ nan", lambda: NSUB.resolvent(X, float("nan")), vm.InvalidProblem, "step size λ"),
    ("resolvent λ inf", lambda: NSUB.resolvent(X, float("inf")), vm.InvalidProblem, "step size λ"),
    ("yosida λ = 0", lambda: NSUB.yosida(X, 0.0), vm.InvalidProblem, "step size λ"),
    ("Linear resolvent λ < 0", lambda: vm.Linear(np.eye(2)).resolvent(X, -0.5), vm.InvalidProblem,
     "step size λ"),
    ("L1 resolvent λ < 0", lambda: vm.L1Subdifferential(1.0, dim=2).resolvent(X, -1.0), vm.InvalidProblem,
     "step size λ"),
    ("NormalCone resolvent λ < 0", lambda: vm.NormalCone(sets.Ball([0.0, 0.0], 1.0)).resolvent(X, -1.0),
     vm.InvalidProblem, "step size λ"),
    ("Shifted resolvent λ = 0", lambda: vm.Shifted(NSUB, [1.0, 0.0]).resolvent(X, 0.0), vm.InvalidProblem,
     "step size λ"),
    ("LogBarrier resolvent λ < 0", lambda: vm.LogBarrier(1.0, dim=2).resolvent(X, -1.0), vm.InvalidProblem,
     "step size λ"),
    ("user resolvent λ < 0", lambda: vm.operator_from_resolvent(lambda x, lam, t: x, 2).resolvent(X, -1.0),
     vm.InvalidProblem, "step size λ"),
    ("kernel λ < 0 (t|x|)", lambda: resolvent_kernel(vm.NormSubdifferential(lambda t: t, dim=2), X)(X, -1.0, 0.5),
     vm.InvalidProblem, "step size λ"),
    ("kernel λ = 0 (box)", lambda: resolvent_kernel(vm.NormalCone(sets.Box([0.0, 0.0], [1.0, 1.0])), X)(X, 0.0, 0.0),
     vm.InvalidProblem, "step size λ"),
    ("kernel λ nan (ball)", lambda: resolvent_kernel(vm.NormalCone(sets.Ball([0.0, 0.0], 1.0)), X)(
        X, float("nan"), 0.0), vm.InvalidProblem, "step size λ"),
    # -- 2. NaN points to projections, complex inputs ------------------------------------------------------
    ("Ball.project(nan)", lambda: sets.Ball([0.0, 0.0], 1.0).project([np.nan, 0.0]), vm.InvalidProblem, "finite"),
    ("Box.project(nan)", lambda: sets.Box([0.0], [1.0]).project([np.nan]), vm.InvalidProblem, "finite"),
    ("HalfSpace.project(nan)", lambda: sets.HalfSpace([1.0, 0.0], 0.0).project([np.nan, 1.0]), vm.InvalidProblem,
     "finite"),
    ("Polyhedron.project(nan)", lambda: sets.Polyhedron([[1.0, 0.0]], [0.0]).project([np.nan, 1.0]),
     vm.InvalidProblem, "finite"),
    ("complex point to a resolvent", lambda: NSUB.resolvent(np.array([1 + 1j, 0.0]), 1.0), vm.InvalidProblem,
     "real"),
    ("complex point to Linear", lambda: vm.Linear(np.eye(2)).resolvent(np.array([1j, 0.0]), 1.0),
     vm.InvalidProblem, "real"),
    ("complex constant parameter", lambda: vm.NormSubdifferential(np.complex128(1 + 1j), dim=2),
     vm.InvalidProblem, "real"),
    ("complex Ball centre", lambda: sets.Ball(np.array([1j, 0.0]), 1.0), vm.InvalidProblem, "real"),
    ("complex Box bound", lambda: sets.Box(np.array([0j]), [1.0]), vm.InvalidProblem, "real"),
    ("complex x0 array", lambda: vm.Problem(NSUB, x0=np.array([1 + 1j, 0.0]), T=1.0), vm.InvalidProblem, "real"),
    ("complex time grid", lambda: vm.solve(vm.Problem(NSUB, x0=[1.0, 0.0], T=1.0), np.linspace(0, 1, 5) + 0j),
     vm.InvalidGrid, "real"),
    ("complex stepper values", lambda: vm.convergence_study(
        lambda p, t: np.zeros((len(t), 2), dtype=complex) + 1j, vm.Problem(NSUB, x0=[1.0, 0.0], T=1.0,
                                                                           exact=lambda t: [1.0, 0.0]),
        [0.1, 0.05]), vm.InvalidProblem, "real"),
    ("complex c(t) in solve", lambda: _solve(vm.NormSubdifferential(lambda t: np.complex128(1 + 1j * t), dim=2),
                                             [1.0, 0.0]), vm.InvalidProblem, "real"),
]


@pytest.mark.parametrize("thunk, error, words", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_input_raises_a_typed_error(thunk, error, words):
    with _no_complex_warning():
        with pytest.raises(error) as info:
            thunk()
    assert isinstance(info.value, vm.VerimonoError)
    assert words in str(info.value)


def test_moving_box_bounds_meeting_by_round_off_are_a_point_not_an_empty_box():
    """Bounds equal at t = 1 in exact arithmetic that cross there by round-off (0.1 + 0.2 t exceeds 0.3 by one
    ulp; the dev profile's hypothesis drew such a box) make a point, the one between them; a crossing beyond
    the tolerance is still an empty box, named with its t."""
    box = sets.Box(lambda t: [0.1 + 0.2 * t, -1.0], lambda t: [0.3, 1.0])
    assert 0.1 + 0.2 * 1.0 > 0.3
    p = box.project([5.0, 0.5], 1.0)
    assert p[0] == 0.5 * ((0.1 + 0.2) + 0.3) and p[1] == 0.5
    assert box.contains(p, 1.0) and not box.contains([5.0, 0.5], 1.0)
    traj = vm.solve(vm.Problem(vm.NormalCone(box), [0.2, 0.0], 1.0), vm.uniform_grid(1.0, steps=8))
    assert np.all(np.isfinite(traj.x)) and traj.x[-1, 0] == pytest.approx(0.3, abs=1e-15)
    with pytest.raises(vm.InvalidProblem, match="box is empty"):
        sets.Box(lambda t: [0.1 + 0.2 * t], lambda t: [0.3 - 1e-6]).project([0.0], 1.0)


def test_a_moving_ball_radius_below_zero_by_round_off_is_its_centre_not_an_empty_ball():
    """0.3 - (0.1 + 0.2 t) is -5.6e-17 at t = 1: the ball shrunk to its centre, in ``project`` and in the solve
    loop's kernel alike; a radius below 0 beyond the tolerance is still an empty ball."""
    ball = sets.Ball(lambda t: [1.0, 0.0], lambda t: 0.3 - (0.1 + 0.2 * t))
    assert 0.3 - (0.1 + 0.2 * 1.0) < 0
    assert np.array_equal(ball.project([3.0, 4.0], 1.0), [1.0, 0.0])
    traj = vm.solve(vm.Problem(vm.NormalCone(ball), [1.1, 0.0], 1.0), vm.uniform_grid(1.0, steps=8))
    assert np.array_equal(traj.x[-1], [1.0, 0.0])
    with pytest.raises(vm.InvalidProblem, match="the ball is empty"):
        sets.Ball(lambda t: [1.0, 0.0], lambda t: 1.0 - 1.001 * t).project([0.0, 0.0], 1.0)
    with pytest.raises(vm.InvalidProblem, match="the ball is empty"):
        vm.solve(vm.Problem(vm.NormalCone(sets.Ball(lambda t: [1.0, 0.0], lambda t: 1.0 - 1.001 * t)), [1.0, 0.0],
                            1.0), vm.uniform_grid(1.0, steps=8))


def test_at_least_40_kinds_of_bad_input():
    assert len({c[0] for c in CASES}) == len(CASES) >= 40


class _no_complex_warning:
    """Complex values must be refused, not truncated with a ComplexWarning on the way."""

    def __enter__(self):
        import warnings

        self._cm = warnings.catch_warnings()
        self._cm.__enter__()
        warnings.simplefilter("error", np.exceptions.ComplexWarning if hasattr(np, "exceptions")
                              else np.ComplexWarning)
        return self

    def __exit__(self, *exc):
        return self._cm.__exit__(*exc)


# -- no unearned pass --------------------------------------------------------------------------------------

def _nan_stepper(problem, t_grid):
    return np.full((len(t_grid),) + problem.x0.shape, np.nan)


def test_a_stepper_returning_nan_fails_convergence_order_on_every_reference():
    """``max(0.0, nan)`` is 0.0: all-NaN errors used to look like round-off ("exceeds every order")."""
    from verimono.checks.orders import check_convergence_order
    from verimono.reference import catalog

    for p in catalog():
        if p.order is None:
            continue
        rec = check_convergence_order(_nan_stepper, p)
        assert rec.status == "failed", (p.name, rec)
        assert "non-finite error" in rec.message and "h=" in rec.message


def test_fit_order_with_a_nan_error_is_not_exact():
    from verimono.core.convergence import fit_order

    fit = fit_order([0.1, 0.05, 0.025], [1e-3, float("nan"), 2.5e-4], floor=1e-12)
    assert not fit.exact and fit.nonfinite == [1] and fit.slope != fit.slope


def test_error_accumulator_keeps_nan():
    from verimono.core.convergence import ErrorAccumulator
    from verimono.reference import get

    p = get("t|x| (n=1)")
    acc = ErrorAccumulator(p)
    t = np.linspace(0, p.T, 5)
    x = np.asarray(vm.solve(p, t))
    x[2] = np.nan
    acc.update(t[:3], x[:3])
    acc.update(t[3:], x[3:])
    assert acc.errors()["sup"] != acc.errors()["sup"]


def test_a_passed_record_with_nan_worst_is_failed():
    rec = vm.CheckResult("monotone", "op", "passed", worst=float("nan"), bound=1.0)
    assert rec.status == "failed" and "non-finite" in rec.message


def test_examples_zero_is_refused_not_passed():
    """``check_operator(x ↦ 2x, examples=0)`` reported "9 passed"; with examples it fails.  (A law by name through
    ``verimono.checks.run_law``, which registers the operator laws: run alone, this test once met a KeyError.)"""
    from verimono.checks import run_law

    rec = run_law("monotone", NSUB, seed=0, examples=3)
    assert rec.status == "passed" and rec.details["evaluations"] > 0
    with pytest.raises(InvalidCheckArgument, match="no operator law named 'monotonous'"):
        run_law("monotonous", NSUB, seed=0, examples=3)
    # the map x -> 2x with examples=0 used to report "9 passed"
    double = vm.operator_from_resolvent(lambda x, lam, t: 2 * np.asarray(x), 2, name="2x")
    with pytest.raises(InvalidCheckArgument):
        vm.check_operator(double, examples=0)
    assert not vm.check_operator(double, examples=5, seed=0).ok


# -- typed and validated: grids, sets and shapes that were a bare ValueError, a MemoryError or silence ----------

@pytest.mark.parametrize("build", [
    lambda g: vm.random_grid(1.0, -3),
    lambda g: vm.uniform_grid(1.0, 1e-12),                 # 10^12 cells: a MemoryError before
    lambda g: vm.refine(g, 0),                             # returned the grid's t_K alone before
    lambda g: vm.refine(g, 2.7),                           # refined by 2 before
    lambda g: vm.graded_grid(1.0, 0),
    lambda g: vm.random_grid(1.0, 3, seed=-1),
    lambda g: vm.uniform_grid("a", steps=2),
    lambda g: vm.uniform_grid(1.0, steps=True),
], ids=["negative steps", "1e12 cells", "factor 0", "factor 2.7", "zero cells", "negative seed", "T not a number",
        "bool steps"])
def test_bad_grid_arguments_are_invalid_grids(build):
    from verimono.core.errors import InvalidGrid

    with pytest.raises(InvalidGrid):
        build(vm.uniform_grid(1.0, steps=4))


def test_a_normal_cone_of_what_is_not_a_set_and_a_fractional_shape_are_invalid_problems():
    from verimono.core.errors import InvalidProblem

    with pytest.raises(InvalidProblem, match="NormalCone needs a convex set"):
        vm.NormalCone(3.0)                                 # an AttributeError before
    for shape in (3.5, (2, "a"), (2, 0), True):            # 3.5 gave R^3 silently before
        with pytest.raises(InvalidProblem, match="shape"):
            vm.operator_from_prox(lambda x, lam, t: x, shape=shape)
