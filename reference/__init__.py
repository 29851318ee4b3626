"""Analytic reference problems: each a :class:`verimono.Problem` with its exact solution, the expected
order of the proximal scheme on it and where that order comes from (``problem.order.source``).

``catalog()`` returns them all; ``get(name)`` one by name; ``names()`` their names.
"""

from __future__ import annotations

import functools

from verimono.core.problem import Problem

from . import lcs_example, linear, subdifferential, sweeping

_BUILDERS = [
    lambda: subdifferential.t_norm((1.0,)),
    lambda: subdifferential.t_norm((0.6, -0.8, 0.5)),
    subdifferential.log_barrier,
    sweeping.static_inside,
    sweeping.static_outside,
    sweeping.play_smooth,
    sweeping.play_piecewise_linear,
    sweeping.moving_half_space,
    sweeping.moving_box,
    sweeping.translating_ball,
    linear.linear,
    linear.lipschitz_input,
    lcs_example.ramp_problem,
    lcs_example.sine_problem,
]


def catalog() -> list[Problem]:
    """Every analytic reference problem, freshly built."""
    return [build() for build in _BUILDERS]


@functools.cache
def names() -> frozenset[str]:
    """The names of the catalog's problems, the catalog built once per process to read them (an order check's
    reproduction script built it each time it asked whether its problem is a reference: 1 ms a build here,
    3 ms the first)."""
    return frozenset(p.name for p in catalog())


def get(name: str) -> Problem:
    for p in catalog():
        if p.name == name:
            return p
    raise KeyError(f"no reference named {name!r}; known: {[p.name for p in catalog()]}")


__all__ = ["catalog", "get", "names"]
