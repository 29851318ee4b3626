"""The switching times of the reference catalog's exact solutions: where an event-driven scheme must put
its events (``switching_times`` law, :mod:`verimono.checks.own_steps`).

* ``t|x|`` (``reference.subdifferential.t_norm``): ``|x|' = -t`` until the extinction at ``t* = sqrt(2|x0|)``,
  then ``x = 0``: one switching (from sliding to sticking), at ``t*``;
* the paper's Example with ``v = (sin t, 0)`` (``reference.lcs_example.sine_problem``): the multiplier
  ``z2 = max(-sin t, 0)`` switches on at ``t = π, 3π, ...`` and off at ``t = 2π, 4π, ...``: the switchings
  are ``kπ`` in ``(0, T)``;
* the Example with ``v = (-t, 0)``: ``z2 = t`` for ``t > 0``: no switching in ``(0, T)``.

Problems not listed return ``None`` (their switching times are not stated).
"""

from __future__ import annotations

import math

import numpy as np

from verimono.core.problem import Problem


def switching_times(problem: Problem) -> list[float] | None:
    """The switching times of ``problem``'s exact solution in ``(0, T)``, or ``None`` when not stated."""
    name, T = problem.name, problem.T
    if name.startswith("t|x| (n="):
        t_star = math.sqrt(2.0 * float(np.linalg.norm(problem.x0)))
        return [t_star] if t_star < T else []
    if name == "Example ex, v = (sin t, 0)":
        return [k * math.pi for k in range(1, int(T / math.pi) + 2) if k * math.pi < T]
    if name == "Example ex, v = (−t, 0)":
        return []
    return None


__all__ = ["switching_times"]
