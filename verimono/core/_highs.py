"""``scipy.optimize.linprog(..., method="highs")`` for small dense LPs, without its wrapper.

For the LPs of Section 7 (4–20 variables) ``linprog``'s Python costs ~8× HiGHS' own solve: it re-validates its
inputs, converts the matrix through ``scipy.sparse``, and builds an options manager for each of five option
checks on every call (profiled on the Example's ``lcs.rel_int``: 3.4 ms a call, 0.36 ms of it in HiGHS).
:func:`linprog_highs` hands HiGHS the **same model with the same options** — the options object made once by
the checks SciPy's ``_highs_wrapper`` makes, the matrix in the same compressed-column form, infinite bounds as
``kHighsInf`` — on a solver instance in a fresh one's state (one per thread, ``clear()``-ed before each call; SciPy makes a new
one per call), and applies SciPy's own acceptance test
(``_check_result``: an optimal point within ``√tol·10`` of its bounds and rows).  Its status, objective and
point are bit for bit ``linprog``'s (``tests/lcs/test_lcs_highs.py`` compares them on random, degenerate,
infeasible and unbounded LPs).  Only the default options of ``linprog(method="highs")`` are reproduced.
"""

from __future__ import annotations

import math
import threading
import warnings

import numpy as np

#: SciPy's ``linprog`` default ``tol`` (``_parse_linprog``), and the acceptance tolerance ``_check_result``
#: derives from it
_TOL = 1e-9
_CHECK_TOL = float(np.sqrt(_TOL) * 10)

_state: dict = {}


def _core():
    """HiGHS' bindings and the options object of ``linprog(method="highs")``'s defaults, made once; ``None``
    when this SciPy's private HiGHS modules are not the ones read here (``linprog`` itself is then called)."""
    if not _state:
        try:
            import scipy.optimize._highspy._core as h
            from scipy.optimize._highspy import _highs_options as hopt
            from scipy.optimize._highspy._highs_wrapper import check_option
            h.HighsLp, h._Highs, h.HighsOptions, h.kHighsInf, h.MatrixFormat.kColwise   # noqa: B018 - present?
        except (ImportError, AttributeError):                                   # pragma: no cover
            _state["h"] = None
            return None

        # the options _linprog_highs passes at its defaults, filtered and checked as _highs_wrapper does
        options = {"presolve": True, "highs_debug_level": h.HighsDebugLevel.kHighsDebugLevelNone,
                   "log_to_console": False, "output_flag": False,
                   "simplex_strategy": h.simplex_constants.SimplexStrategy.kSimplexStrategyDual}
        manager, probe, opts = hopt.HighsOptionsManager(), h._Highs(), h.HighsOptions()
        for key, val in options.items():
            if manager.get_option_type(key) == -1:
                raise RuntimeError(f"HiGHS does not know the option {key!r}")    # pragma: no cover
            if key == "presolve":
                val = "on" if val else "off"
            opt_type = h.HighsOptionType(manager.get_option_type(key))
            status, msg = check_option(probe, key, val)
            if opt_type == h.HighsOptionType.kBool and not isinstance(val, bool):
                continue                                                       # pragma: no cover
            if status != 0:
                warnings.warn(msg, stacklevel=2)                              # pragma: no cover
                continue                                                       # pragma: no cover
            setattr(opts, key, val)
        _state.update(h=h, options=opts, inf=h.kHighsInf)
    return _state


def _replace_inf(x: np.ndarray, inf: float) -> np.ndarray:
    infs = np.isinf(x)
    if infs.any():
        with np.errstate(invalid="ignore"):
            x[infs] = np.sign(x[infs]) * inf
    return x


#: the fixed part of the models :func:`linprog_highs` built (everything but the rows' upper bounds ``b_ub``), by the
#: exact bytes of the arrays it is made of: a search asks hundreds of LPs of one system that differ in ``b_ub``
#: alone (Section 7's margin LP at each time ``t``); emptied past :data:`_MODELS_MAX` entries
_MODELS: dict = {}
_MODELS_MAX = 64


def _fixed_part(inf, c, A_ub, n_ub, A_eq, b_eq, lb, ub) -> tuple:
    """What of :func:`linprog_highs`'s model does not depend on ``b_ub``, the arrays as the one-call path made
    them: ``(bounds, b_eq, lower rows, column starts, row indices, values, lb, ub)`` (read only)."""
    nv = c.size
    bounds = np.column_stack([lb, ub])                  # as _clean_inputs makes them, for _check_result
    with np.errstate(invalid="ignore"):
        lhs = np.concatenate((-np.ones(n_ub) * np.inf, b_eq))
    # the compressed columns scipy.sparse.csc_array makes of the dense matrix (its nonzeros, column by
    # column, rows ascending)
    At = np.vstack((A_ub, A_eq)).T
    cols, rows = np.nonzero(At)
    data = At[cols, rows]
    indptr = np.zeros(nv + 1, dtype=np.int32)
    np.cumsum(np.bincount(cols, minlength=nv), out=indptr[1:])
    lhs = _replace_inf(lhs, inf)
    lb, ub = _replace_inf(lb.copy(), inf), _replace_inf(ub.copy(), inf)
    out = (bounds, b_eq, lhs, indptr, rows.astype(np.int32), data, lb, ub)
    for a in out:
        a.flags.writeable = False
    return out


#: one HiGHS instance per thread, cleared before each LP (:func:`_solver`)
_LOCAL = threading.local()


def _solver(h):
    """A HiGHS instance in the state a fresh one is in: this thread's, ``clear()``-ed (its options reset, its model,
    presolve, basis, solution and simplex data dropped: HiGHS' ``Highs::clear``), made once.  Constructing one costs
    ~150 µs, half of a Section 7 margin LP's call; ``clear()`` ~1 µs.  The options are passed again after it, as to
    a fresh instance, and nothing of a previous solve is handed on (``tests/lcs/test_lcs_highs.py`` compares
    sequences of random, degenerate, infeasible and unbounded LPs with ``linprog``'s answers, bit for bit)."""
    highs = getattr(_LOCAL, "highs", None)
    if highs is None:
        highs = _LOCAL.highs = h._Highs()
    else:
        highs.clear()
    return highs


def linprog_highs(c, A_ub, b_ub, A_eq=None, b_eq=None, lb=None, ub=None):
    """``linprog(c, A_ub, b_ub, A_eq, b_eq, bounds=zip(lb, ub), method="highs")``'s ``(status, fun, x)``.

    ``A_ub``, ``A_eq`` dense; ``lb``/``ub`` arrays (``±inf`` for none; default ``0`` and ``+inf`` as
    ``linprog``'s); ``status`` is ``linprog``'s (0 optimal and accepted; 4 when SciPy's acceptance test
    refuses HiGHS' optimum; otherwise HiGHS' model status as ``linprog`` maps it); ``fun`` and ``x`` are
    ``None`` unless HiGHS found an optimum.

    The model's part that does not depend on ``b_ub`` is made once per ``(c, A_ub, A_eq, b_eq, lb, ub)``
    (:data:`_MODELS`, by their bytes; the same arrays the one-call path makes, so HiGHS is handed the same
    model); each call builds its own ``HighsLp`` from them and a fresh solver, as SciPy does."""
    st = _core()
    if st is None or st["h"] is None:
        return _linprog(c, A_ub, b_ub, A_eq, b_eq, lb, ub)
    h, inf = st["h"], st["inf"]
    c = np.asarray(c, dtype=float).reshape(-1)
    nv = c.size
    A_ub = np.asarray(A_ub, dtype=float).reshape(-1, nv)
    b_ub = np.array(b_ub, dtype=float).reshape(-1)
    A_eq = np.zeros((0, nv)) if A_eq is None else np.asarray(A_eq, dtype=float).reshape(-1, nv)
    b_eq = np.zeros(0) if b_eq is None else np.asarray(b_eq, dtype=float).reshape(-1)
    lb = np.zeros(nv) if lb is None else np.asarray(lb, dtype=float).reshape(nv)
    ub = np.full(nv, np.inf) if ub is None else np.asarray(ub, dtype=float).reshape(nv)
    key = (nv, A_ub.shape[0], b_ub.size, A_eq.shape[0], c.tobytes(), A_ub.tobytes(), A_eq.tobytes(), b_eq.tobytes(),
           lb.tobytes(), ub.tobytes())
    fixed = _MODELS.get(key)
    if fixed is None:
        fixed = _fixed_part(inf, c, A_ub, b_ub.size, A_eq, b_eq, lb, ub)
        if len(_MODELS) >= _MODELS_MAX:
            _MODELS.clear()
        _MODELS[key] = fixed
    bounds, b_eq, lhs, indptr, rows, data, lb, ub = fixed
    rhs = _replace_inf(np.concatenate((b_ub, b_eq)), inf)

    numrow = rhs.size
    lp = h.HighsLp()
    lp.num_col_ = nv
    lp.num_row_ = numrow
    lp.a_matrix_.num_col_ = nv
    lp.a_matrix_.num_row_ = numrow
    lp.a_matrix_.format_ = h.MatrixFormat.kColwise
    lp.col_cost_ = c
    lp.col_lower_ = lb
    lp.col_upper_ = ub
    lp.row_lower_ = lhs
    lp.row_upper_ = rhs
    lp.a_matrix_.start_ = indptr
    lp.a_matrix_.index_ = rows
    lp.a_matrix_.value_ = data

    highs = _solver(h)
    if highs.passOptions(st["options"]) == h.HighsStatus.kError:
        return 4, None, None                                                   # pragma: no cover
    if highs.passModel(lp) == h.HighsStatus.kError:
        return 2, None, None                                                   # pragma: no cover (kModelError)
    if highs.run() == h.HighsStatus.kError:
        return _status(h, highs.getModelStatus()), None, None
    model_status = highs.getModelStatus()
    if model_status != h.HighsModelStatus.kOptimal:
        return _status(h, model_status), None, None
    info = highs.getInfo()
    solution = highs.getSolution()
    x = np.array(solution.col_value)
    fun = info.objective_function_value
    slack_all = rhs - solution.row_value
    slack, con = np.array(slack_all[:b_ub.size]), np.array(slack_all[b_ub.size:])
    # _check_result
    tol = _CHECK_TOL
    if np.isnan(x).any() or math.isnan(fun) or np.isnan(slack).any() or np.isnan(con).any():
        return 4, fun, x
    ok = bool(((x >= bounds[:, 0] - tol) & (x <= bounds[:, 1] + tol)).all())
    ok = ok and not (slack < -tol).any() and not (np.abs(con) > tol).any()
    return (0 if ok else 4), fun, x


def _linprog(c, A_ub, b_ub, A_eq=None, b_eq=None, lb=None, ub=None):
    """The same through ``scipy.optimize.linprog`` itself (another SciPy's private HiGHS modules)."""
    from scipy.optimize import linprog

    nv = len(c)
    lb = np.zeros(nv) if lb is None else np.asarray(lb, dtype=float)
    ub = np.full(nv, np.inf) if ub is None else np.asarray(ub, dtype=float)
    bounds = [(None if np.isinf(lo) else lo, None if np.isinf(hi) else hi) for lo, hi in zip(lb.tolist(), ub.tolist())]
    b_ub = np.asarray(b_ub, dtype=float).reshape(-1)
    res = linprog(c, A_ub=A_ub if b_ub.size else None, b_ub=b_ub if b_ub.size else None, A_eq=A_eq, b_eq=b_eq,
                  bounds=bounds, method="highs")
    return res.status, (res.fun if res.x is not None else None), res.x


def _status(h, model_status) -> int:
    """``linprog``'s status for a HiGHS model status that is not optimal (``_highs_to_scipy_status_message``)."""
    M = h.HighsModelStatus
    return {M.kModelError: 2, M.kTimeLimit: 1, M.kIterationLimit: 1, M.kInfeasible: 2,
            M.kUnbounded: 3}.get(model_status, 4)


__all__ = ["linprog_highs"]
