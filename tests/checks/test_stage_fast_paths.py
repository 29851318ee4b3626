"""Issue 43 items 1 and 3 (branch units7): the operator_laws stage's fast paths give the numbers of the paths they
replace, bit for bit — ``Linear``'s inverses of a block of step sizes in one stacked ``inv``, the offset and scale
designs' samples in one broadcast pass, ``members.norm`` without ``np.linalg.norm``'s dispatch — each compared with
the one-point path on a *fresh* object (a shared cache would compare a value with itself), and each comparison seen
failing on a variant that moves the last bits only.
"""

from __future__ import annotations

import numpy as np

from verimono.checks.engine import coordinates
from verimono.checks.engine.samples import Sample
from verimono.checks.members import norm
from verimono.core.operators import Linear


def _matrix(n: int) -> np.ndarray:
    """A monotone, non-symmetric ``M`` (identity plus a strictly upper triangle)."""
    return np.eye(n) + np.triu(np.random.default_rng(n).normal(size=(n, n)), 1) * 0.3


def _steps() -> np.ndarray:
    """64 distinct step sizes over twelve decades, one repeated (the cache's order is part of the path)."""
    ls = np.exp(np.random.default_rng(1).uniform(-14.0, 14.0, 64))
    ls[40] = ls[3]
    return ls


def _block_differs(n: int) -> bool:
    """``Linear(M).resolvent`` of a block of step sizes against separate calls on another ``Linear(M)`` (its own
    cache, filled one step size at a time), bit for bit."""
    M, ls = _matrix(n), _steps()
    X = np.random.default_rng(2).normal(size=(ls.size, n))
    together = Linear(M).resolvent(X, ls)
    alone = Linear(M)
    each = np.array([alone.resolvent(x, lam) for x, lam in zip(X, ls.tolist())])
    return together.tobytes() != each.tobytes()


def test_linear_inverts_a_block_of_steps_as_each_step_alone():
    for n in (1, 2, 3, 5, 9):
        assert not _block_differs(n), n


def test_the_block_comparison_sees_inverses_rounded_otherwise(monkeypatch):
    """The stacked factors computed as ``inv((I + λM)ᵀ)`` (the transpose's inverse: the same matrix exactly, its
    elimination in another order) differ in the last bits at n = 9, and the comparison says so."""
    real = np.linalg.inv

    def transposed(a):
        return real(np.swapaxes(a, -1, -2)).swapaxes(-1, -2) if np.ndim(a) == 3 else real(a)
    monkeypatch.setattr(np.linalg, "inv", transposed)
    assert _block_differs(9)


def _design_samples(name: str, x2_of=None) -> tuple[list, list]:
    """The samples of coordinate ``name``'s design from a sample at ``n = 3``: made in one pass, and one by one."""
    rng = np.random.default_rng(4)
    s = Sample(x1=rng.normal(size=3) * 3.0, x2=rng.normal(size=3), lam=0.3, mu=0.1, nu=0.01, t=0.4)
    op = Linear(_matrix(3))
    space, at, design = coordinates._moves(s, name, op, 1.0)
    design = design + coordinates._even(space, 200)
    if x2_of is not None:
        at.many = x2_of(at, s, op)
    return coordinates._samples(at, design), [at(v) for v in design]


def _same(a: list, b: list) -> bool:
    return len(a) == len(b) and all(p.x1.tobytes() == q.x1.tobytes() and p.x2.tobytes() == q.x2.tobytes()
                                    and (p.lam, p.mu, p.nu, p.t) == (q.lam, q.mu, q.nu, q.t) for p, q in zip(a, b))


def test_the_offset_and_scale_designs_in_one_pass_are_the_one_point_samples():
    for name in ("offset", "scale"):
        together, each = _design_samples(name)
        assert _same(together, each), name
        assert len({id(p.x1) for p in together}) == len(together)       # a row of its own each


def test_the_design_comparison_sees_a_product_associated_otherwise():
    """``x2 = b + 1e3·(v·n)`` where the one-point sample has ``b + (1e3·v)·n``: the same real number, other last
    bits on some rows of the offset design."""
    def reassociated(at, s, op):
        b = np.asarray(op.resolvent(s.x1.copy(), s.nu, s.t), dtype=float)
        d = coordinates._norm(s.x1 - b)
        n = (s.x1 - b) / d
        return lambda vs: coordinates._rows_of(s, vs, lambda V: b + V[:, None] * n,
                                               lambda V: b + 1e3 * (V[:, None] * n), np.array(vs))
    together, each = _design_samples("offset", reassociated)
    assert not _same(together, each)


def _norm_before(v) -> float:
    """``members.norm``'s numbers as 5a13165 computed them (``np.max`` and ``np.linalg.norm``)."""
    v = np.asarray(v, dtype=float)
    m = float(np.max(np.abs(v), initial=0.0))
    if m == 0.0 or not np.isfinite(m):
        return 0.0
    return m * float(np.linalg.norm(v / m))


def _vectors() -> list:
    rng = np.random.default_rng(5)
    out = [rng.normal(size=n) * s for n in (1, 2, 3, 7, 33, 1000) for s in (1e-300, 1e-8, 1.0, 1e200)]
    big = rng.normal(size=(40, 25))
    return out + [big, big[::3, ::2], big.T, np.zeros(4), np.array([np.inf, 1.0]), np.array([np.nan, 1.0])]


def test_norm_is_the_scaled_norm_it_was():
    for v in _vectors():
        assert norm(v) == _norm_before(v) or (np.isnan(norm(v)) and np.isnan(_norm_before(v)))


def test_the_norm_comparison_sees_a_pairwise_sum():
    """The same squares summed by ``np.sum`` (pairwise) instead of the dot product differ in the last bit on some
    of the vectors, and the comparison says so."""
    def pairwise(v):
        v = np.asarray(v, dtype=float)
        m = float(np.abs(v).max(initial=0.0))
        if m == 0.0 or not np.isfinite(m):
            return 0.0
        w = v / m
        return m * float(np.sqrt(np.sum(w * w)))
    assert any(pairwise(v) != _norm_before(v) for v in _vectors())


def _conditioned_cases() -> list:
    """Square matrices around the stepper's threshold ``cond = 1e12`` (rotated ``diag(1, 1e-12·(1 + k·eps))``),
    random ones over 400 decades, 1×1 ones with 0, ±0, tiny, huge and non-finite entries, and singular ones."""
    rng = np.random.default_rng(6)
    out = []
    for k in range(-3, 4):
        Q = np.linalg.qr(rng.normal(size=(2, 2)))[0]
        out += [np.diag([1.0, 1e-12 * (1 + k * 2.2e-16)]), Q @ np.diag([1.0, 1e-12 * (1 + k * 2.2e-16)]) @ Q.T]
    out += [rng.normal(size=(n, n)) * 10.0 ** rng.uniform(-200, 200) for n in (1, 2, 3) for _ in range(30)]
    out += [np.array([[v]]) for v in (0.0, -0.0, 5e-324, 1e308, np.inf, -np.inf, np.nan)]
    return out + [np.zeros((2, 2)), np.ones((2, 2)), np.array([[np.nan, 1.0], [1.0, 1.0]])]


def _verdict(f, A):
    try:
        with np.errstate(all="ignore"):
            return bool(f(A))
    except np.linalg.LinAlgError:
        return "raises"


def test_the_stepper_judges_a_pattern_matrix_as_cond_did():
    from verimono.lcs.relations import _well_conditioned
    for A in _conditioned_cases():
        assert _verdict(_well_conditioned, A) == _verdict(lambda a: np.linalg.cond(a) < 1e12, A), A


def test_the_conditioning_comparison_sees_the_threshold_moved():
    """``cond ≤ 1e12`` where the stepper had ``cond < 1e12``: ``diag(1, 1e-12)`` is judged otherwise."""
    assert any(_verdict(lambda a: np.linalg.cond(a) <= 1e12, A) != _verdict(lambda a: np.linalg.cond(a) < 1e12, A)
               for A in _conditioned_cases())
