"""Convex sets: static balls, boxes, half-spaces, polyhedra (each containing a drawn point) and moving sets
with their (A3) modulus φ (:class:`MovingSet`).  Bounds: :mod:`verimono.strategies`."""

from __future__ import annotations

import dataclasses

import numpy as np
from hypothesis import strategies as st

from ..core import sets as _sets
from .values import (SET_SCALE, TimeFunction, _dim, _entry, _fmt, _kinds, _nonneg_time_functions, _vec, floats,
                     time_functions)


# -- convex sets ------------------------------------------------------------------------------------

def _nonzero_vectors(k: int, lo: float = 0.5, hi: float = 3.0) -> st.SearchStrategy[np.ndarray]:
    """Vectors with a component of size in ``[lo, hi]`` (nonzero by construction), the others 0 or at least
    ``ENTRY_FLOOR`` in magnitude: constraint normals (rows of ``G`` and ``A``) 1e-7 apart in angle make a
    polyhedron whose projection no double-precision QP answers to ``QP_RTOL`` (a dev-profile run drew eight
    such copies of ``e₁``; ProxQP returned nothing, DAQP a point 5e-9 outside), while rows that are equal or
    at least 1e-3 apart are solved (400 of 400 such polyhedra, measured)."""
    def build(v, i, s, sign):
        v = np.array([_entry(e) for e in v])
        v[i] = sign * s
        return v
    return st.builds(build, _vec(k, -hi, hi), st.integers(0, k - 1), floats(lo, hi), st.sampled_from([1.0, -1.0]))


def convex_sets(n: int | None = None, kinds: tuple[str, ...] = ("ball", "box", "halfspace", "polyhedron")
                ) -> st.SearchStrategy[_sets.ConvexSet]:
    """Nonempty closed convex sets (static): balls (radius 0 allowed), boxes (possibly flat or with
    infinite sides), half-spaces and polyhedra ``{Gx ≤ h, Ax = b}`` built around a point ``p`` with
    ``h = Gp + s``, ``s ≥ 0`` and ``b = Ap`` — so ``p`` belongs to the set."""
    @st.composite
    def _draw(draw):
        k = draw(_dim(n), label="n")
        kind = draw(st.sampled_from(list(kinds)), label="kind")
        return draw(_static_set(k, kind), label=kind)
    return _draw()


def _static_set(k: int, kind: str) -> st.SearchStrategy[_sets.ConvexSet]:
    @st.composite
    def _draw(draw):
        if kind == "ball":
            c = draw(_vec(k, -SET_SCALE, SET_SCALE))
            r = draw(floats(0.0, SET_SCALE))
            return _sets.Ball(c, r, name=f"Ball[c={_fmt(c)}, r={r:.4g}]")
        if kind == "box":
            lo = draw(_vec(k, -SET_SCALE, SET_SCALE))
            w = draw(_vec(k, 0.0, SET_SCALE))
            hi = lo + w
            unb = draw(st.lists(st.sampled_from(["", "lo", "hi"]), min_size=k, max_size=k))
            lo = np.where([u == "lo" for u in unb], -np.inf, lo)
            hi = np.where([u == "hi" for u in unb], np.inf, hi)
            return _sets.Box(lo, hi, name=f"Box[{_fmt(lo)}, {_fmt(hi)}]")
        if kind == "halfspace":
            a = draw(_nonzero_vectors(k))
            b = draw(floats(-SET_SCALE, SET_SCALE))
            return _sets.HalfSpace(a, b, name=f"HalfSpace[{_fmt(a)}·x ≤ {b:.4g}]")
        if kind == "polyhedron":
            p = draw(_vec(k, -SET_SCALE, SET_SCALE))
            rows = draw(st.integers(1, 2 * k))
            G = np.stack([draw(_nonzero_vectors(k)) for _ in range(rows)])
            s = draw(_vec(rows, 0.0, SET_SCALE))
            h = G @ p + s
            eq = draw(st.integers(0, k - 1))
            if eq:
                A = np.stack([draw(_nonzero_vectors(k)) for _ in range(eq)])
                b = A @ p
                return _sets.Polyhedron(G, h, A, b, name=f"Polyhedron[G={_fmt(G)}, h={_fmt(h)}, "
                                                          f"A={_fmt(A)}, b={_fmt(b)}]")
            return _sets.Polyhedron(G, h, name=f"Polyhedron[G={_fmt(G)}, h={_fmt(h)}]")
        raise ValueError(f"unknown set kind {kind!r}")
    return _draw()


@dataclasses.dataclass(frozen=True)
class MovingSet:
    """A moving closed convex set ``S(t)``, ``t ∈ [0, T]``, with a known (A3) modulus ``φ``.

    ``φ(t) = rate · t`` is nondecreasing and absolutely continuous, and
    ``sup_{z ∈ S(s)} dist(z, S(t)) ≤ φ(t) - φ(s)`` for ``0 ≤ s ≤ t ≤ T`` (assumption (A3) for
    ``F(t,·) = N_{S(t)}``, whose domain is ``S(t)``).
    """

    set: _sets.ConvexSet
    rate: float
    T: float
    how: str

    @property
    def dim(self) -> int:
        return self.set.dim

    def phi(self, t: float) -> float:
        return self.rate * float(t)

    def __repr__(self) -> str:
        return f"MovingSet({self.how}, φ(t)={self.rate:.4g}·t)"


def moving_sets(n: int | None = None, T: float = 1.0) -> st.SearchStrategy[MovingSet]:
    """Moving sets with their (A3) bound: a static set translated along ``c(t)`` (``φ' = Lip(c)``), a
    ball with moving centre and radius (``φ' = Lip(c) + Lip(r)``), a box with moving bounds
    (``φ' = |(max(Lip lᵢ, Lip uᵢ))ᵢ|``) and a half-space with moving offset (``φ' = Lip(b)/|a|``)."""
    @st.composite
    def _draw(draw):
        k = draw(_dim(n), label="n")
        kind = draw(st.sampled_from(["translated", "ball", "box", "halfspace"]), label="kind")
        if kind == "translated":
            S0 = draw(convex_sets(k), label="S0")
            c = draw(time_functions((k,), -1.0, 1.0), label="shift")
            S = _sets.Translated(S0, c, name=f"{S0.name} + {c!r}")
            return MovingSet(S, c.lipschitz, T, S.name)
        if kind == "ball":
            c = draw(time_functions((k,)), label="center")
            r = draw(_nonneg_time_functions(0.0, SET_SCALE), label="radius")
            S = _sets.Ball(c, r, name=f"Ball[c={c!r}, r={r!r}]")
            return MovingSet(S, c.lipschitz + r.lipschitz, T, S.name)
        if kind == "box":
            kd = draw(_kinds(), label="g")
            l0 = draw(_vec(k, -SET_SCALE, SET_SCALE))
            dl = draw(_vec(k, -2.0, 2.0))
            du = draw(_vec(k, -2.0, 2.0))
            lo = TimeFunction(l0, dl * (kd[0] != "const"), kd[0], kd[1])
            # width w0 ≥ |du - dl| max|g| keeps lower ≤ upper on [0, T]
            w0 = draw(_vec(k, 0.0, SET_SCALE)) + np.abs(du - dl) * lo.gmax(T)
            hi = TimeFunction(l0 + w0, du * (kd[0] != "const"), kd[0], kd[1])
            rate = float(np.linalg.norm(np.maximum(np.abs(lo.b), np.abs(hi.b)))) * lo.slope
            S = _sets.Box(lo, hi, name=f"Box[{lo!r}, {hi!r}]")
            return MovingSet(S, rate, T, S.name)
        a = draw(_nonzero_vectors(k), label="normal")
        b = draw(time_functions((), rate=2.0), label="offset")
        S = _sets.HalfSpace(a, b, name=f"HalfSpace[{_fmt(a)}·x ≤ {b!r}]")
        return MovingSet(S, b.lipschitz / float(np.linalg.norm(a)), T, S.name)
    return _draw()
