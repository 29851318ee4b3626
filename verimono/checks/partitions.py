"""The drivers of the stepper laws: running a stepper on partitions of ``[0, T]`` and judging each.

A *stepper* is a callable ``stepper(problem, t_grid)`` returning ``x_0, ..., x_K`` (shape ``(K+1, n)``).
A stepper law is one decorated evaluator (:func:`stepper_law`), of one of two forms:

* ``over_grids=True``: ``check_<law>(stepper, problem, t, **kw) -> Outcome`` judges the stepper's solution on
  one partition ``t``.  The driver (:func:`run_on_grids`) evaluates it on every partition of the battery
  (:func:`battery_grids`: uniform and random, or those given; for the step laws every partition the battery
  builds, :func:`every_battery_grid`, and its convergence study's), keeps the worst, and shrinks a failure to
  the shortest prefix ``[0, t_k]`` of its partition that still fails (re-verified), so the counterexample
  holds the problem, the partition, the initial point and the offending step;
* otherwise ``check_<law>(stepper, problem, **kw) -> Outcome`` judges the stepper as a whole (a unique
  limit over refinements, a convergence order): :func:`run_once`.

A stepper claiming ``grids="uniform"`` (:class:`verimono.Stepper`: it steps ``t_n = n T/K`` and refuses any
other partition) is judged on the uniform partitions of the battery only (:func:`claimed_grids`): every kind
the battery builds has a uniform partition of the same resolution among them, so no law is failed or skipped
because the stepper refused the others, and each record says which were left out (``details["grids"]``, the
message).

The laws are stated per initial point: a batch problem is checked through its first row.  Requirements
(what the stepper claims, what the problem states) are judged before the stepper runs; every exception
is judged by the core's one policy (:func:`verimono.checks.core.classify`).  Under a unit's time budget
(:func:`verimono.execution.timeouts.run_unit`: ``check_stepper`` and the stepper stages run every law in one) a
per-partition law states its progress partition by partition: stopped by the budget after partitions that
all held, its record is *undecided* (time budget, ``k`` partitions), not a failure of the stepper; stopped
before any partition returned, or after one that failed, it is failed.  A law of the stepper as a whole
(:func:`run_once`: one evaluation, no partial evidence) stopped by the budget is failed.
"""

from __future__ import annotations

import functools
from typing import Any, Callable

import numpy as np

from ..core._validate import states_shape_error
from ..core.arrays import as_float64, precision_of
from ..core.claims import claim_of
from ..core.grid_design import cells_of
from ..core.grids import graded_grid, random_grid, uniform_grid, validate_grid
from ..core.problem import Problem
from ..core.stepping import Trajectory, solve
from ..records.results import PASSED
from ..execution.timeouts import note_progress
from .core import Outcome, law, run, stepper_subject
from .arguments import valid_seed
from .shared_runs import noted_partitions, remembered
from .subjects import require_problem, require_stepper

#: cells of the default partitions (fine enough for the lemmas' bounds, fast enough for a battery)
DEFAULT_CELLS = 40
#: cells of the refinement levels of ``unique_limit`` (:mod:`verimono.checks.limits`; |Δ| shrinks 16-fold)
LIMIT_LEVELS = (10, 40, 160)
#: nonuniformity of the default random partition (cell lengths vary by a factor up to 4)
RANDOM_SPREAD = 0.6
#: the law's form for a stepper claiming only ``scheme="any"``, by law name (``in_domain``: a distance to
#: the domain vanishing at the claimed order, instead of exact membership at every node)
ANY_SCHEME_FORM: dict[str, Callable[..., Outcome]] = {}
#: laws judged on every partition the battery builds (:func:`every_battery_grid`), not only the two default ones:
#: the step laws on one trajectory (``selections``, ``in_domain``, ``bounds_lg``, ``bounds_yb``), whose verdict on
#: a stepper that deviates on some steps only (a Newton solve stopped at a residual of 1e-4: off on the small
#: steps) must not depend on which partitions a seed happened to draw
EVERY_GRID: set[str] = set()
#: laws judged on the partitions of the stepper's convergence study as well — its finest grid and those where its
#: errors fell short (:func:`verimono.checks.shared_runs.note_partitions`): the step laws above and
#: ``contraction`` (whose pairs of runs from other starts are new runs: on the default partitions and these, not on
#: every one), so a scheme that changes on steps finer than the battery's partitions is judged there
STUDY_GRID: set[str] = set()


def single(problem: Problem) -> Problem:
    """The laws are stated per initial point: a batch is checked through its first row."""
    return problem.replace(x0=problem.x0[0]) if problem.batched else problem


def run_stepper(stepper: Callable, problem: Problem, grid: np.ndarray) -> np.ndarray:
    """``stepper(problem, grid)`` as a float array of shape ``(K+1, n)``, finite (else ``ValueError``); inside
    :func:`verimono.checks.shared_runs.shared_runs`, run once per (stepper, problem, partition)."""
    return remembered(stepper, problem, grid, lambda: _validated_run(stepper, problem, grid))


def _validated_run(stepper: Callable, problem: Problem, grid: np.ndarray) -> tuple[np.ndarray, str | None]:
    raw = stepper(problem, grid)
    precision = precision_of(raw)
    # any array library, its precision observed; always a copy: a law that holds this run while it runs the
    # stepper again (contraction's other starts) must judge the values returned, not what a stepper handing out
    # one shared buffer writes into it later (that stepper fails trajectory_immutable) — except the states of
    # verimono's own scheme (the function itself, not a declaration a stepper could make): solve returns a
    # Trajectory of a fresh array nothing else holds (a copy was 1.3 GB of page faults per 161 nodes at n = 10^6)
    if stepper is solve and type(raw) is Trajectory and type(raw.x) is np.ndarray and raw.x.dtype == np.float64:
        x = raw.x
    else:
        x = np.array(as_float64(raw), dtype=float, copy=True)
    if x.shape != (len(grid),) + problem.x0.shape:
        raise states_shape_error(stepper_subject(stepper, problem).split(' on ')[0], x.shape, len(grid),
                                 problem.x0.shape)
    if not all_finite(x):
        raise ValueError("the stepper returned non-finite states")
    return x, precision


def all_finite(x: np.ndarray) -> bool:
    """Whether every number of ``x`` is finite: its sum is finite then (a NaN or an infinity makes it NaN or
    infinite), read in one pass without the boolean array ``np.isfinite`` forms (161 MB for a 161-node run at
    n = 10^6); a sum that overflows on finite numbers is decided by ``np.isfinite``."""
    with np.errstate(all="ignore"):
        if np.isfinite(np.add.reduce(x, axis=None)):
            return True
    return bool(np.all(np.isfinite(x)))


def _built_once(build: Callable[..., dict[str, np.ndarray]]) -> Callable[..., dict[str, np.ndarray]]:
    """``build(*key)`` made once per key (hashable arguments), each call given its own copies: every law of a
    battery asks for the same partitions of every problem (a battery built them 640 times, 0.1 s)."""
    made = functools.lru_cache(maxsize=512)(build)

    def grids(*key: Any) -> dict[str, np.ndarray]:
        try:
            hash(key)
        except TypeError:        # an argument the builder refuses with its own error
            return build(*key)
        return {name: g.copy() for name, g in made(*key).items()}
    return grids


@_built_once
def _default_grids(T: float, seed: int, cells: int) -> dict[str, np.ndarray]:
    return {"uniform": uniform_grid(T, steps=cells), "random": random_grid(T, cells, seed=seed, spread=RANDOM_SPREAD)}


def default_grids(problem: Problem, seed: int = 0, cells: int = DEFAULT_CELLS) -> dict[str, np.ndarray]:
    """A uniform and a random (nonuniform) partition of ``[0, T]`` with ``cells`` cells."""
    return _default_grids(problem.T, seed, cells)


@_built_once
def _limit_grids(T: float, K: int, seed: int) -> dict[str, np.ndarray]:
    return {"uniform": uniform_grid(T, steps=K), "random": random_grid(T, K, seed=seed, spread=RANDOM_SPREAD),
            "graded": graded_grid(T, K, 2.0)}


def limit_grids(T: float, K: int, seed: int = 0) -> dict[str, np.ndarray]:
    """Uniform, random and graded (``t_k = T (k/K)²``) partitions with ``K`` cells."""
    return _limit_grids(T, K, seed)


def refined_random_grid(T: float, K0: int, K: int, seed: int = 0) -> np.ndarray:
    """The random partition of ``K0`` cells (:func:`limit_grids`) with every cell split in ``K/K0`` equal
    parts: the random kind as a refinement sequence (``K`` a multiple of ``K0``)."""
    base = limit_grids(T, K0, seed)["random"]
    sub = np.linspace(0.0, 1.0, K // K0 + 1)[:-1]
    return np.append((base[:-1, None] + np.diff(base)[:, None] * sub[None, :]).ravel(), T)


#: the neighbours' cell ratios ``h_k/h_{k-1}`` the strongly non-uniform partitions (:func:`ratio_grids`) span: a
#: step-size controller's output after rejected steps, a mesh graded toward a kink.  The battery's other partitions
#: stay within ``[0.29, 3.5]`` (``RANDOM_SPREAD``, the graded ``(k/K)²``): a scheme changed only where a cell is
#: shorter than a quarter of the one before was the paper's scheme on all of them (blind set 8, ``merges_short_cells``)
CELL_RATIOS = (1e-3, 1e3)
#: cells of each strongly non-uniform partition
RATIO_CELLS = 40


def ratio_grids(T: float, seed: int = 0) -> dict[str, np.ndarray]:
    """Two strongly non-uniform partitions of ``[0, T]`` with ``RATIO_CELLS`` cells, neighbours' ratios over
    :data:`CELL_RATIOS`: ``"ratios random"`` — cell lengths ``10^u``, ``u`` uniform in ``[-3, 0]`` (seeded; its
    first cells ``1, 10^-3, 1``: both ends of the range met), and ``"ratios graded"`` — the cascade ``1, 10^-1,
    10^-2, 10^-3`` repeated (each cell a tenth of the one before, then a thousandfold jump)."""
    return _ratio_grids(float(T), int(seed))


@_built_once
def _ratio_grids(T: float, seed: int) -> dict[str, np.ndarray]:
    lo, hi = (float(np.log10(r)) for r in CELL_RATIOS)
    span = (hi - lo) / 2.0                                  # cell lengths over half the ratios' decades
    w = 10.0 ** np.random.default_rng([int(seed) % (2 ** 63), 0x5A71]).uniform(-span, 0.0, RATIO_CELLS)
    w[:3] = (1.0, 10.0 ** -span, 1.0)
    cascade = 10.0 ** -np.resize(np.arange(int(round(span)) + 1, dtype=float), RATIO_CELLS)
    out = {}
    for name, cells in (("ratios random", w), ("ratios graded", cascade)):
        t = np.concatenate([[0.0], np.cumsum(cells)]) * (T / cells.sum())
        t[-1] = T
        out[name] = validate_grid(t, T)
    return out


def cell_ratio_range(parts: dict[str, np.ndarray]) -> list[float]:
    """``[min, max]`` of the neighbours' cell ratios ``h_k/h_{k-1}`` over the partitions ``parts`` (``[1, 1]``
    when none has two cells): what a per-partition law's record states it searched."""
    lo, hi = 1.0, 1.0
    for g in parts.values():
        h = np.diff(np.asarray(g, dtype=float))
        if h.size > 1:
            r = h[1:] / h[:-1]
            lo, hi = min(lo, float(r.min())), max(hi, float(r.max()))
    return [lo, hi]


def every_battery_grid(problem: Problem, seed: int = 0) -> dict[str, np.ndarray]:
    """Every partition the battery builds for ``problem``: :func:`default_grids`, the graded one of as many
    cells, the convergence grids of ``unique_limit`` (:func:`limit_grids` at each of ``LIMIT_LEVELS``, the random
    kind refined from the first level's) and the strongly non-uniform ones (:func:`ratio_grids`); duplicates
    dropped."""
    return _every_battery_grid(problem.T, seed)


@_built_once
def _every_battery_grid(T: float, seed: int) -> dict[str, np.ndarray]:
    out = dict(_default_grids(T, seed, DEFAULT_CELLS))
    out["graded"] = graded_grid(T, DEFAULT_CELLS, 2.0)
    K0 = LIMIT_LEVELS[0]
    for K in LIMIT_LEVELS:
        gs = limit_grids(T, K, seed)
        if K % K0 == 0 and K != K0:
            gs["random"] = refined_random_grid(T, K0, K, seed)
        for kind, g in gs.items():
            if not any(len(g) == len(h) and np.array_equal(g, h) for h in out.values()):
                out[f"{kind} K={K}"] = g
    out.update(_ratio_grids(T, seed))
    return out


def battery_grids(grids: Any, problem: Problem, seed: int, *, every: bool = False,
                  stepper: Callable | None = None, study: bool = False) -> dict[str, np.ndarray]:
    """The partitions a law is judged on: ``grids`` (a dict or a list of increasing arrays from 0 to ``T``),
    else :func:`default_grids` and the strongly non-uniform :func:`ratio_grids` (``every=True``:
    :func:`every_battery_grid`, which holds them), with ``study=True`` the partitions of
    ``stepper``'s convergence study on ``problem`` noted in the :func:`verimono.checks.shared_runs.shared_runs`
    block."""
    if grids is None:
        out = every_battery_grid(problem, seed) if every else {**default_grids(problem, seed),
                                                               **ratio_grids(problem.T, seed)}
        for g in noted_partitions(stepper, problem) if study and stepper is not None else []:
            if abs(g[-1] - problem.T) <= 1e-12 * max(1.0, problem.T) and not any(
                    len(g) == len(h) and np.array_equal(g, h) for h in out.values()):
                out[f"study K={len(g) - 1}"] = validate_grid(g, problem.T)
        return out
    if isinstance(grids, dict):
        return {k: validate_grid(g, problem.T) for k, g in grids.items()}
    return {f"grid{i}": validate_grid(g, problem.T) for i, g in enumerate(grids)}


def claimed_grids(stepper: Callable | None, parts: dict[str, np.ndarray], T: float
                  ) -> tuple[dict[str, np.ndarray], list[str]]:
    """``(kept, left_out)``: the partitions of ``parts`` the stepper claims to run on — the uniform ones
    (``np.linspace(0, T, K + 1)``: ``t_K = T`` exactly) for ``grids="uniform"``, all of them otherwise — and
    the names of the others.  A uniform partition of as many cells replaces each one left out that has no
    uniform twin among ``parts`` (the same resolution, the kind the stepper runs)."""
    if stepper is None or not claim_of(stepper).uniform:
        return parts, []
    kept = {k: g for k, g in parts.items() if cells_of(g, T) is not None}
    left = [k for k in parts if k not in kept]
    for k in left:
        K = len(parts[k]) - 1
        if not any(len(g) == K + 1 for g in kept.values()):
            kept[f"uniform K={K}"] = uniform_grid(T, steps=K)
    return kept, left


def grids_note(left_out: list[str]) -> tuple[dict, str]:
    """What a record of a ``grids="uniform"`` stepper says of its partitions: ``details["grids"]`` and the
    message's suffix."""
    return ({"claimed": "uniform", "left_out": list(left_out)},
            " — on uniform partitions only (the stepper claims grids='uniform'"
            + (f"; left out: {', '.join(left_out)})" if left_out else ")"))


def _prefix_failure(decl: Any, stepper: Callable, p: Problem, grid: np.ndarray, k: int, kw: dict) -> Outcome | None:
    """The law re-evaluated on the prefix ``[0, t_k]`` of ``grid``, when that still fails."""
    try:
        again = decl.evaluate(stepper, p.replace(T=float(grid[k])), grid[:k + 1].copy(), **kw)
    except Exception:  # noqa: BLE001 - a prefix the law cannot evaluate is no smaller counterexample
        return None
    return again if again.failed else None


def _held(out: Outcome) -> bool:
    """Whether one partition's outcome is evidence that the law holds (decided, within its bound)."""
    return not (out.failed or out.inconclusive) and out.status in (None, PASSED)


def run_on_grids(decl: Any, stepper: Callable, problem: Problem, *, grids: Any = None, seed: int = 0,
                 **kw: Any) -> Any:
    """A per-partition law on every partition of the battery: the worst outcome, a failure shrunk to the
    shortest failing prefix of its partition (module docstring)."""
    require_stepper(stepper)
    p = single(require_problem(problem))
    seed = valid_seed(seed)
    subject = stepper_subject(stepper, p)
    any_form = ANY_SCHEME_FORM.get(decl.name)
    if any_form is not None and grids is None and not claim_of(stepper).proximal:
        return run(decl, subject, lambda: any_form(stepper, p, seed=seed), stepper=stepper, problem=p)
    parts = battery_grids(grids, p, seed, every=decl.name in EVERY_GRID, stepper=stepper,
                          study=decl.name in STUDY_GRID)
    left_out: list[str] | None = None
    if grids is None and claim_of(stepper).uniform:       # the partitions it runs on (module docstring)
        parts, left_out = claimed_grids(stepper, parts, p.T)
    kw = {"seed": seed, **kw}

    def evaluate() -> Outcome:
        outcomes: dict[str, Outcome] = {}
        for g, t in parts.items():
            outcomes[g] = decl.evaluate(stepper, p, t, **kw)
            # out of budget now, a law whose partitions all held is undecided, not failed (verimono.execution.timeouts)
            note_progress(len(outcomes), all(_held(o) for o in outcomes.values()), "partitions")
        gname = max(outcomes, key=lambda g: outcomes[g].worst)
        out = outcomes[gname]
        out.details = {"worst_by_grid": {g: o.worst for g, o in outcomes.items()},
                       "cell_ratios": cell_ratio_range(parts), **out.details}
        if left_out is not None:
            out.details["grids"], said = grids_note(left_out)
            out.message = (out.message or "") + said
        if not out.failed:
            return out
        grid = parts[gname]
        counter = {"problem": p.name, "T": p.T, "x0": p.x0, "grid": grid, "grid_kind": gname, **out.counter,
                   "shrunk": False}
        if out.k is not None and 1 <= out.k < len(grid) - 1:
            again = _prefix_failure(decl, stepper, p, grid, out.k, kw)
            if again is not None:
                counter = {"problem": p.name, "T": float(grid[out.k]), "x0": p.x0, "grid": grid[:out.k + 1],
                           "grid_kind": f"{gname} prefix [0, t_{out.k}]", **again.counter, "shrunk": True}
        out.counter = counter
        return out

    rec = run(decl, subject, evaluate, stepper=stepper, problem=p)
    if rec.status == "failed" and rec.counterexample is None:      # the stepper raised: what it was given
        rec.counterexample = {"problem": p.name, "x0": p.x0, "grids": dict(parts)}
    return rec


def run_once(decl: Any, stepper: Callable, problem: Problem, **kw: Any) -> Any:
    """A law of the stepper as a whole: its evaluator once, under the core's policy."""
    require_stepper(stepper)
    p = single(require_problem(problem))
    if "seed" in kw:
        kw["seed"] = valid_seed(kw["seed"])
    subject = stepper_subject(stepper, p)
    rec = run(decl, subject, lambda: decl.evaluate(stepper, p, **kw), stepper=stepper, problem=p)
    if rec.status == "failed" and rec.counterexample is None:      # the stepper raised: what it was given
        rec.counterexample = {"problem": p.name, "T": p.T, "x0": p.x0,
                              **{k: v for k, v in kw.items() if k in ("levels", "seed", "steps", "step_range")}}
    return rec


def stepper_law(name: str, label: str, *requires: Any, over_grids: bool = True,
                any_scheme: Callable[..., Outcome] | None = None, battery: bool = True,
                every_grid: bool = False, study_grids: bool = False) -> Callable:
    """Declare a stepper law (module docstring); ``any_scheme`` is its form for a stepper claiming only
    ``scheme="any"`` (judged once, not per partition); ``every_grid``: judged on :func:`every_battery_grid`
    when no partitions are given; ``study_grids``: on the partitions of the stepper's convergence study too."""
    if any_scheme is not None:
        ANY_SCHEME_FORM[name] = any_scheme
    if every_grid:
        EVERY_GRID.add(name)
    if study_grids:
        STUDY_GRID.add(name)
    return law(name, label, subject="stepper", driver=run_on_grids if over_grids else run_once, requires=requires,
               battery=battery)


__all__ = ["stepper_law", "run_on_grids", "run_once", "run_stepper", "single", "default_grids", "limit_grids",
           "battery_grids", "every_battery_grid", "refined_random_grid", "DEFAULT_CELLS", "RANDOM_SPREAD",
           "ANY_SCHEME_FORM", "EVERY_GRID", "STUDY_GRID", "claimed_grids", "grids_note", "ratio_grids",
           "cell_ratio_range", "CELL_RATIOS", "RATIO_CELLS"]
