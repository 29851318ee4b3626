"""The piecewise-linear play operator's input ``u`` in Python floats (``reference.sweeping._interp``, branch perf10:
``np.interp`` per call was most of its assumption unit): ``float(np.interp(t, xp, fp))`` bit for bit, at and
beside the kinks, outside the range, on tiny and non-finite times."""

import math

import numpy as np

from verimono.reference.sweeping import _interp, play_piecewise_linear

KINKS = [0.0, 1.0, 1.5, 3.0, 4.0]
VALUES = [0.0, 1.0, 0.2, 1.4, 0.0]


def _times():
    rng = np.random.default_rng(5)
    k = np.array(KINKS)
    return np.concatenate([rng.uniform(-1.0, 5.0, 800), rng.uniform(0.0, 4.0, 400) * 10.0 ** rng.uniform(-15, 0, 400),
                           k, np.nextafter(k, 10.0), np.nextafter(k, -10.0), [np.nan, np.inf, -np.inf, -0.0, 5e-324]])


def _bits(x: float) -> bytes:
    return np.float64(x).tobytes()


def test_interp_is_numpys_bit_for_bit():
    for xp, fp in ((KINKS, VALUES), ([-2.0, 0.5, 0.7, 9.0], [3.0, -1e-9, 1e12, 3.0]), ([0.0, 1e-300], [1.0, -1.0])):
        for t in _times().tolist():
            want = float(np.interp(t, xp, fp))
            got = _interp(t, xp, fp)
            assert type(got) is float and (_bits(got) == _bits(want) or (want != want and got != got)), (xp, t)


def test_the_problems_bounds_are_u_plus_minus_r():
    p = play_piecewise_linear()
    box = p.operator.S
    for t in (0.0, 0.3, 1.0, 1.2, 2.9, 4.0):
        u = float(np.interp(t, KINKS, VALUES))
        assert box.lower(t).tolist() == [u - 0.25] and box.upper(t).tolist() == [u + 0.25]


def test_the_moving_boxs_bounds_are_u_minus_and_plus_r_bit_for_bit():
    from verimono.reference.sweeping import moving_box

    box = moving_box().operator.S
    r = np.array([0.3, 0.5])
    for t in np.concatenate([np.linspace(0.0, 2 * np.pi, 97), [1e-300, 3.0e7, -0.0]]).tolist():
        u = np.array([math.sin(t), 0.7 * math.cos(t)])      # the problem's u(t)
        assert box.lower(t).tobytes() == (u - r).tobytes() and box.upper(t).tobytes() == (u + r).tobytes(), t
