"""Correct projections of PyTorch and JAX (jaxopt) with their indicators as ``value``, at float32 and float64,
single and batched: the subjects of issue 42's "PyTorch and JAX projections with values ... pass every law at
every seed" (tests/core/test_arrays_sweep.py), and a few deliberately wrong ones that must still fail.

Each set is written once per library, as a user of that library writes it: the projection in the library's
own arithmetic (closed forms, a sort for the ℓ1 ball and the simplex, a small solve for the affine set), and
the indicator evaluated by the library on the values verimono hands it — strict for the inequalities
(``+inf`` at every point outside), and for the equalities (``A x = b``, the simplex's sum), which no rounded
point meets exactly, within ``EQ_ULPS`` units of round-off of the terms summed, ``EQ_ULPS·eps·(1 + Σ|terms|)``.
A fixed slack such as ``1e-6`` would state another set than the one projected onto: in float64 the prox
of that ``g`` differs from the projection by ``~1e-6``, 100 times float64's tolerance, and verimono rightly
says so (``prox_minimiser``, ``prox_inequality``).  Nothing here knows verimono's tolerances."""

from __future__ import annotations

import numpy as np

import verimono as vm

N = 3
A_HALF, B_HALF = np.array([1.0, -2.0, 0.5]), 0.3                   # {a·x ≤ b}
A_AFF, B_AFF = np.array([[1.0, 1.0, 0.0], [0.0, 1.0, -1.0]]), np.array([0.5, -0.25])   # {A x = b}
CENTRE, RADIUS = np.array([0.5, -0.25, 1.0]), 1.0                 # the ℓ2 ball
LO, HI = -1.0, 2.0                                                # the box
EQ_ULPS = 4                                                       # the equalities' slack in units of round-off
SETS = ("half-space", "affine", "l1-ball", "simplex", "l2-ball", "box")


def _torch_sets(dtype):
    import torch

    T = lambda a: torch.as_tensor(a, dtype=dtype)   # noqa: E731
    a, b, A, bb, c = T(A_HALF), T(B_HALF), T(A_AFF), T(B_AFF), T(CENTRE)
    AAt = A @ A.T

    def half(x):
        return x - torch.clamp(x @ a - b, min=0.0)[..., None] * a / (a @ a)

    def affine(x):
        r = x @ A.T - bb                                         # (..., m)
        return x - torch.linalg.solve(AAt, r.unsqueeze(-1)).squeeze(-1) @ A if r.ndim > 1 \
            else x - A.T @ torch.linalg.solve(AAt, r)

    def simplex_tau(v, z):                                        # Duchi et al.: the threshold on the last axis
        u, _ = torch.sort(v, dim=-1, descending=True)
        css = torch.cumsum(u, dim=-1) - z
        k = torch.arange(1, v.shape[-1] + 1, dtype=v.dtype)
        cond = u - css / k > 0
        rho = cond.to(torch.int64).cumsum(-1).argmax(-1, keepdim=True)   # the last index where cond holds
        return torch.gather(css, -1, rho) / (rho + 1).to(v.dtype)

    def simplex(x):
        return torch.clamp(x - simplex_tau(x, 1.0), min=0.0)

    def l1ball(x):
        inside = torch.abs(x).sum(-1, keepdim=True) <= 1.0
        w = torch.clamp(torch.abs(x) - simplex_tau(torch.abs(x), 1.0), min=0.0)
        return torch.where(inside, x, torch.sign(x) * w)

    def l2ball(x):
        d = x - c
        nd = torch.linalg.norm(d, dim=-1, keepdim=True)
        return torch.where(nd <= RADIUS, x, c + d * (RADIUS / nd))

    def box(x):
        return torch.clamp(x, LO, HI)

    inf, eps = float("inf"), torch.finfo(dtype).eps

    def on_affine(x):
        return bool((torch.abs(A @ x - bb) <= EQ_ULPS * eps * (1 + torch.abs(A) @ torch.abs(x) + torch.abs(bb))).all())

    def on_simplex(x):
        return float(x.min()) >= 0.0 and abs(float(x.sum()) - 1.0) <= EQ_ULPS * eps * (1 + float(torch.abs(x).sum()))

    values = {
        "half-space": lambda x: 0.0 if float(x @ a) <= B_HALF else inf,
        "affine": lambda x: 0.0 if on_affine(x) else inf,
        "l1-ball": lambda x: 0.0 if float(torch.abs(x).sum()) <= 1.0 else inf,
        "simplex": lambda x: 0.0 if on_simplex(x) else inf,
        "l2-ball": lambda x: 0.0 if float(torch.linalg.norm(x - c)) <= RADIUS else inf,
        "box": lambda x: 0.0 if float(x.min()) >= LO and float(x.max()) <= HI else inf,
    }
    projections = {"half-space": half, "affine": affine, "l1-ball": l1ball, "simplex": simplex, "l2-ball": l2ball,
                   "box": box}
    return projections, values


def torch_projection(kind, precision="float32", batched=False):
    """The PyTorch projection onto set ``kind`` (of :data:`SETS`) with its indicator, computing in ``precision``."""
    import torch

    projections, values = _torch_sets(getattr(torch, precision))
    P = projections[kind]
    prox = (lambda X, lams: P(X)) if batched else P
    return vm.operator_from_prox(prox, step=None if batched else False, batched=batched, value=values[kind],
                                 shape=N, array="torch", dtype=precision,
                                 name=f"torch {kind} {precision}" + (", batched" if batched else ""))


def _jax_sets():
    import jax.numpy as jnp
    from jaxopt import projection as P

    inf = jnp.inf

    def l2ball(x):
        return jnp.asarray(CENTRE, x.dtype) + P.projection_l2_ball(x - jnp.asarray(CENTRE, x.dtype), RADIUS)

    projections = {
        "half-space": lambda x: P.projection_halfspace(x, (jnp.asarray(A_HALF, x.dtype), B_HALF)),
        "affine": lambda x: P.projection_affine_set(x, (jnp.asarray(A_AFF, x.dtype), jnp.asarray(B_AFF, x.dtype))),
        "l1-ball": lambda x: P.projection_l1_ball(x, 1.0),
        "simplex": lambda x: P.projection_simplex(x, 1.0),
        "l2-ball": l2ball,
        "box": lambda x: P.projection_box(x, (LO, HI)),
    }
    def on_affine(x):
        A, eps = jnp.asarray(A_AFF, x.dtype), jnp.finfo(x.dtype).eps
        b = jnp.asarray(B_AFF, x.dtype)
        return (jnp.abs(A @ x - b) <= EQ_ULPS * eps * (1 + jnp.abs(A) @ jnp.abs(x) + jnp.abs(b))).all()

    def on_simplex(x):
        eps = jnp.finfo(x.dtype).eps
        return (x.min() >= 0.0) & (jnp.abs(x.sum() - 1.0) <= EQ_ULPS * eps * (1 + jnp.abs(x).sum()))

    values = {
        "half-space": lambda x: jnp.where(x @ jnp.asarray(A_HALF, x.dtype) <= B_HALF, 0.0, inf),
        "affine": lambda x: jnp.where(on_affine(x), 0.0, inf),
        "l1-ball": lambda x: jnp.where(jnp.abs(x).sum() <= 1.0, 0.0, inf),
        "simplex": lambda x: jnp.where(on_simplex(x), 0.0, inf),
        "l2-ball": lambda x: jnp.where(jnp.linalg.norm(x - jnp.asarray(CENTRE, x.dtype)) <= RADIUS, 0.0, inf),
        "box": lambda x: jnp.where((x.min() >= LO) & (x.max() <= HI), 0.0, inf),
    }
    return projections, values


def jax_projection(kind, precision="float32", batched=False):
    """The jaxopt projection onto set ``kind`` with its indicator, jitted (and vmapped when ``batched``);
    float64 needs ``jax.enable_x64`` around the check (tests/core/test_arrays_sweep.py)."""
    import jax

    projections, values = _jax_sets()
    P = projections[kind]
    prox = jax.jit(jax.vmap(lambda x, lam: P(x))) if batched else jax.jit(P)
    return vm.operator_from_prox(prox, step=None if batched else False, batched=batched, value=jax.jit(values[kind]),
                                 shape=N, array="jax", dtype=precision,
                                 name=f"jax {kind} {precision}" + (", batched" if batched else ""))


def wrong_torch_projection(kind, precision="float32"):
    """Broken controls: the projection of ``kind`` perturbed so that it is wrong beyond any round-off.

    ``"ball 1.01"``: onto the ℓ2 ball of radius 1.01 (stated radius 1); ``"half-space 50 ulps"``: the half-space's
    projection moved ``50·eps·(1 + |x|)`` outward along ``a`` (a float32 projection off by 50 ulps)."""
    import torch

    dt = getattr(torch, precision)
    projections, values = _torch_sets(dt)
    if kind == "ball 1.01":
        c = torch.as_tensor(CENTRE, dtype=dt)

        def P(x):
            d = x - c
            nd = torch.linalg.norm(d)
            return x if nd <= 1.01 else c + d * (1.01 / nd)
        value = values["l2-ball"]
    elif kind == "half-space 50 ulps":
        a = torch.as_tensor(A_HALF, dtype=dt)
        eps = torch.finfo(dt).eps

        def P(x):
            return projections["half-space"](x) + 50 * eps * (1 + float(torch.abs(x).max())) * a / torch.linalg.norm(a)
        value = values["half-space"]
    else:
        raise KeyError(kind)
    return vm.operator_from_prox(P, step=False, value=value, shape=N, array="torch", dtype=precision,
                                 name=f"wrong torch {kind} {precision}")
