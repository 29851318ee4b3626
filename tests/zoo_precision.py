"""float32 versions of operators, problems and steppers: the same code computing in single precision.

``float32(op)`` rounds every input of ``op`` to float32 and returns every output as a float32 array (the
precision a float32 implementation delivers: a correctly rounded result, plus the rounding of its inputs);
``float32_problem(p)`` does so for the operator and the field ``f`` of a problem, and ``float32_stepper(s)``
returns a stepper's states as float32.  A correct operator stays correct (up to float32 rounding) and a
broken one keeps its bug, so the judgement at float32 precision (:mod:`verimono.core.tolerances`) is tested on
both sides: every correct one passes, every broken one is still caught.
"""

from __future__ import annotations

import functools

import numpy as np

from verimono.core.operators import Operator

F32 = np.float32


def _r(x):
    """``x`` rounded to float32, handed on in float64 (the wrapped code computes in float64)."""
    return np.asarray(x, dtype=F32).astype(np.float64)


class Float32(Operator):
    """``op`` computing in float32 (module docstring)."""

    def __init__(self, op):
        super().__init__(op.dim, f"{op.name}@float32")
        self.op = op
        self.static = getattr(op, "static", False)
        self.full_domain = getattr(op, "full_domain", False)

    def resolvent(self, x, lam, t=0.0):
        z = _r(x)
        given = z.copy()
        out = np.asarray(self.op.resolvent(z, float(F32(lam)), t), dtype=F32)
        if isinstance(x, np.ndarray) and not np.array_equal(z, given):
            x[...] = z          # a resolvent that overwrites its input does so in float32 as well
        return out

    def yosida(self, x, lam, t=0.0):       # the member of its own where op has one (provides() says so)
        return np.asarray(self.op.yosida(_r(x), float(F32(lam)), t), dtype=F32)

    def min_norm(self, x, t=0.0):
        return np.asarray(self.op.min_norm(_r(x), t), dtype=F32)

    def project_domain(self, x, t=0.0):
        return np.asarray(self.op.project_domain(_r(x), t), dtype=F32)

    def contains(self, x, y, t=0.0, tol=None):
        return self.op.contains(_r(x), _r(y), t, tol)

    def value(self, x, t=0.0):
        return F32(self.op.value(_r(x), t))

    def growth(self, t=0.0):
        return self.op.growth(t)

    def provides(self, member):
        from verimono.core.operators import provides
        return provides(self.op, member)


def float32(op) -> Float32:
    return Float32(op)


def float32_problem(p):
    """``p`` with its operator and field computing in float32."""
    kw = {"operator": float32(p.operator)}
    if p.f is not None:
        f = p.f
        kw["f"] = lambda x: np.asarray(f(_r(x)), dtype=F32)
    return p.replace(**kw)


def float32_stepper(stepper):
    """``stepper`` on the float32 version of the problem, its states returned as float32."""
    @functools.wraps(stepper)
    def run(problem, t_grid):
        return np.asarray(stepper(float32_problem(problem), t_grid), dtype=F32)
    run.__name__ = f"{getattr(stepper, '__name__', 'stepper')}@float32"
    for attr in ("claim", "batched"):
        if hasattr(stepper, attr):
            setattr(run, attr, getattr(stepper, attr))
    return run
