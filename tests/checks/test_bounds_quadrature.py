"""The a-priori bounds' quadrature (``verimono.checks.bounds._cell_integrals``, in place of ``scipy.integrate.quad``):
``∫|u|`` and ``∫σ`` over every cell on the large side — the side on which lem:bndSeq's β and ψ only grow — and
within ``QUAD_RTOL`` of the integral, against closed forms in exact rational arithmetic."""

from fractions import Fraction

import numpy as np
import pytest

from verimono.checks import bounds
from verimono.checks.bounds import LGBounds, QUAD_RTOL, _cell_integrals

#: |u| of a piecewise-linear u: zeros (kinks) at 3/4 and 5/4, kinks where the two pieces cross (13/12, 7/4);
#: each value is one rounded subtraction (relative error ≤ 2^-53), the doubling and the min exact
KINKS = (Fraction(3, 4), Fraction(13, 12), Fraction(5, 4), Fraction(7, 4))
#: the rounding of the nodes' positions, which the quadrature's estimate does not cover (the first test)
ROUNDING = 32 * np.finfo(float).eps


def _abs_u(s):
    return min(abs(s - 0.75), 2.0 * abs(s - 1.25))


def _exact(a: Fraction, b: Fraction) -> Fraction:
    """∫_a^b |u| exactly: |u| is linear between its kinks, so the trapezoid rule on them is exact."""
    def v(s):
        return min(abs(s - KINKS[0]), 2 * abs(s - KINKS[2]))
    pts = sorted({a, b} | {k for k in KINKS if a < k < b})
    return sum(((v(p) + v(q)) * (q - p) / 2 for p, q in zip(pts, pts[1:])), Fraction(0))


def _relative_excess(cells: int) -> list[Fraction]:
    t = np.linspace(0.0, 2.0, cells + 1)
    got = _cell_integrals(_abs_u, t)
    return [Fraction(got[k]) / _exact(Fraction(t[k]), Fraction(t[k + 1])) - 1 for k in range(cells)]


@pytest.mark.parametrize("cells", [7, 40])
def test_cell_integrals_of_a_kinked_input_are_on_the_large_side_and_tight(cells):
    excess = _relative_excess(cells)
    # never below the integral (ψ and β only grow), but for the rounding of the nodes themselves: a node
    # s = m + h x is within an ulp of s, |u| moves by |u'| ulp(s) there, a relative 4 ulps of the integral of
    # the cell [5/4, 13/10] where |u| = 2(s − 5/4) starts from 0 (the quadrature's own rounding is covered)
    assert min(excess) >= -ROUNDING, float(min(excess))
    assert max(excess) <= QUAD_RTOL, float(max(excess))       # and above it by at most the stated tolerance


def test_without_the_bisection_a_kink_is_missed(monkeypatch):
    """The broken control: one Gauss–Kronrod pass per cell (no bisection) is off by far more than QUAD_RTOL on
    the cells holding a kink — what the bisection is there for."""
    monkeypatch.setattr(bounds, "QUAD_DEPTH", 0)
    assert max(_relative_excess(40)) > 1e3 * QUAD_RTOL


def test_smooth_integrands_to_round_off_and_the_input_total():
    t = np.linspace(0.0, 3.0, 13)
    got, exact = _cell_integrals(np.exp, t), np.diff(np.exp(t))          # ∫_a^b e^s = e^b − e^a
    assert np.all(got >= exact * (1 - 4e-16)) and np.all(got <= exact * (1 + 1e-13))
    lg = LGBounds(0.0, lambda s: 0.0, lambda s: 0.0, np.pi, absu=lambda s: abs(np.cos(s)))   # ∫_0^π |cos| = 2
    assert 2.0 * (1 - 4e-16) <= lg.u_total <= 2.0 * (1 + 1e-12)


#: a kink or a jump between a cell's end and its outermost Gauss–Kronrod node (the nodes sit at 0.43% of the
#: cell from each end, so every node sees one smooth piece: K15 = G7 there); found by the probe of issue 43
HIDDEN = [(Fraction(3, 1000), "kink"), (Fraction(997, 1000), "kink"), (Fraction(1, 500), "jump"),
          (Fraction(499, 500), "jump")]


@pytest.mark.parametrize("c,kind", HIDDEN)
def test_a_kink_or_a_jump_no_node_sees_is_still_on_the_large_side(c, kind):
    cf = float(c)
    if kind == "kink":                                         # |s − c|: ∫_0^1 = (c² + (1 − c)²) / 2
        fn, exact = (lambda s: abs(s - cf)), (c * c + (1 - c) ** 2) / 2
    else:                                                      # 2 before c, 1 after: ∫_0^1 = 2c + (1 − c)
        fn, exact = (lambda s: 2.0 if s < cf else 1.0), 2 * c + (1 - c)
    got = Fraction(float(_cell_integrals(fn, np.array([0.0, 1.0]))[0]))
    assert got / exact - 1 >= -ROUNDING, float(got / exact - 1)
    assert got / exact - 1 <= QUAD_RTOL, float(got / exact - 1)


def test_an_integral_that_overflows_is_infinite_not_nan():
    got = _cell_integrals(lambda s: 1.7e308 * (1.0 + s), np.array([0.0, 1.0]))      # ∫ = 2.55e308 > max float
    assert got[0] == np.inf


@pytest.mark.parametrize("scale", [1e-300, 1e-150, 1.0, 1e150, 1e300])
def test_a_jump_is_on_the_large_side_at_every_magnitude(scale):
    """The acceptance floor scales with the whole integral: an absolute 1e-14 accepted the piece holding a jump of
    |u| at scale 1e-300 on its first estimate, blind to it (7.7e-5 below the integral, found by a user's probe)."""
    rng = np.random.default_rng(3)
    for c in rng.uniform(0.0, 1.0, 40).tolist():
        got = _cell_integrals(lambda s: scale * (2.0 if s >= c else 1.0), np.array([0.0, 1.0]))[0]
        exact = Fraction(scale) * (Fraction(c) + 2 * (1 - Fraction(c)))
        assert Fraction(got) >= exact and Fraction(got) / exact - 1 <= 1e-9, (scale, c, got)


def test_an_input_that_never_settles_costs_calls_linear_in_the_cells():
    """An |u| with a jump on every scale (values from the bits of s): the bisection stops at QUAD_PIECES open pieces a
    cell, each estimate added — it doubled its pieces at every level before, 2^40 of them."""
    calls = []

    def noise(s):
        calls.append(s)
        return 1.0 + (hash(s) % 1000) / 1000.0

    got = _cell_integrals(noise, np.linspace(0.0, 1.0, 11))
    assert np.all(np.isfinite(got)) and 1.0 <= got.sum() <= 4.0, got       # 1 ≤ |u| < 2 on [0, 1], estimates added
    assert len(calls) <= 17 * 2 * bounds.QUAD_PIECES * 10, len(calls)
