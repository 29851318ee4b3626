"""The problems the stepper battery searches besides the references: drawn from
:func:`verimono.strategies.stated_problems`, deterministically from the battery's seed.

Problem ``#i`` of seed ``s`` is :func:`generated_problem` ``(s, i)``: the ``i``-th stratum of :data:`STRATA`
(where ``x0`` lies, the size class of ``n``, which of ``f`` and ``u`` are present — so that every few draws
cover every placement, size and term) and the rest (``n`` in its class, ``T``, the operator, ``f``, ``u``, the
points) drawn by hypothesis from the seed ``s·1000003 + i``.  The same ``(s, i)`` gives the same problem
(under one hypothesis release), and the problem's name starts ``generated #i (seed s)``: a failing record
names its recipe, and ``check_stepper(stepper, problems=[generated_problem(s, i)])`` reproduces it.

:func:`generated_problems` ``(seed, count)`` is the first ``count``: the profile's ``generated_subjects``
(``dev`` 3, ``ci`` 6 — one round of the strata —, ``thorough`` 30).  Most draws are small or medium; one in
three is large (``n`` up to 50).
"""

from __future__ import annotations

import functools

from ..core.problem import Problem
from .sample_problems import valid_count

#: ``(placement, size, terms)`` of draw ``i`` is ``STRATA[i % 6]``: the first three hold a start on the
#: boundary, an interior one in ``n ≥ 13`` and one just inside the boundary in ``5 ≤ n ≤ 12``, each with
#: ``f`` and ``u``; the next three a start just outside (the catching-up jump), the bounds' setting
#: (``f = 0``) and ``f`` alone
STRATA = (("on", "small", "f+u"), ("inside", "large", "f+u"), ("near_inside", "medium", "f+u"),
          ("near_outside", "small", "u"), ("inside", "small", "none"), ("on", "medium", "f"))
#: the seed of draw ``i`` of battery seed ``s`` is ``s * SEED_STRIDE + i``
SEED_STRIDE = 1_000_003


@functools.lru_cache(maxsize=256)
def generated_problem(seed: int, index: int) -> Problem:
    """Problem ``#index`` of battery seed ``seed`` (module docstring)."""
    from hypothesis import HealthCheck, Phase, given, settings
    from hypothesis import seed as hseed

    from ..strategies.problems import stated_problems

    seed, index = valid_count(seed, "seed"), valid_count(index, "index")
    placement, size, terms = STRATA[index % len(STRATA)]
    drawn: list[Problem] = []

    # two examples: hypothesis' first is the simplest (every choice at its minimum), the second is drawn
    @settings(max_examples=2, derandomize=False, database=None, phases=[Phase.generate], deadline=None,
              suppress_health_check=list(HealthCheck))
    @given(stated_problems(size=size, placement=placement, terms=terms))
    def collect(p: Problem) -> None:
        drawn.append(p)

    hseed(seed * SEED_STRIDE + index)(collect)()
    p = drawn[-1]
    return p.replace(name=f"generated #{index} (seed {seed}): {p.name}",
                     notes=f"generated_problem({seed}, {index}); {p.notes}")


def generated_problems(seed: int = 0, count: int = len(STRATA)) -> list[Problem]:
    """Problems ``#0 .. #count-1`` of battery seed ``seed``."""
    return [generated_problem(int(seed), i) for i in range(valid_count(count))]


__all__ = ["STRATA", "SEED_STRIDE", "generated_problem", "generated_problems"]
