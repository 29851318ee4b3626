"""The trajectory laws: each seen failing on a broken stepper of the zoo (with a shrunk, reproducing
counterexample), none failing on verimono.solve over the reference catalog and 20 seeded problems, and
the bounds computed exactly as the paper's lemmas define them."""

from __future__ import annotations

import numpy as np
import pytest

from verimono import Problem, solve, uniform_grid
from verimono.checks import check_stepper
from verimono.checks.sample_problems import sample_problem
from verimono.checks.bounds import LGBounds, YBBounds, check_bounds_lg
from verimono.checks.stepper_battery import CHECKS, LAWS, reproduce, stepper_checks
from verimono.checks.trajectory_laws import check_contraction, check_in_domain
from verimono.reference import catalog, get
from verimono.records.results import FAILED, PASSED, SKIPPED

from zoo_steppers import BREAKS, ZOO, amplifier, drops_input, lagged_step, wrong_time

#: laws of the stepper as a whole or of its start: judged without a ratio (exact) resp. at node 0
WHOLE = {"unique_limit", "trajectory_immutable"}
STEP_LOCAL = [law for law in LAWS if law not in WHOLE | {"initial_value"}]


@pytest.mark.parametrize("law", LAWS)
def test_every_law_fails_on_a_zoo_member(law):
    member, ref, _ = BREAKS[law]
    problem = get(ref)
    rec = CHECKS[law](member, problem)
    assert rec.status == FAILED, str(rec)
    if law == "trajectory_immutable":          # exact: no ratio, the findings instead
        assert rec.worst is None and rec.counterexample["findings"]
    else:
        assert rec.worst > rec.bound == 1.0
    cx = rec.counterexample
    assert cx["problem"] == ref and "x0" in cx
    again = reproduce(member, problem, rec)            # the counterexample alone reproduces the failure
    assert again.status == FAILED, str(again)
    if law in STEP_LOCAL:
        assert cx["shrunk"] is True                   # shrunk to the shortest failing prefix [0, t_k]
        assert len(cx["grid"]) == cx["k"] + 1 <= 161 and cx["T"] == pytest.approx(cx["grid"][-1])
        assert reproduce(solve, problem, rec).status != FAILED   # same inputs, correct stepper: no failure
    elif law == "initial_value":                      # shrunk to one cell: x_0 is judged at node 0
        assert cx["shrunk"] is True and len(cx["grid"]) == 2 and cx["k"] == 0
        assert reproduce(solve, problem, rec).status != FAILED
    elif law == "trajectory_immutable":               # its two partitions, which reproduce it
        assert len(cx["grids"]) == 2 and reproduce(solve, problem, rec).status != FAILED
    else:
        assert len(cx["distances"]) == len(cx["levels"]) and cx["distances"][-1] > 0.5 * max(cx["distances"][:-1])


def test_other_zoo_members_are_caught_too():
    assert check_in_domain(wrong_time, get("translating ball")).status == FAILED
    assert CHECKS["selections"](drops_input, get("Lipschitz field and input")).status == FAILED
    # h_k instead of h_{k+1}: invisible on a uniform partition, caught on a nonuniform one
    p = get("linear x' = -Mx")
    assert CHECKS["selections"](lagged_step, p, grids={"uniform": uniform_grid(p.T, steps=40)}).status == PASSED
    assert CHECKS["selections"](lagged_step, p).status == FAILED
    for member in ZOO:   # every member of the zoo is caught by some law on some reference
        assert any(CHECKS[law](member, q).status == FAILED for q in catalog()[:12] for law in LAWS), member


def test_in_domain_takes_resolvent_witnesses_and_measures_the_rest_exactly():
    """``dist(x_k, dom F) <= |x_k - J(x_k + mu y_k)|`` (a resolvent's value lies in dom F): a correct run is
    measured exactly at x_0 only, and its bounds are the exact distances up to round-off; a stepper off the
    domain is measured exactly where its witness is far, so its distance is the projection's."""
    p = get("translating ball")
    rec = check_in_domain(solve, p, grids=[uniform_grid(p.T, steps=40)])
    assert rec.status == PASSED and rec.details["measured_nodes"] == 1
    assert rec.details["max_distance"] < 1e-12
    bad = check_in_domain(wrong_time, p, grids=[uniform_grid(p.T, steps=40)])
    assert bad.status == FAILED and bad.details["measured_nodes"] >= 1
    cx = bad.counterexample
    exact = float(np.linalg.norm(np.asarray(cx["projection"]) - np.asarray(cx["x_k"])))
    assert cx["distance"] == pytest.approx(exact, rel=1e-12)


def test_witness_steps_are_powers_of_two_below_half_the_step_shared_by_each_octave():
    """``μ_k`` is the power of two in ``(h_k/4, h_k/2]`` (never the scheme's own step, round-off within the
    states'), so a partition whose steps span ``r`` octaves needs at most ``r + 1`` distinct resolvent steps."""
    from verimono.checks.trajectory_laws import witness_steps
    from verimono.core.grids import graded_grid, random_grid

    for t in (random_grid(9.4, 160, seed=3), graded_grid(9.4, 160), uniform_grid(1.0, steps=3)):
        h, mu = np.diff(t), witness_steps(t)
        assert np.all(h / 4 < mu) and np.all(mu <= h / 2)
        assert np.all(np.frexp(mu)[0] == 0.5)                      # exactly powers of two
        octaves = np.log2(h.max() / h.min())
        assert len(np.unique(mu)) <= np.floor(octaves) + 2


def test_unique_limit_refines_past_meshes_coarser_than_the_problem():
    """A thorough hypothesis run found this false alarm: x' ∈ −∂(2|x|) from x0 = 1/32 dies out at t = 1/64,
    so every partition of mesh 0.1 or 0.025 gives 0 from its first cell on: distances 0, 0, then c·h at
    K = 160, which is not 'approaching' until a finer level shows the distance falling."""
    from verimono import NormSubdifferential
    from verimono.checks.limits import check_unique_limit

    p = Problem(NormSubdifferential(2.0, dim=1), [0.03125], 1.0, name="dies out at t = 1/64")
    rec = check_unique_limit(solve, p)
    assert rec.status == PASSED, str(rec)
    D = rec.details["distances"]
    assert D[:2] == [0.0, 0.0] and len(D) > 3 and D[-1] <= 0.5 * max(D[:-1])
    # a stepper with no unique limit still fails, however far the levels are refined
    assert check_unique_limit(BREAKS["unique_limit"][0], p).status == FAILED


def test_unique_limit_assumes_no_rate():
    """x' ∈ −∂(c(t)|x|), c = 0.1 t^(−0.9) (σ ∈ L¹ unbounded; exact 2 − t^0.1): the scheme converges like
    0.943 h^0.1, and the uniform and graded partitions drift apart until K ≈ 1000.  The old law (distance
    must halve per 16-fold refinement, an assumed rate 1/4) failed here; the Cauchy criterion with each
    sequence's own tail passes, while the error against the exact solution falls."""
    from verimono.reference.subdifferential import slow_rate
    from verimono.checks.limits import check_unique_limit
    from verimono import uniform_grid as ug

    p = slow_rate()
    rec = check_unique_limit(solve, p)
    assert rec.status == PASSED, str(rec)
    D = rec.details["distances"]
    assert D[0] < D[1] < D[2], D                                    # the partitions do drift apart
    assert D[-1] > 0.5 * max(D[:-1])                                # what the assumed rate rejected
    r = rec.details["ratios"]
    assert 4 ** -0.25 < r["uniform"] < 1.0, r                       # 4^-0.1 = 0.87: a rate near 0.1
    errs = [float(np.max(np.abs(solve(p, ug(1.0, steps=K)).x[:, 0] - (2.0 - ug(1.0, steps=K) ** 0.1))))
            for K in (10, 40, 160)]
    assert errs[0] > errs[1] > errs[2] and abs(errs[2] / (0.943 * (1 / 160) ** 0.1) - 1) < 0.05, errs
    # the zoo's member with different limits per partition kind is still caught, on this problem too
    bad = check_unique_limit(BREAKS["unique_limit"][0], get(BREAKS["unique_limit"][1]))
    assert bad.status == FAILED and "different limits" in bad.message, str(bad)
    assert bad.counterexample["tails"] and bad.counterexample["pair"]
    # two levels give one difference per kind: a third is added (the tail needs a ratio)
    assert check_unique_limit(solve, get("t|x| (n=1)"), levels=(10, 40)).details["levels"] == [10, 40, 160]


def test_contraction_runs_its_starts_in_one_batch_and_falls_back_when_a_batch_is_wrong():
    """solve declares batches: x0 and the perturbed starts run as one (B, n) solve.  A user's resolvent that
    takes the norm of the whole batch instead of each row changes the batch's first row, so the check
    notices and runs every start on its own (same verdict as the separate runs)."""
    from verimono import operator_from_resolvent
    from verimono.checks.trajectory_laws import perturbed_starts, run_starts

    calls = []

    def counted(problem, grid):
        calls.append(problem.x0.shape)
        return solve(problem, grid)

    counted.batched = True
    p = get("translating ball")
    assert check_contraction(counted, p).status == PASSED
    assert all(len(shape) == 2 for shape in calls[1::2])      # per grid: x0 alone, then one batch

    def whole_batch_shrink(x, lam, t):         # ∂(|x|) row-wise for one point, wrong for a batch
        x = np.asarray(x, dtype=float)
        nrm = np.linalg.norm(x)
        return x * max(1.0 - lam / nrm, 0.0) if nrm > 0 else x

    q = Problem(operator_from_resolvent(whole_batch_shrink, 2, project_domain=lambda x, t: x), [1.0, 2.0], 1.0)
    grid = uniform_grid(1.0, steps=20)
    x = solve(q, grid)
    starts = perturbed_starts(q)
    separate = [solve(Problem(q.operator, z, 1.0), grid).x for z in starts]
    np.testing.assert_array_equal(np.stack(run_starts(solve, q, starts, grid, x.x)), np.stack(separate))
    assert check_contraction(solve, q).status == PASSED


@pytest.fixture(scope="module")
def solve_on_catalog():
    return check_stepper(solve, catalog(), orders=False)


def test_no_false_alarm_on_the_catalog(solve_on_catalog):
    assert solve_on_catalog.ok, "\n".join(map(str, solve_on_catalog.failures))
    assert len(solve_on_catalog) == len(catalog()) * len(LAWS)
    for law in LAWS:     # every law actually ran on some reference (not all skipped)
        assert any(r.status == PASSED for r in solve_on_catalog.by_check(law)), law


@pytest.mark.parametrize("seed", range(20))
def test_no_false_alarm_on_generated_problems(seed):
    p = sample_problem(seed)
    recs = [CHECKS[law](solve, p, seed=seed) for law in LAWS]
    assert not [r for r in recs if r.status == FAILED], [str(r) for r in recs if r.status == FAILED]
    assert sum(r.status == PASSED for r in recs) >= 4


def test_lemma_constants_are_the_papers():
    # t|x| from x0 = 1 on [0, 2]: φ ≡ 0, σ(s) = s: α = 1, ∫σ = 2, β = 1 + 2·2 = 5, γ = 5, ψ(t) = t + 3t²
    lg = LGBounds(1.0, lambda s: 0.0, lambda s: s, 2.0)
    assert (lg.alpha, lg.beta, lg.gamma) == pytest.approx((1.0, 5.0, 5.0))
    assert lg.psi_nodes(np.array([0.0, 1.0, 2.0])) == pytest.approx([0.0, 4.0, 14.0])
    # (YB) with θ(s) = s: α = 2(θ(2) - θ(0)) + |F^0(0, x0)| = 4 + 0, β = 1 + 4·2, ψ(t) = 4t
    p = get("t|x| (n=1)")
    yb = YBBounds(p.x0, p.theta, p.operator, p.T)
    assert (yb.alpha, yb.beta) == pytest.approx((4.0, 9.0))
    # with an input (lemma l:extinput): φ̄ = φ + ∫|u|, σ̄ = σ(1 + ∫_0^T|u|)
    lgu = LGBounds(1.0, lambda s: 0.0, lambda s: 1.0, 1.0, absu=lambda s: 2.0)
    assert lgu.alpha == pytest.approx(3.0) and lgu.beta == pytest.approx(3.0 + 2.0 + 4.0 * 3.0)
    # on a given partition ∫σ becomes the right Riemann sum Σ h_k σ(t_k) the proof actually bounds
    on_grid = LGBounds(1.0, lambda s: 0.0, lambda s: s, 2.0, grid=np.array([0.0, 1.0, 2.0]))
    assert on_grid.beta == pytest.approx(1.0 + (1.0 + 1.0) * (1.0 * 1.0 + 1.0 * 2.0))   # α + (1+α) Σ h σ = 7
    assert on_grid.psi_nodes(np.array([0.0, 1.0, 2.0])) == pytest.approx([0.0, 1 + 8 * 1, 2 + 8 * 3])


def test_bounds_lg_hold_on_the_example_with_oscillating_sigma():
    """σ(t) = max(-sin t, 0): the discrete |x_k| is a right Riemann sum of σ and exceeds ∫σ on some grids;
    the partition's own Riemann sum bounds it (no false alarm), as the proof of lem:bndSeq gives."""
    from verimono.reference.lcs_example import sine_problem

    assert check_bounds_lg(solve, sine_problem()).status == PASSED


def test_contraction_with_lipschitz_field_uses_exp_Lt():
    """The explicit ``f`` of sample_problem(7) (``f(x) = Bx + b`` in a static ball) expands differences: the
    step-wise law holds with the declared ``L = ‖B‖₂`` (factor ``1 + hL ≤ e^{hL}``) and fails with ``L = 0``
    — the ``e^{Lt}`` allowance is needed, not decorative."""
    p = sample_problem(7)
    assert p.f is not None and p.lipschitz > 0
    rec = check_contraction(solve, p)
    assert rec.status == PASSED and rec.details["L"] == p.lipschitz
    assert rec.worst <= 1.0 and rec.details["global_ratio"] <= 1.0
    understated = check_contraction(solve, Problem(p.operator, p.x0, p.T, f=p.f, lipschitz=0.0, name="L = 0"))
    assert understated.status == FAILED and understated.worst > 1.0, str(understated)
    assert check_contraction(amplifier, p).status == FAILED


def test_psi_interpolant_hits_the_nodes():
    p = get("t|x| (n=1)")
    t = uniform_grid(p.T, steps=10)
    tr = solve(p, t)
    psi = lambda s: s + 3 * s * s  # noqa: E731
    assert tr.interpolate(t, kind="psi", psi=psi) == pytest.approx(tr.x)     # e:x delta at tk


def test_skips_say_why():
    rec = CHECKS["bounds_lg"](solve, get("static ball, x0 outside (jump)"))
    assert rec.status == SKIPPED and "closure" in rec.message


def test_battery_generator_is_the_runners():
    names = [n for n, _ in stepper_checks(solve, [get("t|x| (n=1)")])]
    assert names == ["convergence_order[t|x| (n=1)]"] + [f"{law}[t|x| (n=1)]" for law in LAWS]
    rep = check_stepper(amplifier, [get("t|x| (n=1)")])
    assert [r.check for r in rep] == ["convergence_order"] + list(LAWS)
    assert {r.check for r in rep.failures} >= {"contraction", "bounds_lg", "bounds_yb", "selections"}


@pytest.mark.slow
@pytest.mark.parametrize("law", ["bounds_lg", "bounds_yb", "psi_interpolation"])
def test_bound_laws_fail_on_generated_problems_with_the_breaking_stepper(law):
    """The properties of verimono.properties.laws_trajectories, fed the zoo stepper that breaks the law
    (BREAKS), find a generated problem on which the law fails — the generated problems state σ/θ/φ, so the
    a-priori bounds are actually checked there, not skipped."""
    from verimono.properties.laws_trajectories import law_property

    member = BREAKS[law][0]
    with pytest.raises(AssertionError, match=f"FAILED +{law}"):
        law_property(law, stepper=member, examples=30, derandomize=True)()
    law_property(law, examples=30, derandomize=True)()           # the same search on solve finds nothing


def test_contraction_admits_an_implicit_lipschitz_term():
    """x_{k+1} = J(x_k + h f(x_{k+1})) contracts with 1/(1 - hL) > e^{hL} per step: a correct stepper that a
    factor e^{hL} alone flagged (1.003 on this problem), still e^{Lt} in the limit; an amplifier still fails."""
    from verimono import NormSubdifferential

    def implicit_f(problem, t_grid):
        x = [problem.x0]
        for k in range(1, len(t_grid)):
            h, y = t_grid[k] - t_grid[k - 1], x[-1]
            for _ in range(200):                          # fixed point: hL = 2h < 1
                y = problem.operator.resolvent(x[-1] + h * problem.f(y), h, t_grid[k])
            x.append(y)
        return np.array(x)

    p = Problem(NormSubdifferential(0.5, dim=2), [1.0, 0.5], 1.0, f=lambda x: 2.0 * x, lipschitz=2.0,
                name="expanding f")
    assert check_contraction(implicit_f, p).status == PASSED
    assert check_contraction(solve, p).status == PASSED
    assert check_contraction(amplifier, p).status == FAILED


def test_yb_bounds_skip_where_f0_overflows_at_the_edge_of_the_domain():
    """x0 = 7e-304 for x' = c/x: |F^0(0, x0)| = c/x0 overflows, so lem:bndSeqYB's α is infinite — the
    bounds say nothing there and the laws are skipped with the reason (found by a dev-profile search,
    which saw bounds_yb fail with ψ = nan and psi_interpolation raise)."""
    import verimono as vm
    from verimono.checks.bounds import check_bounds_yb, check_psi_interpolation

    p = vm.Problem(vm.LogBarrier(1.0), [7e-304], 1.0, theta=lambda s: 0.0, name="c/x at the edge")
    for check in (check_bounds_yb, check_psi_interpolation):
        rec = check(vm.solve, p)
        assert rec.status == "skipped", rec
    assert "not finite" in check_bounds_yb(vm.solve, p).message


def test_selections_names_the_discrete_velocity_and_first_a_state_outside_the_domain():
    """Issue 23, item 4: the message names the quantity tested — the discrete velocity with the f and u terms
    the problem has, and their values — and, when x_(k+1) lies outside dom F, says so first."""
    rec = CHECKS["selections"](drops_input, get("Lipschitz field and input"))
    assert rec.status == FAILED
    assert "discrete velocity y = (x_k + h f(x_k) + ∫u - x_(k+1))/h" in rec.message, rec.message
    assert "f(x_k) = [" in rec.message and "∫u = [" in rec.message
    assert rec.counterexample["velocity"] == "(x_k + h f(x_k) + ∫u - x_(k+1))/h"
    plain = CHECKS["selections"](wrong_time, get("t|x| (n=1)"))
    assert plain.message.startswith("the discrete velocity y = (x_k - x_(k+1))/h = "), plain.message
    from verimono import NormalCone, sets

    ball = Problem(NormalCone(sets.Ball([0.0, 0.0], 1.0)), [0.5, 0.0], 1.0, name="unit ball")
    tripled = lambda p, t: np.asarray(solve(p, t)) * np.r_[1.0, [3.0] * (len(t) - 1)][:, None]   # noqa: E731
    out = CHECKS["selections"](tripled, ball)
    assert out.status == FAILED and out.message.startswith("x_(k+1) = [1.5 0. ] lies outside"), out.message
    assert "outside cl dom F" in out.message.split(";")[0] and out.counterexample["distance_to_domain"] > 0
    assert CHECKS["selections"](solve, get("moving box")).message.startswith("the discrete velocity (x_k")


# -- initial_value (issue 40): every trajectory starts at x0 -------------------------------------------------------

def _start_off(rel, dtype=np.float64):
    """``verimono.solve`` returned in ``dtype`` with ``x_0 = x0 (1 + rel)`` (``rel`` relative to ``|x0|``)."""
    def stepper(problem, t_grid):
        x = np.array(solve(problem, t_grid).x, dtype=dtype)
        x[0] = (problem.x0 * (1.0 + rel)).astype(dtype)
        return x
    stepper.__name__ = f"start_off_{rel:g}_{np.dtype(dtype).name}"
    return stepper


def test_initial_value_fails_on_a_start_other_than_x0_with_a_one_cell_counterexample():
    from verimono.checks.trajectory_laws import check_initial_value
    from zoo_steppers import projected_start, scaled_start, starts_at_zero

    p = get("t|x| (n=1)")
    for member in (scaled_start, starts_at_zero):
        rec = check_initial_value(member, p)
        assert rec.status == FAILED, str(rec)
        cx = rec.counterexample
        assert cx["shrunk"] and len(cx["grid"]) == 2 and "x_0 = " in rec.message, rec.message
        assert reproduce(member, p, rec).status == FAILED
    # x0 outside dom F(0): verimono.solve returns x_0 = x0 and jumps in the first step, so x_0 = x0 is the law
    # there too, and a stepper returning the projection of x0 as x_0 fails; where x0 lies in the domain it is x0
    jump = get("static ball, x0 outside (jump)")
    assert np.array_equal(solve(jump, uniform_grid(jump.T, steps=4)).x[0], jump.x0)
    assert check_initial_value(solve, jump).status == PASSED
    assert check_initial_value(projected_start, jump).status == FAILED
    assert check_initial_value(projected_start, get("static ball, x0 inside")).status == PASSED


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_initial_value_tolerance_is_the_subjects_precision_relative_to_x0(dtype):
    """|x_0 - x0|_∞ ≤ rtol(dtype)·|x0|_∞ (+ the precision's smallest normal number): 1.02 times it fails,
    0.98 times it passes, a float32 stepper judged at float32's rtol (its rounding of x0 alone is 6e-8)."""
    from verimono.checks.trajectory_laws import check_initial_value
    from verimono.core.tolerances import rtol_for

    rtol = rtol_for(np.dtype(dtype).name)
    p = get("translating ball")                              # x0 = (0.3, 0.6): |x0|_∞ = 0.6
    assert check_initial_value(_start_off(0.0, dtype), p).status == PASSED
    over = check_initial_value(_start_off(1.02 * rtol, dtype), p)
    assert over.status == FAILED and 1.0 < over.worst < 1.03, str(over)
    under = check_initial_value(_start_off(0.98 * rtol, dtype), p)
    assert under.status == PASSED and 0.97 < under.worst < 1.0, str(under)
    assert under.details["dtype"] == np.dtype(dtype).name


# -- trajectory_immutable (issue 42): a returned trajectory never changes after later calls ------------------------

def test_trajectory_immutable_fails_on_shared_buffers_mutated_inputs_and_aliases():
    from verimono.checks.trajectory_laws import check_trajectory_immutable
    from zoo_steppers import at_rest_view, mutates_grid, mutates_x0, shared_buffer

    p = get("t|x| (n=1)")
    cases = {shared_buffer: "changed when", mutates_grid: "t_grid", mutates_x0: "problem.x0"}
    for member, said in cases.items():
        rec = check_trajectory_immutable(member, p)
        assert rec.status == FAILED and said in rec.message, str(rec)
        assert reproduce(member, p, rec).status == FAILED
        assert rec.counterexample["problem"] == p.name and len(rec.counterexample["grids"]) == 2
    assert p.x0[0] == 1.0                                    # the battery's problem is never handed to a mutator
    rest = get("static ball, x0 inside")                     # at rest: every grid gives the same values
    assert "memory of problem.x0" in check_trajectory_immutable(at_rest_view, rest).message
    assert "memory of" in check_trajectory_immutable(shared_buffer, rest).message   # same values, one buffer
    one = {"given": uniform_grid(p.T, steps=8)}             # one partition given: run twice on it
    assert "memory of the array call 1 returned" in check_trajectory_immutable(shared_buffer, p, grids=one).message
    assert check_trajectory_immutable(solve, p, grids=one).details["calls"] == 2
    grid_view = lambda problem, t: np.asarray(t)[:, None]    # noqa: E731 - the states in the grid's memory
    assert "memory of t_grid" in check_trajectory_immutable(grid_view, p).message
    # the lawful controls: the same steppers returning a fresh array and leaving their inputs alone
    for control in (solve, lambda q, t: shared_buffer(q, t).copy(), lambda q, t: np.array(at_rest_view(q, t))):
        for q in (p, rest):
            assert check_trajectory_immutable(control, q).status == PASSED


def test_a_shared_buffer_does_not_corrupt_the_other_laws():
    """A law holding one run while it runs the stepper again (contraction's second starts) judges the values
    the stepper returned, not what a later call wrote into the same buffer: the amplifier writing into one
    buffer passed contraction (both runs were the one array, at distance 0) and fails it now, as it does alone."""
    from zoo_steppers import amplifier, shared_buffer

    buffers = {}

    def amplified_in_one_buffer(problem, t_grid):
        x = amplifier(problem, t_grid)
        buf = buffers.setdefault(x.shape, np.empty(x.shape))
        buf[...] = x
        return buf

    p = get("linear x' = -Mx")
    assert check_contraction(amplifier, p).status == FAILED
    assert check_contraction(amplified_in_one_buffer, p).status == FAILED
    assert check_contraction(shared_buffer, p).status == PASSED       # the scheme's values: they contract


# -- in_domain for scheme="any" (issue 40 item 5): a distance that does not shrink fails at every order -------------

RESTING = Problem(__import__("verimono").NormalCone(__import__("verimono").sets.Ball([0.0, 0.0], 1.0)),
                  [0.6, 0.8], 1.0, name="at rest on the unit sphere")


def _pushed_out(order, shrinks, finest=1.0):
    """The solution at rest on the unit sphere, every x_k (k ≥ 1) pushed radially out by ``eps(K)``: its distance to
    the ball.  ``eps = C (160/K)^order`` (shrinks like ``h^order``) or ``C`` (does not shrink): equal at K = 160;
    ``finest`` multiplies the distance on the finest level only."""
    def fn(problem, t):
        K = len(t) - 1
        eps = 1e-3 * ((160.0 / K) ** order if shrinks else 1.0) * (finest if K == 160 else 1.0)
        x = np.array(solve(problem, t).x)
        x[1:] *= 1.0 + eps
        return x
    import verimono as vm

    return vm.Stepper(fn, scheme="any", order=order, name=f"pushed out, order {order}")


@pytest.mark.parametrize("order", [0.5, 1.0, 2.0])
def test_in_domain_fails_a_distance_that_does_not_shrink_at_every_claimed_order(order):
    """A user saw distances 0.411, 0.466, 0.460 pass for order 1/2: the bound 2·4^-1/2 = 1 allowed them.  The
    same distance at K = 160, shrinking like h^order before it, passes; constant, it fails."""
    still = check_in_domain(_pushed_out(order, False), RESTING)
    assert still.status == FAILED and still.worst > 1.99, str(still)
    assert "does not vanish at order" in still.message
    lawful = check_in_domain(_pushed_out(order, True), RESTING)
    assert lawful.status == PASSED and lawful.worst == pytest.approx(0.5, rel=1e-3), str(lawful)
    D = lawful.details["distances"]
    assert D[-1] == pytest.approx(still.details["distances"][-1], rel=1e-9)        # the same finest distance


@pytest.mark.parametrize("order", [0.5, 1.0, 2.0])
def test_in_domain_rate_is_judged_at_its_stated_slack(order):
    """The finest distance at 1.02 resp. 0.98 times what the claimed order predicts times the slack."""
    from verimono.core.tolerances import DOMAIN_ORDER_SLACK as S

    assert check_in_domain(_pushed_out(order, True, finest=1.02 * S), RESTING).status == FAILED
    assert check_in_domain(_pushed_out(order, True, finest=0.98 * S), RESTING).status == PASSED


def _grows_then_falls(order):
    """The resting problem's distance ``1e-3 (160/K)^order`` from K = 40 on, but 1e-5 at K = 10: it grows before it
    falls (pre-asymptotic), so the constant is fitted on K = 40, which at order 1/2 needs a level of 640 cells."""
    import verimono as vm

    def fn(problem, t):
        K = len(t) - 1
        x = np.array(solve(problem, t).x)
        x[1:] *= 1.0 + (1e-5 if K == 10 else 1e-3 * (160.0 / K) ** order)
        return x
    return vm.Stepper(fn, scheme="any", order=order, name=f"grows then falls, order {order}")


def test_in_domain_refines_past_a_distance_that_grows_before_it_falls_and_is_undecided_below_order_quarter():
    rec = check_in_domain(_grows_then_falls(0.5), RESTING)
    assert rec.status == PASSED and rec.details["levels"] == [10, 40, 160, 640], str(rec)
    assert rec.details["fitted_on"] == [10, 40] and rec.worst == pytest.approx(0.5, rel=1e-3)
    # order 0.2: even 2560 cells predict a fall of 256^0.2 = 3.0 from K = 10, under 2·S = 4: a distance that
    # does not shrink cannot be refuted there, and is never passed
    low = check_in_domain(_pushed_out(0.2, False), RESTING)
    assert low.status == "undecided" and low.details["levels"][-1] == 2560, str(low)
    assert check_in_domain(_pushed_out(0.25, False), RESTING).status == FAILED     # 256^0.25 = 4: refuted
    assert check_in_domain(_pushed_out(0.25, True), RESTING).status == PASSED


def test_in_domain_keeps_correct_order_half_schemes_passing():
    """The midpoint scheme claiming order 1/2 on the catalog: its iterates lie off the domain at the nodes, at
    distances that vanish (verimono.solve's lie in it: the slow test below, with every valid alternative)."""
    import verimono as vm
    from zoo_steppers import midpoint_time

    s = vm.Stepper(midpoint_time, scheme="any", order=0.5)
    recs = [check_in_domain(s, q) for q in catalog()]
    assert all(r.status == PASSED for r in recs), [str(r) for r in recs if r.status != PASSED]
    assert max(r.details["distances"][0] for r in recs) > 1e-3           # distances to speak of, not round-off


@pytest.mark.slow
def test_in_domain_keeps_every_valid_alternative_passing_at_low_orders():
    """verimono.solve and every valid alternative claiming order 1/4, 1/2 and 1, on the catalog and 8 sample
    problems (measured: worst ratio 0.503, midpoint at order 1; levels refined to 2560 at order 1/4 only)."""
    import verimono as vm
    from zoo_steppers import VALID_ALTERNATIVES

    problems = catalog() + [sample_problem(s) for s in range(8)]
    for fn in [solve, *VALID_ALTERNATIVES]:
        for order in (0.25, 0.5, 1.0):
            s = vm.Stepper(fn, scheme="any", order=order)
            for q in problems:
                if fn.__name__ == "exact_sampled" and q.exact is None:
                    continue
                rec = check_in_domain(s, q)
                assert rec.status == PASSED, str(rec)


def test_the_unique_limits_interpolant_is_np_interp_of_every_coordinate_at_once():
    """``unique_limit`` interpolated column by column (one ``np.interp`` call per coordinate: 840 000 calls at
    n = 10^4); the interpolant of all coordinates at once is the same, node values exact, constant outside."""
    from verimono.checks.limits import _distances, _interp

    rng = np.random.default_rng(3)
    t = np.concatenate([[0.0], np.sort(rng.uniform(0, 1, 18)), [1.0]])
    x = rng.normal(size=(20, 7))
    tau = np.concatenate([rng.uniform(-0.1, 1.1, 300), t])
    ref = np.stack([np.interp(tau, t, x[:, j]) for j in range(7)], axis=-1)
    assert np.allclose(_interp(t, x, tau), ref, rtol=0, atol=1e-14) and np.array_equal(_interp(t, x, t), x)
    g2 = np.linspace(0, 1, 9)
    x2 = rng.normal(size=(9, 7))
    want = np.linalg.norm(ref - np.stack([np.interp(tau, g2, x2[:, j]) for j in range(7)], axis=-1), axis=-1)
    assert np.allclose(_distances(t, x, g2, x2, tau), want, rtol=1e-13, atol=1e-14)


@pytest.mark.parametrize("slow", ["_cells", "_norms"])
def test_unique_limit_stopped_in_the_harness_is_undecided_not_a_stepper_that_never_returns(slow, monkeypatch):
    """At n = 10^6 unique_limit spent its budget in its own comparisons of the stepper's (correct, returned)
    solutions, stated no progress, and the budget's verdict counted the whole law as one call of the stepper that
    never returned: failed.  Every run that returns is now progress, so a law stopped in the harness is undecided.
    (Here the harness is slowed down, at two places of its comparisons, instead of run at n = 10^6.)"""
    import time as _time

    import verimono.checks.limits as limits
    from verimono.execution.timeouts import budget
    from verimono.reference import subdifferential

    real = getattr(limits, slow)

    def slowed(*args, **kwargs):
        _time.sleep(0.05)
        return real(*args, **kwargs)

    monkeypatch.setattr(limits, slow, slowed)
    with budget(0.6):
        (rec,) = check_stepper(solve, [subdifferential.t_norm((0.6, -0.8))], laws=["unique_limit"], orders=False,
                               generated=0).results
    assert rec.check == "unique_limit" and rec.status == "undecided", rec
    assert rec.details.get("undecided_reason") == "time budget" and rec.details["evaluated"] >= 3, rec.details


def _peak_bytes(fn):
    import tracemalloc

    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_unique_limits_distances_are_formed_in_cache_sized_blocks(monkeypatch):
    """Work linear in n, in blocks: ``_distances`` of two solutions of n = 20 000 coordinates holds at most a few
    blocks of ``BLOCK_ELEMENTS`` (or one time's n) numbers at once, never all the times' interpolated states;
    its values are the distances of the two ``np.interp`` interpolants.  With the former block (``1 << 22``
    numbers, every time at once here) the same call holds ten times more: the bound can fail."""
    import verimono.checks.limits as limits

    rng = np.random.default_rng(5)
    n = 20_000
    ga, gb = np.linspace(0.0, 1.0, 11), np.sort(np.r_[0.0, rng.uniform(0.0, 1.0, 39), 1.0])
    xa, xb = rng.normal(size=(11, n)), rng.normal(size=(41, n))
    tau = np.union1d(ga, gb)[1:]
    got = limits._distances(ga, xa, gb, xb, tau)
    cols = slice(0, n, 997)
    ia = np.stack([np.interp(tau, ga, xa[:, j]) for j in range(n)[cols]], axis=-1)
    ib = np.stack([np.interp(tau, gb, xb[:, j]) for j in range(n)[cols]], axis=-1)
    sub = limits._distances(ga, xa[:, cols], gb, xb[:, cols], tau)
    assert np.allclose(sub, np.linalg.norm(ia - ib, axis=-1), rtol=1e-13, atol=0.0)
    assert got.shape == tau.shape and np.all(got > 0.0)
    bound = 6 * max(limits.BLOCK_ELEMENTS, n) * 8 + 64 * tau.size
    assert _peak_bytes(lambda: limits._distances(ga, xa, gb, xb, tau)) <= bound
    monkeypatch.setattr(limits, "BLOCK_ELEMENTS", 1 << 22)
    assert _peak_bytes(lambda: limits._distances(ga, xa, gb, xb, tau)) > bound


def test_pair_norms_and_witness_keys_do_not_copy_the_trajectory(monkeypatch):
    """``psi_interpolation``'s pair differences are formed ``PAIR_BLOCK`` numbers at a time, and the key of the
    resolvent witnesses fingerprints the states without a copy of them (``tobytes`` held the whole trajectory):
    at n = 20 000 and 60 times each holds a small part of the 9.6 MB of the states; the former block
    (``PAIR_ELEMENTS``) holds them all."""
    import verimono.checks.bounds as bounds
    from verimono.checks.shared_runs import fingerprint

    rng = np.random.default_rng(6)
    X = rng.normal(size=(60, 20_000))
    i, j = (a[:40] for a in np.triu_indices(60, 1))
    want = np.linalg.norm(X[j] - X[i], axis=-1)
    assert np.allclose(bounds._pair_norms(X, i, j), want, rtol=1e-13, atol=0.0)
    small = X.nbytes // 4
    assert _peak_bytes(lambda: bounds._pair_norms(X, i, j)) <= small
    assert _peak_bytes(lambda: fingerprint(X)) <= 4096
    Y = X.copy()
    Y[3, 7] += 1.0
    assert fingerprint(X) == fingerprint(X.copy()) and fingerprint(X) != fingerprint(Y)
    monkeypatch.setattr(bounds, "PAIR_BLOCK", bounds.PAIR_ELEMENTS)
    assert _peak_bytes(lambda: bounds._pair_norms(X, i, j)) > small


@pytest.mark.slow
def test_the_stepper_battery_never_forms_an_n_by_n_array(monkeypatch):
    """Per-node work linear in n, counted in memory: the whole battery (9 laws, ``orders=False``) at n = 4000 holds
    at most 16 trajectories' worth of numbers at once (161 × n doubles is 5 MB; measured 42 MB; an n × n array
    is 128 MB; the shared runs, which keep up to 64 MB, keep nothing here).
    Seen failing when one helper forms an n × n array (``norms`` through an outer product)."""
    import sys

    import verimono as vm
    import verimono.checks.trajectory_laws as laws

    n = 4000
    p = vm.Problem(vm.NormSubdifferential(1.0, dim=n), np.linspace(-1.0, 1.0, n), 1.0, name="|x| n=4000")
    bound = 16 * 161 * n * 8          # 16 trajectories on the finest (160-cell) partition: 82 MB < n × n's 128 MB
    # nothing kept between laws (the shared runs hold up to MAX_BYTES = 64 MB): the peak is the laws' own work
    monkeypatch.setattr(sys.modules["verimono.checks.shared_runs"], "MAX_BYTES", 0)

    def battery():
        rep = check_stepper(solve, [p], orders=False, generated=0)
        assert not [r for r in rep.results if r.status == "failed"], rep.summary()

    assert _peak_bytes(battery) <= bound
    real = laws.norms
    formed = []

    def quadratic(a):
        a = np.asarray(a, dtype=float)
        if a.ndim and a.shape[-1] == n and not formed:     # once is enough to be seen
            row = a.reshape(-1, n)[0]
            formed.append(np.outer(row, row).shape)
        return real(a)

    monkeypatch.setattr(laws, "norms", quadratic)
    monkeypatch.setattr(sys.modules["verimono.checks.bounds"], "norms", quadratic)
    assert _peak_bytes(battery) > bound and formed == [(n, n)]


# -- large n: counted work and memory (issue 43, item 2) ------------------------------------------------------

def _big_problem(n: int, name: str = "|x| large n"):
    return Problem(__import__("verimono").NormSubdifferential(1.0, dim=n), np.linspace(-1.0, 1.0, n), 1.0, name=name)


def test_witness_rows_are_the_witnesses_per_row_numbers_in_a_few_rows_of_memory():
    """``witness_rows`` gives what ``in_domain`` and ``selections`` read of the resolvent witnesses — ``|J_k -
    x_{k+1}|`` and the rows' maxima ``row_tolerances`` takes — the same numbers as the trajectory-sized arrays of
    :func:`resolvent_witnesses`, holding a few rows at once (n = 5000, 41 nodes: at most 8 rows; the witnesses'
    arrays, seen with the same bound, hold more than 80)."""
    from verimono.checks.trajectory_laws import norms, resolvent_witnesses, witness_rows, witness_steps

    n = 5000
    p, t = _big_problem(n), np.sort(np.r_[0.0, np.random.default_rng(3).uniform(0, 1, 39), 1.0])
    x = solve(p, t).x
    w = witness_rows(solve, p, t, x)
    _, y, back = resolvent_witnesses(solve, p, t)
    np.testing.assert_array_equal(w["distance"], norms(back - x[1:]))
    np.testing.assert_array_equal(w["back_max"], np.abs(back).max(axis=1))
    np.testing.assert_array_equal(w["muy_max"], np.abs(witness_steps(t)[:, None] * y).max(axis=1))
    np.testing.assert_array_equal(w["hy_max"], np.abs(np.diff(t)[:, None] * y).max(axis=1))
    np.testing.assert_array_equal(w["x_max"], np.abs(x).max(axis=1))
    bound = 8 * n * 8
    assert _peak_bytes(lambda: witness_rows(solve, p, t, x)) <= bound
    assert _peak_bytes(lambda: resolvent_witnesses(solve, p, t)) > 10 * bound


def test_streamed_psi_pairs_are_the_pair_norms_without_the_interpolants_array(monkeypatch):
    """``psi_interpolation`` at large n forms the ψ-interpolant one time at a time: the same pair norms and
    ``|X|_∞`` as the array of all the times' states (forced here at n = 3000 with a small ``ROW_BLOCK``), and the
    same record; its peak at n = 8000 is the subsample's rows and a few more, where the array of 121 times is
    7.7 MB."""
    import verimono.checks.bounds as bounds

    n = 3000
    p, t = _big_problem(n), uniform_grid(1.0, steps=40)
    x = solve(p, t).x
    lg = bounds._lg_setup(p, t)[0]
    tau = np.unique(np.concatenate([t, 0.5 * (t[:-1] + t[1:]), np.random.default_rng(0).uniform(0.0, 1.0, 40)]))
    psi = lg.psi_function(np.union1d(t, tau))
    i, j = bounds._pairs(len(tau), n)
    X = bounds._psi_interpolant(t, x, tau, psi)
    rows, lhs, xmax = bounds._streamed_pairs(t, x, tau, psi, i, j)
    np.testing.assert_array_equal(lhs, bounds._pair_norms(X, i, j))
    assert float(np.max(xmax)) == float(np.abs(X).max())
    np.testing.assert_array_equal(rows[int(j[-1])], X[int(j[-1])])
    small = _big_problem(200)
    before = check_psi_interpolation_record(small)
    monkeypatch.setattr(bounds, "ROW_BLOCK", 100)
    after = check_psi_interpolation_record(small)
    assert (before.status, before.worst) == (after.status, after.worst)
    monkeypatch.undo()
    monkeypatch.setattr(bounds, "PAIR_ELEMENTS", 1 << 19)     # a subsample of 11 times at n = 8000
    n = 8000
    p, t = _big_problem(n), uniform_grid(1.0, steps=40)
    x = solve(p, t).x
    i, j = bounds._pairs(len(tau), n)
    kept = len(set(i[j != i + 1].tolist()) | set(j[j != i + 1].tolist()))
    assert kept <= 12
    bound = (kept + 8) * n * 8
    assert _peak_bytes(lambda: bounds._streamed_pairs(t, x, tau, psi, i, j)) <= bound
    assert _peak_bytes(lambda: bounds._psi_interpolant(t, x, tau, psi)) > 5 * bound


def check_psi_interpolation_record(p):
    from verimono.checks.bounds import check_psi_interpolation

    return check_psi_interpolation(solve, p)


def test_unique_limits_distances_by_columns_are_the_interpolants_distances(monkeypatch):
    """In a large dimension ``_distances`` forms every time's interpolated values for a block of coordinates (a
    sparse interpolation matrix): the distances of the two ``np.interp`` interpolants (forced at n = 3000), and a
    peak of a few blocks."""
    import verimono.checks.limits as limits

    rng = np.random.default_rng(11)
    n = 3000
    ga, gb = np.linspace(0.0, 1.0, 11), np.sort(np.r_[0.0, rng.uniform(0.0, 1.0, 39), 1.0])
    xa, xb = rng.normal(size=(11, n)), rng.normal(size=(41, n))
    tau = np.r_[np.union1d(ga, gb)[1:], 1.5]          # one time beyond the end: held constant
    ia = np.stack([np.interp(tau, ga, xa[:, j]) for j in range(n)], axis=-1)
    ib = np.stack([np.interp(tau, gb, xb[:, j]) for j in range(n)], axis=-1)
    want = np.linalg.norm(ia - ib, axis=-1)
    monkeypatch.setattr(limits, "SPARSE_COLUMNS", 1000)
    monkeypatch.setattr(limits, "COLUMN_ELEMENTS", 4096)
    got = limits._distances(ga, xa, gb, xb, tau)
    assert np.allclose(got, want, rtol=1e-13, atol=0.0)
    assert _peak_bytes(lambda: limits._distances(ga, xa, gb, xb, tau)) <= 64 * 4096 * 8


def test_the_shared_runs_keep_a_battery_at_n_1e6():
    """Counted, not timed: every partition the stepper battery judges a problem on fits in the shared runs at
    n = 10^6 (762 nodes with the two strongly non-uniform partitions of 41 nodes each, 6.1 GB), so each is run once — the former 64 MiB kept nothing beyond n = 2·10^5 and the
    battery ran the stepper 65 times instead of 12 — and a run larger than the bound is run again, never held."""
    import verimono.checks.shared_runs as shared
    from verimono.checks.partitions import every_battery_grid

    nodes = sum(len(g) for g in every_battery_grid(_big_problem(3)).values())
    assert nodes == 762
    assert nodes * 10 ** 6 * 8 <= shared.MAX_BYTES
    assert not nodes * 10 ** 6 * 8 <= 64 * 2 ** 20      # the former bound


def test_all_finite_reads_a_sum_and_decides_overflow_exactly():
    from verimono.checks.partitions import all_finite

    a = np.full((4, 5), 1e308)
    assert all_finite(a)                                # the sum overflows, every number is finite
    a[2, 3] = np.nan
    assert not all_finite(a)
    b = np.zeros((3, 3))
    b[1, 1] = -np.inf
    assert not all_finite(b) and all_finite(np.zeros((3, 3)))


@pytest.mark.parametrize("block", [1, 3, 1 << 16])
def test_velocity_rows_are_the_trajectorys_selections_bit_for_bit_in_any_block(monkeypatch, block):
    """``velocity_rows`` (the input's increments a block of cells at a time) yields ``y_k = (z_k - x_{k+1})/h``,
    the trajectory's own selections, bit for bit, with a Lipschitz field and an input, across block boundaries
    (a block of 1 number is one cell per call, the old way), and ``velocity_row`` agrees row by row."""
    from verimono import random_grid
    from verimono.checks import trajectory_laws as tl

    monkeypatch.setattr(tl, "_INCREMENT_BLOCK", block)
    p = get("Lipschitz field and input")
    t = random_grid(p.T, 40, seed=5)
    tr = solve(p, t)
    x = np.asarray(tr.x)
    rows = np.array(list(tl.velocity_rows(p, t, x)))
    assert np.array_equal(rows, np.asarray(tr.selections))
    assert all(np.array_equal(rows[k], tl.velocity_row(p, t, x, k)) for k in range(len(t) - 1))


@pytest.mark.parametrize("name", ["Lipschitz field and input", "play operator, piecewise-linear u",
                                  "Example ex, v = (sin t, 0)", "t|x| (n=3)"])
def test_witness_blocks_are_the_row_loops_numbers_bit_for_bit(name):
    """``witness_rows`` and ``selections``' velocities formed a block of rows at a time (``_witness_blocks``,
    ``_velocities``) are the row-by-row loop's numbers bit for bit — with a field ``f``, an input (``U`` and
    ``u``), a complementarity system's stateful resolvent and neither — on a grid of unequal steps (a uniform one
    for the Example: a step size each would be a factorisation each): the same velocities, ``|J_k - x_{k+1}|``
    and row maxima the laws' tolerances are made of."""
    from verimono.checks import trajectory_laws as laws
    from verimono.core.operator_protocol import resolvent_kernel

    p = get(name)
    t = (uniform_grid(p.T, steps=58) if name.startswith("Example") else
         np.sort(np.r_[0.0, np.random.default_rng(5).uniform(0, p.T, 57), p.T]))
    x = solve(p, t).x
    h, mu = np.diff(t), laws.witness_steps(t)
    rows = list(laws.velocity_rows(p, t, x))
    blocks = list(laws._velocities(p, t, x, h))
    assert [k for k, _ in blocks] == list(range(len(h)))
    np.testing.assert_array_equal(np.array([y for _, y in blocks]), np.array(rows))
    step = resolvent_kernel(p.operator, np.asarray(p.x0, dtype=float))
    dist, back_max, muy_max, hy_max, x_max = laws._witness_blocks(p, t, x, mu, h, step)
    step = resolvent_kernel(p.operator, np.asarray(p.x0, dtype=float))
    for k, y in enumerate(rows):          # the row loop witness_rows ran before the blocks
        ymax = laws._absmax(y)
        assert (muy_max[k], hy_max[k]) == (mu[k] * ymax, h[k] * ymax)
        back = np.reshape(step(y * mu[k] + x[k + 1], float(mu[k]), float(t[k + 1])), y.shape)
        assert back_max[k] == laws._absmax(back) and dist[k] == float(laws.norms(back - x[k + 1]))
    np.testing.assert_array_equal(x_max, laws.row_absmax(x))


@pytest.mark.parametrize("name", ["translating ball", "moving box", "moving half-space", "play operator, u = sin t"])
def test_normal_cone_members_of_a_block_are_contains_row_by_row(name):
    """``selections`` asks a catalog normal cone about a block of rows at once (``_cone_members``): the same
    booleans as ``NormalCone.contains`` row by row at each row's time and tolerance — on the scheme's own
    velocities (members), on velocities turned away (not), and on states pushed off the set (not)."""
    from verimono.checks import trajectory_laws as laws

    p = get(name)
    op = p.operator
    assert laws._cone_rows(op)
    t = np.sort(np.r_[0.0, np.random.default_rng(6).uniform(0, p.T, 40), p.T])
    x = solve(p, t).x
    h = np.diff(t)
    Y = np.array([y for _, y in laws._velocities(p, t, x, h)])
    rng = np.random.default_rng(7)
    X1 = x[1:].copy()
    cases = [(X1, Y), (X1, Y + rng.normal(size=Y.shape)), (X1 + rng.normal(size=X1.shape), Y)]
    tols = 1e-9 * (1.0 + np.abs(x[1:]).max(axis=1)) / h
    seen = set()
    for X, V in cases:
        got = laws._cone_members(op.S, X, V, t[1:], tols)
        want = [op.contains(X[k], V[k], float(t[k + 1]), tol=float(tols[k])) for k in range(len(h))]
        assert got.tolist() == want
        seen |= set(want)
    assert seen == {True, False}


def test_a_stepper_writing_into_the_problems_x0_fails_and_is_told_why():
    """A Problem's x0 is read-only (shared by every stepper checked on it): a stepper accumulating into
    np.asarray(problem.x0) fails where it writes, and the record says which array and what to do (probe7: NumPy's
    own message names neither)."""
    from verimono.checks.trajectory_laws import check_in_domain

    def accumulates_into_x0(problem, t_grid):
        x = np.asarray(problem.x0, dtype=float)           # a view of the problem's x0, not a copy
        out = [x.copy()]
        for k in range(1, len(t_grid)):
            x += 0.0                                       # the write
            out.append(problem.operator.resolvent(x, t_grid[k] - t_grid[k - 1], t_grid[k]))
        return np.array(out)

    p = get("t|x| (n=1)")
    rec = check_in_domain(accumulates_into_x0, p)
    assert rec.status == "failed" and "x = np.array(problem.x0)" in rec.message, str(rec)
    assert p.x0.flags.writeable is False and not p.x0.flags.owndata is False
