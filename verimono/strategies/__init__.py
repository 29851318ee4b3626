"""Hypothesis strategies for verimono's objects, valid by construction and shrinking toward simple cases.

Every strategy builds its object so that the property it is advertised with holds exactly in exact
arithmetic (no ``assume``/``filter`` rejection): a PSD matrix is ``LLᵀ + S`` with ``S`` skew, a polyhedron
is built around a point it contains, a passive system is solved from a negative semidefinite KYP block.
Everything shrinks toward the zero/identity/smallest case (dimension 1, zero entries, rank 0, constant in
time, one grid cell).

Bounds (so that conditioning stays moderate and the tolerances of :mod:`verimono.core.tolerances` apply):

* dimensions ``1 ≤ n ≤ MAX_DIM = 6`` when drawn, ``1 ≤ m ≤ 6`` inputs;
* points have entries in ``[-POINT_SCALE, POINT_SCALE] = [-10, 10]``;
* :func:`psd_matrices`: ``M = LLᵀ + W - Wᵀ`` with entries of ``L`` and ``W`` in ``[-1, 1]``, so
  ``|M_ij| ≤ n + 2 ≤ 8``; ``M + Mᵀ = 2LLᵀ`` has rank ``≤ rank`` (singular ones included);
* sets: centres/offsets in ``[-5, 5]``, radii and widths in ``[0, 5]`` (degenerate ones included),
  normals with a component of size ``≥ 1/2``; polyhedra have ``≤ 2n`` inequality rows (each with a
  component ``≥ 1/2``) and ``≤ n - 1`` equality rows, and contain the drawn point ``p``;
* time dependence on ``[0, T]`` through :class:`TimeFunction` (constant, affine, sinusoid with
  ``ω ≤ 2π``), each with a stated Lipschitz constant; moving sets carry ``φ`` with (A3)
  ``sup_{z ∈ S(s)} dist(z, S(t)) ≤ φ(t) - φ(s)``;
* passive systems: KYP data with entries in ``[-2, 2]``, storage ``K = U diag(k) Uᵀ`` with
  ``k ∈ {0} ∪ [1/4, 4]``;
* matrix entries and constraint normals have components 0 or at least ``ENTRY_FLOOR = 1e-3`` in magnitude
  (no rounding-sized entries, no constraints 1e-7 apart in angle);
* grids: ``1 ≤ K ≤ 64`` cells, nonuniform ones with step ratios ``≤ 100``.

Drawn objects have readable reprs (numbers rounded to 4 digits) so counterexamples can be read.

The strategies live in one module per concept — :mod:`.values` (points, step sizes, times, matrices, functions
of time, inputs, the functions φ/σ/θ of the assumptions), :mod:`.sets` (convex and moving sets),
:mod:`.operators` (operators with their stated assumptions, the fixed catalog), :mod:`.systems` (passive and
complementarity systems of Section 7), :mod:`.partitions` (time grids) and :mod:`.problems` (whole problems
with ``f``, ``u`` and ``x0`` on or near a moving boundary, for the stepper battery) — and every name is
re-exported here: ``verimono.strategies.<name>`` is the public spelling.
"""

from __future__ import annotations

from .values import (ENTRY_FLOOR, MAX_CELLS, MAX_DIM, POINT_SCALE, SET_SCALE, ZERO, ACInput, Constant, Rate,
                     TimeFunction, ac_inputs, floats, points, psd_matrices, step_sizes, time_functions, times)
from .sets import MovingSet, convex_sets, moving_sets
from .operators import (LOGBARRIER_YB, Stated, catalog, catalog_operators, maximal_monotone_operators,
                        monotone_linear_operators, stated_linear_operators, stated_moving_set_normal_cones,
                        stated_operators, stated_subdifferential_operators, subdifferential_operators)
from .systems import LCS_MU_FLOOR, PassiveSystem, lcs_operators, passive_systems
from .partitions import grids

#: names of :mod:`.problems` (problems of the stepper battery), imported on first use: a run that never draws a
#: problem does not make its strategies
_LAZY = ("stated_problems", "moving_domains", "lipschitz_fields", "every_coordinate_inputs", "LipschitzField",
         "OffsetInput", "MAX_PROBLEM_DIM")


def __getattr__(name: str):
    if name in _LAZY:
        from . import problems

        return getattr(problems, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

__all__ = [
    "MAX_DIM", "POINT_SCALE", "SET_SCALE", "floats", "points", "step_sizes", "times", "TimeFunction",
    "time_functions", "psd_matrices", "monotone_linear_operators", "convex_sets", "MovingSet", "moving_sets",
    "subdifferential_operators", "maximal_monotone_operators", "catalog", "catalog_operators", "PassiveSystem",
    "passive_systems", "Stated", "stated_linear_operators", "stated_subdifferential_operators",
    "stated_moving_set_normal_cones", "stated_operators", "lcs_operators", "LCS_MU_FLOOR", "LOGBARRIER_YB",
    "ACInput", "ac_inputs", "grids", "Constant", "Rate", "ZERO", "ENTRY_FLOOR", "MAX_CELLS", *_LAZY,
]
