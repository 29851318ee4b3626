"""``prox_optimal`` hands ``g`` one reused buffer for its 42 perturbations per sample
(:class:`verimono.checks.prox_laws._Scratch`): the outcome is bit for bit the one of a fresh point per call —
for a ``g`` that writes into its argument, and for a ``g`` that keeps it (a memo of the last point, which a
reused buffer would feed stale numbers unless it is given up) — both at n where ``|z - x|²`` is summed directly and
above ``EXPANDED_N`` (lowered here).  Seen failing: with the buffer kept although ``g`` holds it, and with the
coordinate perturbations written into the buffer without copying ``p`` first."""

from __future__ import annotations

import numpy as np
import pytest

import verimono as vm
from verimono.checks import LAWS
from verimono.checks import prox_laws
from verimono.checks.engine.samples import Sample


def _g(z) -> float:
    """``g = 2|·|_1`` plus a smooth term, so that every entry of the point counts."""
    return 2.0 * float(np.abs(z).sum()) + 0.25 * float(z @ z)


def _prox(x, lam):
    """The exact prox of ``_g``: soft thresholding at ``2λ`` scaled by ``1/(1 + λ/2)``."""
    return np.sign(x) * np.maximum(np.abs(x) - 2.0 * lam, 0.0) / (1.0 + 0.5 * lam)


class _Memo:
    """A ``g`` that keeps its last argument (the array it was handed, a view of the law's point) and answers again
    from it when handed the same memory (a legal memo for a caller that never changes an array it passed)."""

    def __init__(self) -> None:
        self.last, self.val = None, None

    def __call__(self, z) -> float:
        if self.last is not None and np.shares_memory(z, self.last) and z.shape == self.last.shape:
            return self.val
        self.last, self.val = z, _g(z)
        return self.val


def _scribble(z) -> float:
    """A ``g`` that reads its argument, then overwrites it (its own business: the point was passed to it)."""
    v = _g(z)
    z *= -3.0
    z[::2] = 7.0
    return v


class _Direct:
    """The prox operator of ``_g`` whose ``value`` hands the law's array itself to ``g`` (a NumPy subject that
    takes its argument as it is: ``operator_from_prox`` gives ``g`` a copy of its own)."""

    def __init__(self, value, n: int) -> None:
        self.g, self.op = value, vm.operator_from_prox(_prox, value=_g, shape=n, name="scratch")

    def __getattr__(self, name):
        return getattr(self.op, name)

    def value(self, z, t=0.0) -> float:
        return self.g(z)


def _outcomes(value, n: int) -> list:
    op = _Direct(value, n)
    evaluate = LAWS["prox_optimal"].evaluate
    rng = np.random.default_rng(3)
    out = []
    for k in range(4):
        scale, lam = (1.0, 30.0)[k % 2], 10.0 ** (k - 2)
        s = Sample(scale * rng.standard_normal(n), scale * rng.standard_normal(n), lam, 0.5 * lam, 2.0 * lam, 0.0)
        o = evaluate(op, s)
        out.append((o.worst, o.lhs, o.slack, o.message, repr(o.counter)))
    return out


@pytest.mark.parametrize("expanded", [False, True])
def test_the_reused_buffer_gives_the_fresh_points_outcomes(monkeypatch, expanded):
    n = 40
    if expanded:
        monkeypatch.setattr(prox_laws, "EXPANDED_N", n - 1)
    plain = _outcomes(_g, n)
    assert all(w < 1e-3 for w, *_ in plain)            # the lawful control holds
    assert _outcomes(_Memo(), n) == plain              # bit for bit: worst, lhs, slack, message, counterexample
    assert _outcomes(_scribble, n) == plain


def test_a_kept_buffer_is_given_up():
    """The memo keeps the buffer: the scratch must drop it and hand out a fresh one (seen failing when kept)."""
    memo = _Memo()
    op = _Direct(memo, 5)
    scratch = prox_laws._Scratch(np.zeros(5))
    z = scratch.take()
    z[:] = 1.0
    scratch.value(op, z, 0.0)
    assert np.shares_memory(memo.last, z) and scratch.take() is not z
    z2 = scratch.take()
    z2[:] = 2.0
    scratch.value(_Direct(_g, 5), z2, 0.0)
    assert scratch.take() is z2                        # nothing kept it: reused


def test_a_memo_is_fed_stale_numbers_without_the_guard(monkeypatch):
    """The planted bug the guard prevents: the buffer reused although ``g`` kept it.  The memo then answers every
    perturbation with the first one's value, and the outcome moves (here the law's worst ratio)."""
    n = 40
    plain = _outcomes(_g, n)
    monkeypatch.setattr(prox_laws._Scratch, "value", lambda self, op, z, t: prox_laws._owned_value(op, z, t))
    assert _outcomes(_Memo(), n) != plain
