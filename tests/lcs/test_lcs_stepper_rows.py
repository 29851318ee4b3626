"""The box stepper's block of rows (``_BoxStepper.rows``, what ``LCSOperator``'s resolvent of a block steps with):
each row's answer bit for bit the one its own call returns, and the stepper left in the same state (the same last
and recent patterns, the same full solves), on random passive systems (complementarity and relay, ``D`` of full
and deficient rank plus a skew part), blocks at one time and a time per row, rows that cross between patterns,
a non-finite row among them (the same error after the same rows)."""

import math

import numpy as np

from verimono.execution.workers import blas_limited
from verimono.lcs import Complementarity, LinearRelationSystem, Relay
from verimono.reference.lcs_example import example_system


def _systems(rng, count):
    yield example_system(lambda t: np.array([-t, 0.0]))
    yield example_system(lambda t: np.array([math.sin(t), 0.0]))
    for k in range(count):
        n, m = int(rng.integers(1, 4)), int(rng.integers(1, 4))
        B, S, K = rng.normal(size=(n, m)), rng.normal(size=(m, m)), rng.normal(size=(m, m))
        D = S.T @ S * (k % 3 != 0) + (K - K.T)         # PSD, of full or zero rank, plus a skew part
        c = rng.normal(size=m)
        yield LinearRelationSystem(-np.eye(n) * rng.uniform(0, 1), B, B.T.copy(), D,
                                   Complementarity() if k % 2 else Relay(-1.0, 2.0),
                                   v=lambda t, c=c: c * np.sin(3 * t))


def _own(op, X, lam, t):
    ts = t.tolist() if isinstance(t, np.ndarray) else [t] * len(X)
    return np.array([op.resolvent(x, lam, ti) for x, ti in zip(X, ts)]).reshape(X.shape)


def _answer(f, X, lam, t, *op):
    try:
        return f(*op, X, lam, t)
    except Exception as exc:
        return repr(exc)


def test_a_block_of_rows_is_each_rows_own_call_bit_for_bit_and_leaves_the_stepper_as_they_do():
    rng = np.random.default_rng(43)
    blocks = 0
    with blas_limited():
        for s in _systems(rng, 6):
            block, single = s.operator(), s.operator()
            for k in range(8):
                X = rng.normal(size=(int(rng.integers(2, 25)), s.n)) * 10.0 ** int(rng.integers(-3, 3))
                X[::4] = np.abs(X[::4])                     # runs on one side of the edge
                if k == 3:
                    X[len(X) // 2] = np.nan                 # a non-finite row: a full solve, in its place
                lam = float(rng.choice([1e-3, 0.1, 1.0, 7.0]))
                t = float(rng.uniform(0, 5)) if k % 2 else rng.uniform(0, 5, size=len(X))
                got, want = _answer(block.resolvent, X, lam, t), _answer(_own, X, lam, t, single)
                assert type(got) is type(want)
                if isinstance(got, np.ndarray):
                    assert got.shape == want.shape and got.tobytes() == want.tobytes()
                else:                                       # the same error, raised at the same row
                    assert (k == 3 and got == want), got
                a, b = block._mats[lam].step, single._mats[lam].step
                assert (a.full_solves, a.last, a.recent) == (b.full_solves, b.last, b.recent)
                blocks += 1
    assert blocks == 8 * 8
