"""Issue 43 (branch units10): the generated operators' functions of time remember their values per float time
(``TimeFunction.__call__`` for scalars, ``ACInput.integral``) and give the numbers computed afresh, bit for bit and
of the same type: at repeated times, at ``0.0`` and ``-0.0`` (equal dict keys, values of another sign), after the
caller wrote into a returned array, past the memo's size.  Seen failing on a memo keyed by ``t`` alone (the sign of
zero lost) and on an integral returned uncopied."""

from __future__ import annotations

import numpy as np

from verimono.core._params import Param
from verimono.strategies import values as vs


def _fresh_time(f: vs.TimeFunction, t: float):
    return np.asarray(f.a, dtype=float) + f.g(t) * np.asarray(f.b, dtype=float)


def _times():
    rng = np.random.default_rng(5)
    return [0.0, -0.0, 1.0, 0.5, 1e-300, -1e-300] + rng.uniform(0.0, 1.0, 20).tolist()


def test_time_functions_remember_the_fresh_values():
    fns = [vs.TimeFunction(2.222, 0.0), vs.TimeFunction(-0.0, 1.5, "affine"), vs.TimeFunction(0.0, -2.0, "affine"),
           vs.TimeFunction(1.475e-165, 1.475e-165, "sin", 0.7084), vs.TimeFunction(3.0, 1e300, "sin", 5.0)]
    for f in fns:
        for _ in range(2):
            for t in _times():
                got, want = f(t), _fresh_time(f, t)
                assert type(got) is type(want) is np.float64 and got.tobytes() == want.tobytes()
                assert np.asarray(Param(f)(t)).tobytes() == np.asarray(want).tobytes()
    # vectors and non-float times take the path as before
    v = vs.TimeFunction(np.array([1.0, 2.0]), np.array([0.5, -0.5]), "affine")
    assert v(0.5).tobytes() == _fresh_time(v, 0.5).tobytes()
    assert vs.TimeFunction(1.0, 2.0, "affine")(np.float64(0.25)) == 1.5


def test_integrals_remember_copies_of_the_fresh_values():
    knots = np.array([0.0, 0.402, 0.7824, 1.0])
    vals = np.array([[-0.5802, 1.5832], [-0.0, 0.0], [0.0, 0.0], [-1.2048, 0.0]])
    inputs = [vs.ACInput("pwlinear", vals[0], vals[1], knots=knots, values=vals),
              vs.ACInput("affine", np.array([-0.0, 1.0]), np.array([2.0, -3.0])),
              vs.ACInput("sin", np.array([1.0, -1.0]), np.array([0.5, 0.25]), 2.0, 0.3)]
    for u in inputs:
        for _ in range(2):
            for t in _times() + [1.5]:
                got, want = u.integral(t), u._integral(t)
                assert got.tobytes() == want.tobytes() and got.dtype == want.dtype
                got[...] = 7.0            # the caller's array: the memo's stays
        assert u.integral(0.5).tobytes() == u._integral(0.5).tobytes()


def test_the_memo_is_bounded():
    f = vs.TimeFunction(1.0, 2.0, "affine")
    for t in np.linspace(0.001, 1.0, vs.MEMO_SIZE + 10).tolist():
        assert f(t) == 1.0 + t * 2.0
    assert len(f.__dict__["_memo"]) <= vs.MEMO_SIZE
    assert f == vs.TimeFunction(1.0, 2.0, "affine")     # the memo is no field
