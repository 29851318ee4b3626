"""Running a convergence study's grids: each grid's errors against the exact solution, or against a fine-grid
solution of the same stepper, computed as independent jobs (serially, in a process pool, or on any
``concurrent.futures`` executor) without holding trajectories.

For each grid the study records three errors against the exact solution (or, when the problem has none,
against a fine-grid solution of the same stepper, which the study says):

* ``sup``:   ``max_k |x_k - x(t_k)|`` (the norm of the paper's uniform convergence),
* ``l2``:    ``(Σ_k h_k |x_k - x(t_k)|²)^{1/2}`` (discrete L2 in time),
* ``final``: ``|x_K - x(T)|``.

Performance: the grids run as independent jobs, in parallel through any ``concurrent.futures.Executor``
(``executor=``; a ``dask.distributed`` client's ``get_executor()`` works the same), or a process pool
chosen automatically for large studies.  When the problem has an exact solution each job returns only
its three errors: with :func:`verimono.solve` as the stepper the states stream through an
:class:`ErrorAccumulator` block by block (:func:`verimono.core.stepping.stream`), so no job holds a
trajectory at all; any other stepper's trajectory is held by its job only while its errors are computed.
Without an exact solution the fine reference runs first and returns only its values at the studied
grids' nodes (streamed through a :class:`Sampler` for :func:`verimono.solve`); each grid's job then
accumulates its errors against its share of them, so neither the fine trajectory nor any grid's
trajectory reaches the caller.  A study that adds grids as it goes (:mod:`verimono.core.grid_design`) runs
each batch with :class:`GridRunner`, which keeps every grid's result and, without an exact solution, a fine
reference per batch finer than the batch's finest grid.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import os
import pickle
import sys
import time
from typing import Any, Callable, Sequence

import numpy as np

from ._validate import real_array, states_shape_error
from .arrays import as_float64
from .errors import InvalidProblem, UnitTimeout
from .grids import uniform_grid, validate_grid
from .naming import subject_name
from .problem import Problem
from .stepping import solve, stream
from .tolerances import judged_precision

NORMS = ("sup", "l2", "final")


@dataclasses.dataclass
class GridResult:
    """One grid's run: its three errors, the reference's scale ``max |x(t_k)|``, the stepper's seconds, the precision
    its states were computed in, and — for a grid the study added itself, where a stepper may refuse a step far
    larger than it was written for — what it raised (its errors are then ``nan``)."""

    errors: dict[str, float]
    scale: float | None
    seconds: float
    precision: str | None
    failure: str | None = None


class GridRunner:
    """Runs ``stepper`` on ``problem``'s grids batch by batch (:func:`convergence_study` adds grids as it learns
    what the scheme needs), in parallel on ``executor`` (:func:`_choose_executor`).

    Against the exact solution each grid is one job.  Without one, each batch first runs the same stepper on a
    uniform reference grid ``reference_refinement`` times finer than the batch's finest grid — a common multiple
    of the batch's cell counts when one is within 64 times that, so the reference's values at every node are its
    own, not interpolated — and measures the batch against it; ``references`` lists the reference steps used."""

    def __init__(self, stepper: Callable, problem: Problem, executor: Any = None, reference_refinement: int = 8):
        self.stepper, self.problem = stepper, problem
        self.executor, self.refinement = executor, int(reference_refinement)
        self.references: list[float] = []
        self.reference_precisions: list[str | None] = []

    def run(self, grids: Sequence[np.ndarray], tolerant: Sequence[bool] | bool = False) -> list[GridResult]:
        """The results of ``grids``, in order; ``tolerant`` (one flag, or one per grid): a grid on which the
        stepper raises gives a :class:`GridResult` naming the exception instead of raising (the grids the study
        chose itself, where a stepper may refuse a step far larger than it was written for)."""
        grids = list(grids)
        flags = [bool(tolerant)] * len(grids) if isinstance(tolerant, bool) else [bool(f) for f in tolerant]
        if not grids:
            return []
        p = self.problem
        if p.exact is not None:
            executor = _choose_executor(self.executor, sum(len(g) for g in grids))
            jobs = [(g, "errors", None) for g in grids]
        else:
            fine_t = uniform_grid(p.T, steps=_reference_cells(grids, p.T, self.refinement))
            executor = _choose_executor(self.executor, len(fine_t) + sum(len(g) for g in grids))
            nodes = functools.reduce(np.union1d, grids)       # the fine solution is needed only there
            at_nodes, _, _, at_precision = _run_jobs(self.stepper, p, [(fine_t, "sample", nodes)], executor)[0]
            self.references.append(p.T / (len(fine_t) - 1))
            self.reference_precisions.append(at_precision)
            jobs = [(g, "errors", at_nodes[np.searchsorted(nodes, g)]) for g in grids]
        jobs = [job + (flag,) for job, flag in zip(jobs, flags)]
        out = _run_jobs(self.stepper, p, jobs, executor)
        return [GridResult(*r) if len(r) == 4 else GridResult(*r[:4], failure=r[4]) for r in out]


def _reference_cells(grids: Sequence[np.ndarray], T: float, refinement: int) -> int:
    """Cells of the fine reference: at least ``refinement`` times the finest grid's; a common multiple of the
    grids' cell counts when they are uniform and one lies within 64 times the finest (every node then a node of
    the reference), else that many uniform cells (the reference interpolated linearly between its nodes)."""
    base = _cells_finer_than(grids, T) * refinement
    counts = [len(g) - 1 for g in grids]
    if all(np.allclose(g, np.linspace(0.0, T, len(g)), rtol=0.0, atol=1e-12 * T) for g in grids):
        lcm = functools.reduce(math.lcm, counts)
        if lcm <= 64 * base:
            return lcm * max(1, math.ceil(base / lcm))
    return base


def exact_on(problem: Problem, t: np.ndarray) -> np.ndarray:
    """Exact solution at the times ``t``, shape ``(len(t),) + x0.shape``: one call of ``problem.exact`` per time,
    or one call of ``problem.exact.on_times(t)`` when the exact solution carries that vectorized twin (which must
    return the same values; the references that have one: ``verimono.reference.subdifferential.t_norm``)."""
    if problem.exact is None:
        raise InvalidProblem(f"{problem.name} has no exact solution")
    on_times = getattr(problem.exact, "on_times", None)
    if on_times is not None:    # the same values at every time in one vectorized call (the reference's own)
        return np.asarray(on_times(np.asarray(t, dtype=float)), dtype=float)
    return np.array([np.asarray(problem.exact(s), dtype=float) for s in t.tolist()])


def _pointwise(x: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """``|x_k - ref_k|`` per grid point (the largest over a batch)."""
    diff = (np.asarray(x) - ref).reshape(ref.shape[0], -1, ref.shape[-1])
    return np.linalg.norm(diff, axis=-1).max(axis=1)


def grid_errors(t: np.ndarray, x: np.ndarray, ref: np.ndarray) -> dict[str, float]:
    """Sup, discrete-L2 and final errors of ``x`` against ``ref`` at the grid times ``t``.

    The L2 sum is exactly rounded (``math.fsum``), so :class:`ErrorAccumulator` fed the same data in
    blocks gives the same bits.
    """
    d = _pointwise(x, ref)
    h = np.diff(t)
    return {"sup": float(d.max()), "l2": math.sqrt(math.fsum((h * d[1:] ** 2).tolist())), "final": float(d[-1])}


class ErrorAccumulator:
    """Streaming :func:`grid_errors`: feed ``(t_block, x_block)`` pieces in order.

    Against ``problem.exact``, or against ``reference``: the reference values at every node of the grid,
    in order (the fine-grid reference of a study without exact solution).  Holds ``O(1)`` data besides the
    current block (and ``reference``).  ``errors()`` equals ``grid_errors`` on the whole trajectory:
    ``sup`` and ``final`` bit for bit, ``l2`` to within one rounding (its sum is carried as an exactly
    rounded double-double, error ≤ 2^-106 relative before the final rounding, so in practice bit for
    bit).  ``scale`` is ``max |x(t_k)|`` of the reference.
    """

    def __init__(self, problem: Problem, reference: np.ndarray | None = None) -> None:
        if problem.exact is None and reference is None:
            raise InvalidProblem(f"{problem.name} has no exact solution")
        self.problem = problem
        self.reference = reference
        self.sup = 0.0
        self.final = math.nan
        self.scale = 0.0
        self._l2 = [0.0, 0.0]      # running L2 sum as hi + lo (double-double, exactly rounded parts)
        self._t_last: float | None = None
        self._row = 0              # grid index of the next block's first row

    def update(self, t: np.ndarray, x: np.ndarray) -> None:
        if self.reference is None:
            ref = exact_on(self.problem, t)
        else:
            ref = self.reference[self._row:self._row + len(t)]
            if ref.shape[0] != len(t):
                raise InvalidProblem(f"the reference has {self.reference.shape[0]} values, fewer than the grid")
        self._row += len(t)
        d = _pointwise(x, ref)
        self.sup = _nanmax(self.sup, float(d.max()))      # d.max() is nan when any d is; keep it so
        self.final = float(d[-1])
        self.scale = _nanmax(self.scale, float(np.max(np.abs(ref))))
        if self._t_last is None:
            h, dd = np.diff(t), d[1:]
        else:
            h, dd = np.diff(t, prepend=self._t_last), d
        terms = self._l2 + (h * dd ** 2).tolist()
        hi = math.fsum(terms)
        terms.append(-hi)
        self._l2 = [hi, math.fsum(terms)]
        self._t_last = float(t[-1])

    def errors(self) -> dict[str, float]:
        return {"sup": self.sup, "l2": math.sqrt(math.fsum(self._l2)), "final": self.final}


def _nanmax(a: float, b: float) -> float:
    """``max`` that propagates ``nan`` (Python's ``max(0.0, nan)`` is ``0.0``: a diverged stepper would
    have looked exact)."""
    return a if (a != a or a >= b) else b


class Sampler:
    """Streaming linear interpolation of a trajectory at the increasing times ``times``.

    Feed ``(t_block, x_block)`` pieces in order; ``values`` then holds ``x`` at every time, computed as
    ``np.interp`` on the whole trajectory would (the bracketing cell and its formula do not depend on the
    blocking).  Holds the samples and one previous row.
    """

    def __init__(self, times: np.ndarray) -> None:
        self.times = np.asarray(times, dtype=float)
        self.values: np.ndarray | None = None
        self._next = 0                                   # first sample time not yet computed
        self._prev: tuple[np.ndarray, np.ndarray] | None = None

    def update(self, t: np.ndarray, x: np.ndarray) -> None:
        if self.values is None:
            self.values = np.empty((len(self.times),) + x.shape[1:])
        if self._prev is not None:                       # the cell joining the previous block to this one
            t = np.concatenate([self._prev[0], t])
            x = np.concatenate([self._prev[1], x])
        stop = int(np.searchsorted(self.times, t[-1], side="right"))
        if stop > self._next:
            tau = self.times[self._next:stop]
            flat = x.reshape(len(t), -1)
            vals = np.stack([np.interp(tau, t, flat[:, j]) for j in range(flat.shape[1])], axis=-1)
            self.values[self._next:stop] = vals.reshape((len(tau),) + x.shape[1:])
            self._next = stop
        self._prev = (t[-1:].copy(), x[-1:].copy())



def study_grids(T: float, steps: Sequence[Any]) -> list[np.ndarray]:
    """The grids of a study: a step size is the uniform grid of ``[0, T]``, an array an explicit grid."""
    return [validate_grid(s, T) if np.ndim(s) else uniform_grid(T, float(s)) for s in steps]



#: a study of at least this many steps in all runs in a process pool when ``executor=None``
PARALLEL_MIN_STEPS = 200_000


def _job(stepper, problem, grid, want, ref=None, tolerant=False):
    """One grid: ``(errors, scale, seconds, precision)`` when ``want == "errors"`` (against the exact
    solution, or against ``ref``, the reference values at the grid's nodes), ``(values at the times ref,
    None, seconds, precision)`` when ``want == "sample"``.

    ``seconds`` is the stepper's own time (streaming: the blocks' production, not the error sums);
    ``precision`` the one the stepper's states were computed in (:mod:`verimono.core.tolerances`).
    ``tolerant``: what the stepper raised (but a time budget's interrupt or a memory error) gives
    ``(nan errors, None, seconds, None, "Type: message")`` instead.
    """
    start = time.perf_counter()
    try:
        with judged_precision() as precision:
            out = _job_values(stepper, problem, grid, want, ref)
    except (UnitTimeout, MemoryError):
        raise
    except Exception as exc:  # noqa: BLE001 - a grid the study chose itself: the stepper may refuse it
        if not tolerant:
            raise
        return ({n: math.nan for n in NORMS}, None, time.perf_counter() - start, None,
                f"{type(exc).__name__}: {exc}"[:300])
    return (*out, precision.name)


def _job_values(stepper, problem, grid, want, ref=None):
    stepper, problem = _unwrap(stepper), _unwrap(problem)
    sink = ErrorAccumulator(problem, ref) if want == "errors" else Sampler(ref)
    if stepper is solve:
        spent = 0.0
        it = stream(problem, grid)
        while True:
            start = time.perf_counter()
            piece = next(it, None)
            spent += time.perf_counter() - start
            if piece is None:
                break
            sink.update(*piece)
    else:
        x, spent = _timed_run(stepper, problem, grid)
        for i in range(0, len(grid), 8192):     # in blocks, as the stream: one trajectory held, not two
            sink.update(grid[i:i + 8192], x[i:i + 8192])
    if want == "errors":
        return sink.errors(), sink.scale, spent
    return sink.values, None, spent


def _cells_finer_than(grids, T: float) -> int:
    """The fewest uniform cells of ``[0, T]`` no longer than any cell of ``grids``: ``T/h_min``, rounded
    when it is an integer up to rounding (the steps of ``uniform_grid(T, T/K)`` fall a few ulps short of
    ``T/K``: ``ceil`` would give ``K + 1`` and a reference grid that is not a refinement of the grids)."""
    k = T / min(float(np.min(np.diff(g))) for g in grids)
    return int(round(k)) if abs(k - round(k)) <= 1e-9 * k else int(math.ceil(k))


def _choose_executor(executor, total_steps):
    """``executor``, or for ``None`` a process pool above :data:`PARALLEL_MIN_STEPS` steps in all (on a
    multi-core machine), else ``"serial"``."""
    if executor is not None:
        return executor
    return "process" if total_steps >= PARALLEL_MIN_STEPS and (os.cpu_count() or 1) > 1 else "serial"


def _run_jobs(stepper, problem, jobs, executor):
    """Results of :func:`_job` for every ``(grid, want, ref[, tolerant])``, in order (largest jobs submitted
    first)."""
    if executor == "serial":
        return [_job(stepper, problem, *job) for job in jobs]
    order = sorted(range(len(jobs)), key=lambda i: -len(jobs[i][0]))
    if executor == "process":
        import multiprocessing  # with the process pool: only for a parallel study, not `import verimono`
        from concurrent.futures import ProcessPoolExecutor

        workers = max(1, min(len(jobs), os.cpu_count() or 1))
        if "fork" in multiprocessing.get_all_start_methods() and sys.platform.startswith("linux"):
            # forked workers inherit the registry: closures and lambdas need no pickling
            token = id(jobs)
            _REGISTRY[token] = (stepper, problem)
            try:
                with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("fork")) as pool:
                    futures = {i: pool.submit(_registered_job, token, *jobs[i]) for i in order}
                    return [futures[i].result() for i in range(len(jobs))]
            finally:
                _REGISTRY.pop(token, None)
        with ProcessPoolExecutor(workers) as pool:
            return _submit_all(pool, stepper, problem, jobs, order)
    if not hasattr(executor, "submit"):
        raise InvalidProblem(f"executor must be a concurrent.futures.Executor, 'process', 'serial' or None, "
                             f"got {executor!r}")
    return _submit_all(executor, stepper, problem, jobs, order)


def _submit_all(executor, stepper, problem, jobs, order):
    s, p = _Portable(stepper), _Portable(problem)
    futures = {i: executor.submit(_job, s, p, *jobs[i]) for i in order}
    return [futures[i].result() for i in range(len(jobs))]


_REGISTRY: dict[int, tuple[Any, Any]] = {}


def _registered_job(token, grid, want, ref=None, tolerant=False):
    stepper, problem = _REGISTRY[token]
    return _job(stepper, problem, grid, want, ref, tolerant)


class _Portable:
    """Wraps a stepper or problem for executors that pickle their tasks.

    Pickles as the object itself when it pickles, else through ``cloudpickle`` (the catalog's problems and
    most users' are built from lambdas and closures, which it serialises by value, captured parameters
    included).  Executors that do not pickle (threads) hand the wrapper over as is; :func:`_unwrap`.
    """

    __slots__ = ("obj",)

    def __init__(self, obj: Any) -> None:
        self.obj = obj

    def __reduce__(self):
        obj = self.obj
        try:
            pickle.dumps(obj)
            return (_identity, (obj,))
        except Exception:
            pass
        import cloudpickle

        try:
            return (pickle.loads, (cloudpickle.dumps(obj),))
        except Exception as exc:
            raise InvalidProblem(f"cannot send {subject_name(obj)} to the executor's workers: cloudpickle cannot "
                                 f"serialise it ({type(exc).__name__}: {exc}); use executor='process' (forked "
                                 "workers inherit it) or 'serial'") from None


def _identity(obj):
    return obj


def _unwrap(obj):
    return obj.obj if isinstance(obj, _Portable) else obj


def _timed_run(stepper, problem, grid):
    start = time.perf_counter()
    x = stepper(problem, grid)
    try:
        x = as_float64(x)                   # any array library; its precision observed
    except (TypeError, ValueError):
        x = real_array(x, f"the values of stepper {subject_name(stepper)}")   # complex: an error
    if x.shape != (len(grid),) + problem.x0.shape:
        raise states_shape_error(subject_name(stepper), x.shape, len(grid), problem.x0.shape)
    return x, time.perf_counter() - start


__all__ = ["GridRunner", "GridResult", "study_grids", "grid_errors", "exact_on", "ErrorAccumulator", "Sampler",
           "NORMS", "PARALLEL_MIN_STEPS"]
