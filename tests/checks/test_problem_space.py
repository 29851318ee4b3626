"""Problems are searched too (issue 42, item 3): the stepper battery draws its problems from
``verimono.strategies.stated_problems`` — n up to 50, f and u on every coordinate, x0 inside, on and within 1e-6
of the boundary of a moving domain, horizons other than 1 — deterministically from the seed, as many as the
profile's ``generated_subjects``.

The plants (tests/zoo_problem_space.py) are the paper's scheme except in a corner the references and the old
sample problems (all n ≤ 3, f in one n = 1 problem, x0 never on a moving boundary) never reached: each is seen
failing here, moved (another dimension), beside the same code with the fault off, which passes.
"""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

import verimono as vm
from verimono.checks.generated_problems import STRATA, generated_problem, generated_problems
from verimono.checks.stepper_battery import generated_count, stepper_checks
from verimono.core.errors import OutsideDomain
from verimono.execution.config import chosen
from verimono.records.results import FAILED, PASSED
from verimono.strategies.problems import NEAR, SIZES

from zoo_problem_space import drops_f, lags_time, lawful, on_boundary, skips_first_projection


def _dist(p, x, t=0.0):
    return float(np.linalg.norm(np.asarray(p.operator.project_domain(x, t), float) - x))


# -- the problems ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("seed", [0, 1])
def test_generated_problems_are_valid_where_their_recipe_says(seed):
    """Every stratum's promise, measured: the size class of n, f and u present and nonzero on every coordinate,
    ``lipschitz`` a true Lipschitz constant of f on random pairs, ``U`` the primitive of ``u``, x0 in
    ``cl dom F(0)`` — on its boundary for ``on`` (some coordinate step of 1e-7 leaves it), within
    ``NEAR`` inside or outside for ``near_*`` (outside only with the catching-up jump)."""
    rng = np.random.default_rng(seed)
    for i, p in enumerate(generated_problems(seed, len(STRATA))):
        placement, size, terms = STRATA[i]
        lo, hi = SIZES[size]
        assert lo <= p.dim <= hi and p.name.startswith(f"generated #{i} (seed {seed}): n={p.dim}, T=")
        assert (p.f is not None) == ("f" in terms.split("+")) and (p.u is not None) == ("u" in terms.split("+"))
        if p.f is not None:
            x, y = rng.normal(0, 3, (2, 50, p.dim))
            ratio = np.linalg.norm(p.f(x) - p.f(y), axis=1) / np.linalg.norm(x - y, axis=1)
            assert np.all(ratio <= p.lipschitz) and p.lipschitz > 0
            assert np.all(np.abs(p.f(np.zeros(p.dim))) > 0.1)            # f acts on every coordinate
        if p.u is not None:
            d = 1e-6 * p.T
            for a, b in ((0.0, d), (0.37 * p.T - d, 0.37 * p.T + d), (p.T - d, p.T)):   # U' = u, within [0, T]
                assert np.allclose((p.U(b) - p.U(a)) / (b - a), p.u(0.5 * (a + b)), atol=1e-5)
            assert np.all(np.abs([p.u(s) for s in np.linspace(0, p.T, 33)]) >= 0.25)   # on every coordinate
        d0 = _dist(p, p.x0)
        if placement == "near_outside":
            assert p.initial_jump and 0.5 * NEAR < d0 <= NEAR * 1.01
            with pytest.raises(OutsideDomain):
                p.replace(initial_jump=False)
        else:
            assert not p.initial_jump and d0 <= 1e-12 * (1 + np.linalg.norm(p.x0))
        if placement == "on":
            assert on_boundary(p.operator, p.x0)
        if placement == "near_inside":
            assert not on_boundary(p.operator, p.x0, eps=1e-9)
            # within NEAR of the boundary: a step of 2√n NEAR along some ±e_i (at most acos(1/√n) from the
            # outer normal) leaves the domain
            step = 2 * math.sqrt(p.dim) * NEAR
            assert max(_dist(p, p.x0 + s * step * e) for e in np.eye(p.dim) for s in (1, -1)) > 0


def test_generated_problems_span_the_space_the_issue_names():
    """Over ci's two rounds of draws (thorough draws 30): n from the small class to the large one (13–50),
    horizons other than 1, every placement, f and u present on more than half."""
    ps = generated_problems(0, 12)
    dims = [p.dim for p in ps]
    assert min(dims) <= 4 and max(dims) >= 13 and SIZES["large"][1] == 50
    assert len({round(p.T, 6) for p in ps}) >= 5 and any(p.T != 1.0 for p in ps)
    assert {p.name.split("x0 ")[1].split(",")[0] for p in ps} == {"inside", "on", "near inside", "near outside"}
    assert sum(p.f is not None for p in ps) >= 6 and sum(p.u is not None for p in ps) >= 6


def test_a_generated_problem_is_a_function_of_its_seed_and_index():
    """``generated_problem(s, i)`` rebuilt (cache cleared) is bit for bit the same problem, whatever was drawn in
    between; another seed draws another one."""
    a = generated_problem(3, 2)
    generated_problems(4, 3)
    generated_problem.cache_clear()
    b = generated_problem(3, 2)
    assert a is not b and a.name == b.name and np.array_equal(a.x0, b.x0) and a.T == b.T
    assert generated_problem(5, 2).name != a.name


@pytest.mark.slow
def test_a_generated_problem_does_not_depend_on_the_modules_imported_before():
    """hypothesis draws constants from the source of the local modules imported so far; the generator switches
    them off — the same problems in a fresh interpreter that imported the whole reference catalog first."""
    code = ("import sys, numpy as np\n"
            "if sys.argv[1] == 'catalog':\n    import verimono.reference; verimono.reference.catalog()\n"
            "from verimono.checks.generated_problems import generated_problems\n"
            "print([(p.name, float(np.sum(p.x0))) for p in generated_problems(0, 6)])\n")
    outs = [subprocess.run([sys.executable, "-c", code, arg], capture_output=True, text=True, check=True).stdout
            for arg in ("bare", "catalog")]
    assert outs[0] == outs[1] and "generated #5" in outs[0]


def test_the_profile_sets_how_many_are_drawn():
    """``generated=None`` is the profile's ``generated_subjects``: dev 3, ci 6, thorough 30."""
    for profile, count in (("dev", 3), ("ci", 6), ("thorough", 30)):
        with chosen(profile):
            assert generated_count() == count
    with chosen("ci"):
        names = [n for n, _ in stepper_checks(vm.solve, laws=["in_domain"], orders=False)]
    assert [n for n in names if "generated #" in n] == [f"in_domain[{p.name}]" for p in generated_problems(0, 6)]
    assert generated_count(2) == 2


# -- the plants: seen failing on generated problems, beside the lawful control --------------------------------

def _battery(stepper, seed, law):
    """``check_stepper``'s generated problems at the default profile, one law (the one that catches the plant)."""
    return vm.check_stepper(stepper, generated_problems(seed, generated_count()), laws=[law], orders=False,
                            seed=seed)


#: plant → (the law that catches it, the same code with the fault off)
PLANTS = {"drop_f1_from_n3": (drops_f(1, 3), "selections", lawful),
          "lag_time_from_n7": (lags_time(7), "selections", lawful),
          "skip_first_projection_on_boundary": (skips_first_projection(), "in_domain",
                                                skips_first_projection(when_on_boundary=False))}


def _dims(rep):
    return [int(r.subject.split("n=")[1].split(",")[0]) for r in rep.failures]


@pytest.mark.parametrize("name", PLANTS)
def test_each_plant_fails_the_generated_battery_beside_its_lawful_control(name):
    """At seed 0 and the default profile's count, the one law that catches each plant fails it — on generated
    problems in its corner (n ≥ 3 with f; n ≥ 7 with a moving operator; x0 on or within 1e-6 of a moving
    boundary) — and passes the same code with the fault off."""
    plant, law, control = PLANTS[name]
    rep = _battery(plant, 0, law)
    assert rep.failures and all(" on generated #" in r.subject for r in rep.failures), rep.summary()
    if name.startswith("drop_f"):
        assert min(_dims(rep)) >= 3
    elif name.startswith("lag"):
        assert max(_dims(rep)) >= 7
    else:
        assert any("x0 on" in r.subject for r in rep.failures)
        assert all("x0 on" in r.subject or "x0 near" in r.subject for r in rep.failures)
        assert rep.failures[0].counterexample["k"] == 1          # the unprojected first step
    assert _battery(control, 0, law).ok


@pytest.mark.slow
@pytest.mark.parametrize("plant, law, least", [(drops_f(1, 3), "selections", 3), (drops_f(2, 5), "selections", 5),
                                               (lags_time(7), "selections", 7), (lags_time(10), "selections", 10),
                                               (skips_first_projection(), "in_domain", 1)],
                         ids=["f1_n3", "f2_n5", "lag_n7", "lag_n10", "skip_first"])
def test_the_plants_moved_fail_at_seeds_0_to_2(plant, law, least):
    for seed in range(3):
        rep = _battery(plant, seed, law)
        assert rep.failures and max(_dims(rep)) >= least, (seed, rep.summary())
        assert _battery(lawful, seed, law).ok


def test_a_failing_record_names_the_recipe_that_replays_it():
    """The record's subject holds ``generated #i (seed s)``; ``generated_problem(s, i)`` given back to
    ``check_stepper`` reproduces the failure alone."""
    rep = vm.check_stepper(drops_f(1, 3), generated_problems(0, 3)[2:], laws=["selections"], orders=False)
    subject = rep.failures[0].subject.split(" on ", 1)[1]
    i, s = int(subject.split("#")[1].split(" ")[0]), int(subject.split("seed ")[1].split(")")[0])
    generated_problem.cache_clear()                      # rebuilt from the recipe, not the cached object
    again = vm.check_stepper(drops_f(1, 3), [generated_problem(s, i)], laws=["selections"], orders=False)
    assert (i, s) == (2, 0) and [r.subject for r in again.failures] == [rep.failures[0].subject]
    assert again.failures[0].worst == rep.failures[0].worst


# -- the laws on problems without an exact solution -------------------------------------------------------------

def test_laws_needing_an_order_use_the_claim_on_generated_problems():
    """A generated problem states no exact solution and no order.  ``in_domain`` of a scheme claiming only
    ``scheme="any"`` is held to its claimed order there: the first projection skipped on the boundary leaves a
    distance ``O(h)`` (0.6, 0.15, 0.0375 on 10, 40, 160 cells) — it fails a claim of order 2, meets a claim of
    order 1 (it does converge), and the same code projecting passes both.  ``convergence_order`` holds the
    proximal scheme to the general order 1/2 there, against a fine-grid reference (the problem states none)."""
    p = generated_problem(0, 0)
    assert p.exact is None and p.order is None and "x0 on" in p.name

    def in_domain(stepper, order):
        return vm.check_stepper(vm.Stepper(stepper, scheme="any", order=order), [p], laws=["in_domain"],
                                orders=False).results[0]

    skip, project = skips_first_projection(), skips_first_projection(when_on_boundary=False)
    assert in_domain(skip, 2).status == FAILED and in_domain(skip, 1).status == PASSED
    assert in_domain(project, 2).status == PASSED
    order = vm.check_stepper(vm.solve, [p], laws=False).results[0]       # every problem gets a verdict (issue 40):
    assert order.check == "convergence_order" and order.status == PASSED and "expected 0.5" in order.message


# -- the whole battery at the default profile ---------------------------------------------------------------------

@pytest.mark.slow
@pytest.mark.parametrize("plant", [drops_f(1, 2), drops_f(1, 3), lags_time(4), lags_time(7),
                                   skips_first_projection()],
                         ids=["drop_f_n2", "drop_f_n3", "lag_n4", "lag_n7", "skip_first"])
def test_the_plants_fail_check_stepper_at_seeds_0_to_2(plant):
    for seed in range(3):
        rep = vm.check_stepper(plant, seed=seed, orders=False)
        assert [r for r in rep.failures if " on generated #" in r.subject], (seed, rep.summary())


@pytest.mark.slow
def test_the_old_battery_was_blind_to_the_field_and_time_plants():
    """The references and the old sample problems (n ≤ 3, f only in n = 1) pass the f and time plants: they are
    caught by the generated problems alone."""
    from verimono.checks.sample_problems import sample_problems
    from verimono.reference import catalog

    old = list(catalog()) + sample_problems(0, 4)
    for plant in (drops_f(1, 3), lags_time(7)):
        assert vm.check_stepper(plant, old, orders=False).ok


def _readme_stepper(problem, t_grid):            # README.md's my_stepper, verbatim
    dU = problem.input_increments(np.asarray(t_grid))
    x = [problem.x0]
    for k in range(1, len(t_grid)):
        h = t_grid[k] - t_grid[k - 1]
        z = x[-1] + (h * problem.f(x[-1]) if problem.f is not None else 0.0)
        if dU is not None:
            z = z + dU[k - 1]
        x.append(problem.operator.resolvent(z, h, t_grid[k]))
    return np.array(x)


@pytest.mark.slow
@pytest.mark.parametrize("stepper", [_readme_stepper, vm.solve], ids=["my_stepper", "solve"])
def test_no_false_alarm_on_generated_problems_at_seeds_0_to_3(stepper):
    for seed in range(4):
        rep = vm.check_stepper(stepper, seed=seed, orders=False, profile="ci")
        assert not rep.failures and not [r for r in rep.results if r.status == "undecided"], rep.summary()


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_generated_problems_state_assumptions_that_hold(seed):
    """check_assumptions finds every stated φ, σ, θ holding (YB, not stated for a moving set, is expected to fail
    and says so): the constants the bounds laws use are true."""
    for p in generated_problems(seed, 6):
        rep = vm.check_assumptions(p, seed=seed)
        assert not rep.failures, (p.name, rep.summary())


def test_horizons_include_the_issue_examples():
    from verimono.strategies.problems import HORIZONS

    assert set(HORIZONS) == {0.3, 1.0, 2.5, 2 * math.pi}
