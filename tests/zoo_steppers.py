"""Deliberately broken steppers: each is a plausible mistake in implementing the paper's scheme

    x_{k+1} = (I + h_{k+1} F(t_{k+1}, ·))^{-1}(x_k + h_{k+1} f(x_k) + ∫_{t_k}^{t_{k+1}} u)     (eq:iteration)

and every trajectory law of :mod:`verimono.checks.trajectory_laws` must catch at least one of them.
``BREAKS`` says which law each member is shown to break, on which reference problem and partition.
"""

from __future__ import annotations

import numpy as np

from verimono.core.errors import OutsideDomain
from verimono.core.grids import validate_grid


def _scheme(problem, t_grid, *, time=lambda t, k: t[k + 1], step=lambda h, k: h[k], drift_u=True,
            post=None, explicit=False):
    """The proximal scheme with one ingredient swapped out (the correct one by default)."""
    t = validate_grid(t_grid, problem.T)
    h = np.diff(t)
    op, f = problem.operator, problem.f
    dU = problem.input_increments(t) if drift_u else None
    x = np.empty((len(t),) + problem.x0.shape)
    x[0] = problem.x0
    for k in range(len(h)):
        z = x[k]
        if f is not None:
            z = z + h[k] * np.asarray(f(x[k]), dtype=float)
        if dU is not None:
            z = z + dU[k]
        if explicit:
            try:
                y = np.asarray(op.min_norm(x[k], t[k]), dtype=float)
            except OutsideDomain:
                y = np.zeros_like(x[k])     # an explicit step knows nothing about the constraint
            x[k + 1] = z - h[k] * y
        else:
            x[k + 1] = op.resolvent(z, step(h, k), time(t, k))
        if post is not None:
            x[k + 1] = post(problem, t, k, z, x[k + 1])
    return x


def wrong_time(problem, t_grid):
    """Evaluates the operator at ``t_k`` instead of ``t_{k+1}`` (a lagged catching-up step)."""
    return _scheme(problem, t_grid, time=lambda t, k: t[k])


def drops_input(problem, t_grid):
    """Forgets the input term ``∫u`` (keeps ``f``)."""
    return _scheme(problem, t_grid, drift_u=False)


def lagged_step(problem, t_grid):
    """Uses the previous step ``h_k`` instead of ``h_{k+1}`` (the same on uniform partitions)."""
    return _scheme(problem, t_grid, step=lambda h, k: h[max(k - 1, 0)])


def mean_step(problem, t_grid):
    """Uses the mean step ``T/K`` on every cell (right on uniform partitions only)."""
    return _scheme(problem, t_grid, step=lambda h, k: float(np.mean(h)))


def double_step(problem, t_grid):
    """Uses ``2h`` — the inclusion ``x' ∈ -2F(t, x)`` instead of ``x' ∈ -F(t, x)``."""
    return _scheme(problem, t_grid, step=lambda h, k: 2.0 * h[k])


def explicit_euler(problem, t_grid):
    """An explicit step ``x_{k+1} = x_k - h F^0(t_k, x_k)`` passed off as the proximal one."""
    return _scheme(problem, t_grid, explicit=True)


def leaves_domain(problem, t_grid):
    """Pushes every iterate ``1e-3 (1 + |x|)`` beyond the resolvent's output, out of ``cl dom F``."""
    def post(problem, t, k, z, x):
        d = x - z                              # the correction the resolvent applied (inward normal)
        nrm = float(np.linalg.norm(d))
        push = d / nrm if nrm > 0 else np.ones_like(x) / np.sqrt(x.size)
        return x + 1e-3 * (1.0 + float(np.linalg.norm(x))) * push * (-1.0 if nrm > 0 else 1.0)
    return _scheme(problem, t_grid, post=post)


def amplifier(problem, t_grid):
    """Multiplies every iterate by ``1 + 5h`` — an undeclared expanding field ``f(x) = 5x``."""
    return _scheme(problem, t_grid, post=lambda p, t, k, z, x: (1.0 + 5.0 * (t[k + 1] - t[k])) * x)


ZOO = [wrong_time, drops_input, lagged_step, mean_step, double_step, explicit_euler, leaves_domain, amplifier]

#: law -> (zoo member, reference name, partition kind) on which the law is shown to fail
BREAKS = {
    "contraction": (amplifier, "linear x' = -Mx", "uniform"),
    "unique_limit": (mean_step, "t|x| (n=1)", "uniform/random/graded"),
    "in_domain": (leaves_domain, "moving box", "uniform"),
    "bounds_lg": (amplifier, "t|x| (n=1)", "uniform"),
    "bounds_yb": (double_step, "linear x' = -Mx", "uniform"),
    "psi_interpolation": (double_step, "linear x' = -Mx", "uniform"),
    "selections": (wrong_time, "t|x| (n=1)", "uniform"),
}


# -- valid alternative schemes: correct, but not the paper's one-step scheme on the given grid -----------------
# Each converges to the solution; declared ``scheme="any"`` (verimono.Stepper) they must pass every law
# that binds a convergent scheme, on the whole reference catalog.

def _drift(problem, x, h):
    return x if problem.f is None else x + h * np.asarray(problem.f(x), dtype=float)


def midpoint_time(problem, t_grid):
    """The proximal step with the operator at the cell's midpoint, ``J_{h F((t_k + t_{k+1})/2)}``."""
    return _scheme(problem, t_grid, time=lambda t, k: 0.5 * (t[k] + t[k + 1]))


def random_substeps(problem, t_grid):
    """The proximal scheme run on 2 or 3 substeps per cell, cut at random points (seeded by the grid)."""
    t = validate_grid(t_grid, problem.T)
    rng = np.random.default_rng(len(t))
    fine = [t[:1]]
    for a, b in zip(t[:-1], t[1:]):
        cuts = np.sort(rng.uniform(a, b, rng.integers(1, 3)))
        fine.append(np.concatenate([cuts, [b]]))
    s = np.concatenate(fine)
    x = _scheme(problem, s)
    return x[np.searchsorted(s, t)]


def exact_sampled(problem, t_grid):
    """The exact solution itself, sampled on the grid (the references' ``problem.exact``)."""
    t = validate_grid(t_grid, problem.T)
    if problem.exact is None:
        raise ValueError(f"{problem.name} has no exact solution to sample")
    return np.array([np.asarray(problem.exact(float(s)), dtype=float) for s in t])


#: correct schemes that are not the paper's scheme on the given grid
VALID_ALTERNATIVES = [midpoint_time, random_substeps, exact_sampled]


# -- a stepper that deviates on some steps only ------------------------------------------------------------

#: the absolute residual at which :func:`residual_stop` accepts its Newton iterate
RESIDUAL_STOP = 1e-4


def residual_stop(problem, t_grid):
    """A third-party backward Euler whose Newton solve of ``x + hF(t_{k+1}, x) ∋ z`` starts at the predictor
    ``z`` and stops once the residual ``|x + h y − z|`` is below ``RESIDUAL_STOP`` (absolute): the predictor
    itself is accepted whenever ``|z − J_h z| = h|Y_h z| < 1e-4`` — on the small steps, or where ``F`` is
    small — and is off by up to ``1e-4`` there; on every other step the solve is exact."""
    def post(problem, t, k, z, x):
        return z if float(np.linalg.norm(z - x)) < RESIDUAL_STOP else x
    return _scheme(problem, t_grid, post=post)


# -- steppers that break the contract of what a stepper returns (issues 40 and 42) --------------------------------

def scaled_start(problem, t_grid):
    """Starts from ``1.2 x0`` (an initial point rescaled by a stray factor), and runs the scheme from there."""
    return _scheme(problem.replace(x0=1.2 * problem.x0), t_grid)


def starts_at_zero(problem, t_grid):
    """Ignores ``x0``: starts at the origin (a state array initialised with zeros and never given ``x0``)."""
    x = _scheme(problem.replace(x0=np.zeros_like(problem.x0), initial_jump=True), t_grid)
    return x


def projected_start(problem, t_grid):
    """Returns ``x_0 = proj_{cl dom F(0)}(x0)`` instead of the given ``x0``: the catching-up jump taken at
    ``t_0`` rather than in the first step (the same states from ``t_1`` on; different only when ``x0`` lies
    outside the domain, as in ``static ball, x0 outside (jump)``)."""
    x = _scheme(problem, t_grid)
    x[0] = problem.operator.project_domain(problem.x0, 0.0)
    return x


_BUFFERS = {}


def shared_buffer(problem, t_grid):
    """Writes its states into one preallocated buffer per shape, kept between calls and returned: the array
    one call returned is overwritten by the next call of the same shape."""
    x = _scheme(problem, t_grid)
    buf = _BUFFERS.setdefault(x.shape, np.empty(x.shape))
    buf[...] = x
    return buf


def mutates_grid(problem, t_grid):
    """Uses the caller's grid as scratch: after the run it holds the cells' midpoints (``np.asarray`` does not
    copy a float array)."""
    t = np.asarray(t_grid)
    x = _scheme(problem, t)
    t[1:] = 0.5 * (t[:-1] + t[1:])
    return x


def mutates_x0(problem, t_grid):
    """Leaves its final state in ``problem.x0`` (the running state written back into the problem's array): a
    second run of the same problem starts where the first ended."""
    x = _scheme(problem, t_grid)
    problem.x0[...] = x[-1]
    return x


def at_rest_view(problem, t_grid):
    """Returns ``np.broadcast_to(x0, ...)`` when the solution stays at ``x0`` (a problem at rest): the right
    values, in the memory of ``problem.x0`` (a later change of ``x0`` changes the returned trajectory)."""
    x = _scheme(problem, t_grid)
    if np.all(x == problem.x0):
        return np.broadcast_to(problem.x0, x.shape)
    return x


BREAKS["initial_value"] = (scaled_start, "t|x| (n=1)", "uniform")
BREAKS["trajectory_immutable"] = (mutates_grid, "t|x| (n=1)", "uniform/random")   # its float32 wrapper too

# -- uniform-only catching-up steppers with approximate projections (issue 40) ------------------------------
# Written the way public sweeping-process codes are: problem-specific (they know the moving set), stepping
# t_n = n h on uniform grids only (ValueError on any other), projecting by a few iterations of an inner
# solver stopped at a tolerance eps(h).  Each is a factory ``ball_catching_up(...)`` for the ball B(v t, R) of
# ``verimono.reference.sweeping.translating_ball``; ``sweeping_2pi()`` is that problem on [0, 2π].

BALL_V, BALL_R = np.array([1.0, 0.5]), 1.0


def sweeping_2pi():
    """The translating ball on ``[0, 2π]`` (its closed form holds for every ``T``): a horizon no step divides
    in floating point, where a stepper counting ``floor(T/h)`` steps stops one short."""
    from verimono.reference.sweeping import translating_ball

    T = 2 * np.pi
    return translating_ball(T=T).replace(name="translating ball on [0, 2π]",
                                         steps=[T / k for k in (50, 100, 200, 400, 800)])


def dual_gradient_ball_projection(z, c, R, eps):
    """The projection of ``z`` onto ``B(c, R)`` by projected gradient ascent on the dual of
    ``min ½|x − z|² s.t. ½(|x − c|² − R²) ≤ 0`` (``x(λ) = (z + λc)/(1 + λ)``, step ``1/R²``), stopped as soon
    as ``x(λ)`` is certified within ``eps`` of the projection (``x(λ)`` and ``P(z)`` lie on the segment from
    ``c`` to ``z``: their distance is ``||x(λ) − c| − R|``, or 0 inside with ``λ = 0``)."""
    lam = 0.0
    for _ in range(200):
        x = (z + lam * c) / (1.0 + lam)
        r = float(np.linalg.norm(x - c))
        if (lam == 0.0 and r <= R) or abs(r - R) <= eps:
            return x
        lam = max(0.0, lam + 0.5 * (r * r - R * R) / (R * R))
    return x


def ball_catching_up(C=1.0, q=2.0, *, lag=False, floor_steps=False, v=BALL_V, R=BALL_R):
    """The catching-up scheme ``x_{n+1} ≈ P_{C(t_{n+1})}(x_n)`` for ``C(t) = B(v t, R)``, on uniform grids only,
    each projection to ``eps(h) = C h^q``.  ``lag``: the set's centre taken at ``t_n`` instead of ``t_{n+1}``
    (a planted bug); ``floor_steps``: the step count ``floor(T/h)`` (stops one step short where ``h`` does not
    divide ``T`` in floating point, and pads with its last state)."""
    def stepper(problem, t_grid):
        t = np.asarray(t_grid, dtype=float)
        K = len(t) - 1
        h = t[1] - t[0]
        if not np.allclose(np.diff(t), h, rtol=1e-9, atol=0.0):
            raise ValueError("this code steps t_n = n h: uniform grids only")
        eps = C * h ** q
        n_steps = int(np.floor(t[-1] / h)) if floor_steps else K
        x = [np.asarray(problem.x0, dtype=float)]
        for n in range(n_steps):
            centre = v * ((n if lag else n + 1) * h)
            x.append(dual_gradient_ball_projection(x[-1], centre, R, eps))
        x += [x[-1]] * (K - n_steps)
        return np.array(x)
    stepper.__name__ = (f"catching_up_eps_{C:g}h^{q:g}" + ("_lagged" if lag else "")
                        + ("_floor" if floor_steps else ""))
    return stepper
