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

from ..core._reproducible import no_local_constants
from ..core.problem import Problem
from .arguments import valid_seed
from .sample_problems import valid_count

#: ``(placement, size, terms)`` of draw ``i`` is ``STRATA[i % 6]``: the first three (``dev``'s) hold a start on
#: the boundary with ``u`` (where the bounds of lem:bndSeq apply), an interior one in ``n ≥ 13`` and one just
#: inside the boundary in ``5 ≤ n ≤ 12``, both with ``f`` and ``u``; the next three a start just outside (the
#: catching-up jump) with ``f`` alone, one with neither (where lem:bndSeqYB applies too) and a boundary start
#: in ``5 ≤ n ≤ 12`` with ``f`` and ``u``
STRATA = (("on", "small", "u"), ("inside", "large", "f+u"), ("near_inside", "medium", "f+u"),
          ("near_outside", "small", "f"), ("inside", "small", "none"), ("on", "medium", "f+u"))
#: the seed of draw ``i`` of battery seed ``s`` is ``s * SEED_STRIDE + i``
SEED_STRIDE = 1_000_003
#: a draw a strategy's filter or ``assume`` rejects is drawn again from seed ``+ k * ATTEMPT_STRIDE``,
#: ``k = 1, 2, ...`` (still a function of the seed alone), up to ``DRAW_ATTEMPTS`` times
ATTEMPT_STRIDE, DRAW_ATTEMPTS = 7_919_000_003, 20


@functools.lru_cache(maxsize=256)
def generated_problem(seed: int, index: int) -> Problem:
    """Problem ``#index`` of battery seed ``seed`` (module docstring)."""
    from ..strategies.problems import stated_problems

    seed, index = valid_seed(seed), valid_count(index, "index")
    placement, size, terms = STRATA[index % len(STRATA)]
    p = draw(stated_problems(size=size, placement=placement, terms=terms), seed * SEED_STRIDE + index)
    return p.replace(name=f"generated #{index} (seed {seed}): {p.name}",
                     notes=f"generated_problem({seed}, {index}); {p.notes}")


def draw(strategy, seed: int):
    """One value of the hypothesis ``strategy``, a function of ``seed`` alone.

    A test run of hypothesis is not: besides its seed, it draws with some probability among the constants it
    finds in the source of the local modules imported so far (hypothesis ≥ 6.131), so the same seed gave
    another problem once ``verimono.reference`` was imported.  Here one choice sequence is drawn from
    ``random.Random(seed)`` by hypothesis' own provider with those constants switched off — no test engine,
    no first "simplest" example (about 25 ms a problem instead of 50).  A hypothesis without that provider
    interface is driven through ``@given`` and ``@seed`` instead."""
    import random

    try:
        from hypothesis.control import BuildContext
        from hypothesis.errors import UnsatisfiedAssumption
        from hypothesis.internal.conjecture.data import ConjectureData, StopTest
    except ImportError:                                   # another hypothesis release: its test engine
        return _draw_with_engine(strategy, seed)
    for attempt in range(DRAW_ATTEMPTS):
        try:
            data = ConjectureData(random=random.Random(seed + attempt * ATTEMPT_STRIDE), provider=_provider())
            context = BuildContext(data, is_final=False, wrapped_test=draw)
        except (TypeError, AttributeError):               # another hypothesis release: its test engine
            return _draw_with_engine(strategy, seed)
        try:
            with context:
                return data.draw(strategy)
        except (StopTest, UnsatisfiedAssumption):         # a filter or assume of a strategy rejected the draw
            continue
    raise RuntimeError(f"no valid draw in {DRAW_ATTEMPTS} attempts from seed {seed}")


@functools.lru_cache(maxsize=1)
def _provider() -> type:
    from hypothesis.internal.conjecture.providers import HypothesisProvider

    class SeedOnly(HypothesisProvider):
        """Hypothesis' provider, never drawing the constants of the imported modules (:func:`draw`)."""

        def _maybe_draw_constant(self, *args, **kwargs):
            return None

    return SeedOnly


def _draw_with_engine(strategy, seed: int):
    from hypothesis import HealthCheck, Phase, given, settings
    from hypothesis import seed as hseed

    drawn: list = []

    # two examples: the engine's first is the simplest (every choice at its minimum), the second is drawn
    @settings(max_examples=2, derandomize=False, database=None, phases=[Phase.generate], deadline=None,
              suppress_health_check=list(HealthCheck))
    @given(strategy)
    def collect(value) -> None:
        drawn.append(value)

    with no_local_constants():          # the test engine mixes in the imported modules' literals: not here
        hseed(seed)(collect)()
    return drawn[-1]


def generated_problems(seed: int = 0, count: int = len(STRATA)) -> list[Problem]:
    """Problems ``#0 .. #count-1`` of battery seed ``seed``."""
    return [generated_problem(valid_seed(seed), i) for i in range(valid_count(count))]


__all__ = ["STRATA", "SEED_STRIDE", "generated_problem", "generated_problems", "draw"]
