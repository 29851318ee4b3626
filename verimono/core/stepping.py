"""The proximal ("catching-up", implicit Euler) scheme and its trajectories.

On a partition ``0 = t_0 < ... < t_K = T`` with steps ``h_{k+1} = t_{k+1} - t_k`` the paper's scheme
(Section 5.1, labels ``eq:iteration`` and ``e:discrete-yosida``) is

    x_{k+1} = (I + h_{k+1} F(t_{k+1}, ·))^{-1}(x_k),

i.e. ``(x_k - x_{k+1})/h_{k+1} ∈ F(t_{k+1}, x_{k+1})``.  The Lipschitz field ``f`` and the input ``u`` of
Section 6 enter explicitly before the resolvent (the ``G(t, ξ) = F(t, ξ + ∫u)`` shift of lemma
``l:extinput`` and the Picard iteration of the Lipschitz theorem, discretised):

    x_{k+1} = J_{h_{k+1} F(t_{k+1},·)}(x_k + h_{k+1} f(x_k) + ∫_{t_k}^{t_{k+1}} u).

A *stepper* is any callable ``stepper(problem, t_grid)`` returning the values at the grid points, an
array of shape ``(len(t_grid), n)``; :func:`solve` is one and returns a :class:`Trajectory`, which
converts with ``np.asarray``.
"""

from __future__ import annotations

from typing import Any, Callable, Iterator

import numpy as np

from ._validate import real_array
from .arrays import as_float64
from .claims import Claim
from .errors import InvalidProblem, SolverFailure
from .grids import validate_grid
from .operators import resolvent_kernel
from .problem import Problem
from .tolerances import judged_precision


class Trajectory:
    """Discrete solution ``x_0, ..., x_K`` on the grid ``t_0, ..., t_K``.

    ``x`` has shape ``(K+1, n)`` (or ``(K+1, B, n)`` for a batch).  ``selections`` are the elements
    ``(z_k - x_{k+1})/h_{k+1} ∈ F(t_{k+1}, x_{k+1})`` with ``z_k = x_k + h f(x_k) + ∫u`` (so
    ``(x_k - x_{k+1})/h_{k+1}`` without ``f`` and ``u``).  ``extras`` carries per-step data of
    specialised steppers (multipliers and outputs of complementarity systems).
    """

    def __init__(self, t: np.ndarray, x: np.ndarray, problem: Problem | None = None,
                 extras: dict[str, np.ndarray] | None = None, precision: str = "float64") -> None:
        self.t = real_array(t, "trajectory times")
        self.x = real_array(x, "trajectory states")
        #: the precision the states were computed in (the coarsest of the resolvent's and f's outputs); the
        #: states are stored in float64, and a law judging this trajectory judges it at this precision
        self.precision = precision
        if self.x.shape[0] != self.t.shape[0]:
            raise InvalidProblem(f"trajectory has {self.x.shape[0]} states for {self.t.shape[0]} times")
        self.problem = problem
        self.extras = dict(extras or {})

    def __array__(self, dtype=None, copy=None):
        # numpy's protocol: copy=True must not hand out the trajectory's own buffer
        if dtype is None or np.dtype(dtype) == self.x.dtype:
            return self.x.copy() if copy else self.x
        if copy is False:
            raise ValueError(f"a {self.x.dtype} trajectory cannot be viewed as {np.dtype(dtype)} without a copy")
        return self.x.astype(dtype)

    def __len__(self) -> int:
        return self.t.shape[0]

    @property
    def dtype(self) -> str:
        """The precision the states were computed in (:attr:`precision`): what a conversion for the laws
        reports (:func:`verimono.core.arrays.as_float64`), so a float32 operator's trajectory is judged at float32."""
        return self.precision

    @property
    def h(self) -> np.ndarray:
        return np.diff(self.t)

    @property
    def selections(self) -> np.ndarray:
        """``y_{k+1} ∈ F(t_{k+1}, x_{k+1})`` for ``k = 0..K-1``: the scheme's discrete velocities."""
        h = self.h.reshape((-1,) + (1,) * (self.x.ndim - 1))
        p = self.problem
        f = p.f if p is not None else None
        dU = p.input_increments(self.t) if p is not None else None
        if f is None and dU is None:      # one array formed, not three (at n = 10^6 each is 1.3 GB of page faults)
            z = np.subtract(self.x[:-1], self.x[1:])
        else:
            z = self.x[:-1].copy()
            if f is not None:
                z += h * np.array([f(xk) for xk in self.x[:-1]])
            if dU is not None:
                z += dU.reshape((dU.shape[0],) + (1,) * (self.x.ndim - 2) + (dU.shape[-1],))
            z -= self.x[1:]
        z /= h
        return z

    def interpolate(self, tau: Any, kind: str = "linear", psi: Callable | None = None) -> np.ndarray:
        """Values at times ``tau``: piecewise linear in ``t``, or in ``ψ`` (the paper's ``e:x delta``).

        ``kind="psi"`` gives ``x_Δ(τ) = ((ψ(t_{k+1}) - ψ(τ)) x_k + (ψ(τ) - ψ(t_k)) x_{k+1}) /
        (ψ(t_{k+1}) - ψ(t_k))`` for a given strictly increasing ``ψ`` (the check ``psi_interpolation`` passes the ψ of the
        bounds lemmas ``lem:bndSeq`` / ``lem:bndSeqYB``).
        """
        tau = np.asarray(tau, dtype=float)
        scalar = tau.ndim == 0
        tau = np.atleast_1d(tau)
        if np.any(tau < self.t[0]) or np.any(tau > self.t[-1]):
            raise InvalidProblem(f"interpolation times must lie in [{self.t[0]}, {self.t[-1]}]")
        k = np.clip(np.searchsorted(self.t, tau, side="right") - 1, 0, len(self.t) - 2)
        if kind == "linear":
            a, b, s = self.t[k], self.t[k + 1], tau
        elif kind == "psi":
            if psi is None:
                raise InvalidProblem("kind='psi' needs a strictly increasing function psi")
            ps = np.vectorize(lambda s: float(psi(s)))
            a, b, s = ps(self.t[k]), ps(self.t[k + 1]), ps(tau)
            if np.any(b <= a):
                raise InvalidProblem("psi must be strictly increasing on the grid")
        else:
            raise InvalidProblem(f"kind must be 'linear' or 'psi', got {kind!r}")
        w = ((s - a) / (b - a)).reshape((-1,) + (1,) * (self.x.ndim - 1))
        out = (1.0 - w) * self.x[k] + w * self.x[k + 1]
        return out[0] if scalar else out

    def __repr__(self) -> str:
        return f"Trajectory(K={len(self.t) - 1}, shape={self.x.shape}, T={self.t[-1]:g})"


def solve(problem: Problem, t_grid: Any) -> Trajectory:
    """Run the proximal scheme of the paper on the partition ``t_grid`` (see the module docstring).

    Raises :class:`verimono.InvalidGrid` for a grid that is not an increasing partition of
    ``[0, problem.T]`` and :class:`verimono.SolverFailure` when the resolvent returns a value of the
    wrong shape or a non-finite value (reported with its step).

    A batch ``problem.x0`` of shape ``(B, n)`` is solved in one vectorized run (values of shape
    ``(len(t_grid), B, n)``), identical to ``B`` separate solves for the catalog operators.

    Performance: the grid is validated once; the loop calls a resolvent kernel prebound to the
    operator's constant parameters (:func:`verimono.core.operators.resolvent_kernel`), with the steps and
    times as Python floats, and writes into one preallocated array; finiteness is checked once at the
    end, vectorized.  :func:`stream` runs the same loop in blocks without keeping the trajectory.
    """
    if not isinstance(problem, Problem):
        raise InvalidProblem(f"solve expects a verimono.Problem, got {type(problem).__name__}")
    t = validate_grid(t_grid, problem.T)
    x = None
    with judged_precision() as precision:      # the resolvent's and f's precision, observed as they return
        for _, x in _march(problem, t, t.size):
            pass
    return Trajectory(t, x, problem, precision=precision.name)


#: solve accepts a batch ``x0`` of shape ``(B, n)`` (checks may run many initial points in one call)
solve.batched = True
#: verimono.solve is the paper's scheme (eq:iteration): every law applies to it (:mod:`verimono.core.claims`)
solve.claim = Claim()

#: rows per block of :func:`stream` (1 MiB of states for n = 16)
STREAM_BLOCK = 8192


def stream(problem: Problem, t_grid: Any, *, block: int = STREAM_BLOCK) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Run :func:`solve`'s scheme without storing the trajectory: yield ``(t_block, x_block)`` pieces.

    The pieces cover the grid in order (``x_block[i]`` is the state at ``t_block[i]``, the first piece
    starts with ``x_0``), with at most ``block`` rows each; the values are bit-identical to
    ``solve(problem, t_grid).x``.  ``x_block`` is a buffer reused for the next piece: copy what you keep.
    Memory is ``O(block)`` whatever the number of steps — e.g. for streaming error accumulation in
    convergence studies.  Errors as for :func:`solve`.
    """
    if not isinstance(problem, Problem):
        raise InvalidProblem(f"stream expects a verimono.Problem, got {type(problem).__name__}")
    if int(block) < 2:
        raise InvalidProblem(f"block must be at least 2 rows, got {block!r}")
    t = validate_grid(t_grid, problem.T)
    for start, xb in _march(problem, t, int(block)):
        yield t[start:start + xb.shape[0]], xb


def _march(problem: Problem, t: np.ndarray, block: int) -> Iterator[tuple[int, np.ndarray]]:
    """The scheme's loop on the validated grid ``t``, yielding ``(first index, rows)`` per block.

    With ``block >= len(t)`` there is one block: the whole trajectory in a fresh array.
    """
    h = np.diff(t)
    K = h.size
    x0 = problem.x0
    op = problem.operator
    step = resolvent_kernel(op, x0)
    f = problem.f
    block = min(block, K + 1)

    def cells(k):
        """Steps, times (as Python floats: cheap to index and to multiply) and input increments of the
        cells k, ..., k + block - 1, converted block by block so that streaming holds O(block) of them
        (the increments are computed cell by cell, so the values do not depend on the blocking)."""
        dU = problem.input_increments(t[k:k + block + 1])
        if dU is not None and x0.ndim == 2:
            dU = dU[:, None, :]
        return h[k:k + block].tolist(), t[k + 1:k + 1 + block].tolist(), dU

    hs, ts, dU = cells(0)
    buf = np.empty((block,) + x0.shape)
    buf[0] = x0
    shape = x0.shape
    first = step(_drift(x0, hs[0], f, dU, 0, shape, 1, t, problem), hs[0], ts[0])
    if type(first) is not np.ndarray or first.dtype != np.float64:
        first = _returned(first, f"the resolvent of {op.name} at step 1")
    if first.shape != shape:
        raise _bad_shape(first, 1, t, problem)
    buf[1] = first
    xk = first
    row, k, start = 2, 1, 0     # next free row of buf; next step computes x_{k+1}; grid index of buf[0]
    before = x0                 # the state preceding buf[0] (for error messages across blocks)
    plain = f is None and dU is None
    base = 0                    # hs[i], ts[i], dU[i] hold h[base + i], t[base + 1 + i], ∫ u over cell base + i
    while True:
        m = min(block - row, K - k)
        if m > 0:
            if k + m > base + len(hs):  # this block's steps are not all converted yet
                base = k
                hs, ts, dU = cells(k)
            lo = k - base
            # every step's shape is checked (one tuple comparison: a value of another shape would be
            # broadcast into the row silently — a scalar into every component); finiteness is checked
            # per block, vectorized, by _check_finite
            try:
                if plain:
                    xk = _plain_steps(step, xk, buf, row, hs[lo:lo + m], ts[lo:lo + m], shape)
                else:
                    xk = _drift_steps(step, xk, buf, row, k, m, base, hs, ts, f, dU, shape, t, problem)
            except _Stray as stray:
                raise _bad_shape(stray.value, start + stray.row, t, problem) from None
            k += m
            row += m
        out = buf[:row]
        _check_finite(out, start, before, t, problem)
        yield start, out
        if k >= K:
            return
        before = out[-1].copy()
        start += row
        row = 0


class _Stray(Exception):
    """A resolvent value that is not an array of the state's shape, met at ``row`` of the block (:func:`_march`)."""

    def __init__(self, row: int, value: Any) -> None:
        self.row, self.value = row, value


# The stepping loops are small functions of their own, not loops inside ``_march``: under :mod:`tracemalloc` (the
# performance stage's memory record traces a 10^5-step study) every allocation looks up its line number by scanning
# the allocating function's line table from its start (CPython 3.11), so an allocation in a loop deep inside a long
# function costs several times one near the start of a short one (a traced 10^5-step solve of t|x| in R^10: 1.63-1.65 s
# with the loops inside ``_march``, 1.25-1.43 s here, 4 alternating rounds; untraced 0.20-0.23 s either way).  The
# same operations in the same order.

def _plain_steps(step: Callable, xk: np.ndarray, buf: np.ndarray, row: int, hs: list, ts: list,
                 shape: tuple) -> np.ndarray:
    """``buf[row], buf[row + 1], ...`` = the scheme's states after ``xk`` with steps ``hs`` at times ``ts`` (no
    field, no input); the last state.  A value not of ``shape`` (or no array) raises :class:`_Stray`."""
    i = row
    try:
        for hk, tk in zip(hs, ts):
            xk = step(xk, hk, tk)
            if xk.shape != shape:
                raise _Stray(i, xk)
            buf[i] = xk
            i += 1
    except AttributeError:
        if not hasattr(xk, "shape"):   # a resolvent returning a list or a float
            raise _Stray(i, xk) from None
        raise
    return xk


def _drift_steps(step: Callable, xk: np.ndarray, buf: np.ndarray, row: int, k: int, m: int, base: int, hs: list,
                 ts: list, f: Any, dU: Any, shape: tuple, t: np.ndarray, problem: Problem) -> np.ndarray:
    """As :func:`_plain_steps`, each step from ``x_j + h_j f(x_j) + ∫u`` (:func:`_drift`), for the steps
    ``j = k, ..., k + m - 1`` (``hs[j - base]``, ``ts[j - base]``, ``dU[j - base]``)."""
    i = row
    try:
        for j in range(k, k + m):
            xk = step(_drift(xk, hs[j - base], f, dU, j - base, shape, j + 1, t, problem), hs[j - base], ts[j - base])
            if xk.shape != shape:
                raise _Stray(i, xk)
            buf[i] = xk
            i += 1
    except AttributeError:
        if not hasattr(xk, "shape"):
            raise _Stray(i, xk) from None
        raise
    return xk


def _returned(value: Any, what: str) -> np.ndarray:
    """A value the problem's members returned, as float64 with its precision observed (a float32 resolvent
    makes a float32 trajectory, :attr:`Trajectory.precision`); any array library's arrays are converted."""
    try:
        return as_float64(value)
    except (TypeError, ValueError):
        return real_array(value, what)      # the typed error for complex or non-numeric values


def _check_finite(out, start, before, t, problem):
    with np.errstate(all="ignore"):   # a finite sum: every state finite, read without a boolean array of them all
        if np.isfinite(np.add.reduce(out, axis=None)):
            return
    if np.isfinite(out).all():        # a sum that overflowed on finite states
        return
    bad = int(np.flatnonzero(~np.isfinite(out.reshape(out.shape[0], -1)).all(axis=1))[0])
    prev = out[bad - 1] if bad > 0 else before
    k = start + bad
    raise SolverFailure(f"non-finite state at step {k} (t = {t[k]:g}) of {problem.name}: the resolvent "
                        f"of {problem.operator.name} returned {out[bad]} from x = {prev}")


def _bad_shape(value, k, t, problem) -> SolverFailure:
    """The error for a resolvent value of the wrong shape (or no array at all) at step ``k``."""
    shape = getattr(value, "shape", None)
    what = f"shape {shape}" if shape is not None else f"a {type(value).__name__}"
    return SolverFailure(f"the resolvent of {problem.operator.name} returned {what} for a point of shape "
                         f"{problem.x0.shape} at step {k} (t = {t[k]:g}) of {problem.name}")


def _drift(xk, hk, f, dU, k, shape=None, step=0, t=None, problem=None):
    """``x_k + h f(x_k) + ∫u`` for the cell ``k`` of the current block (``step``: the index of the state it
    leads to, for messages); ``f(x_k)`` must have the state's shape — a scalar would be broadcast."""
    z = xk
    if f is not None:
        fx = f(xk)
        if type(fx) is not np.ndarray or fx.dtype != np.float64:
            fx = _returned(fx, "f(x)")
        if shape is not None and fx.shape != shape:
            where = f" at step {step} (t = {t[step - 1]:g}, evaluated at x_{step - 1})" if t is not None else ""
            raise SolverFailure(f"f returned shape {fx.shape} for a state of shape {shape}{where} of "
                                f"{problem.name if problem is not None else 'the problem'}")
        z = z + hk * fx
    if dU is not None:
        z = z + dU[k]
    return z


__all__ = ["Trajectory", "solve", "stream"]
