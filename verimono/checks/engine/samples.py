"""Samples of the operator laws: two points, three step sizes and a time, ``(x1, x2, λ, μ, ν, t)``.

:func:`law_samples` is the hypothesis strategy the search draws and shrinks; above :data:`NUMPY_DIM`
coordinates a sample's points are NumPy draws from a recipe (seed, kind, scale) that hypothesis draws and
shrinks instead (:func:`numpy_point`), so that a million-coordinate sample is recorded and replayed by a few
numbers.
"""

from __future__ import annotations

import dataclasses
import functools
from typing import Any

import numpy as np
from hypothesis import strategies as st

from ...strategies.values import points, step_sizes, times
from .forms import CONTIGUOUS, FORMS, INTEGER, integral

#: above this dimension the points of a sample are drawn by NumPy from a seed (and a kind) that hypothesis
#: draws and shrinks: hypothesis draws each coordinate through its byte buffer, which cannot hold vectors of
#: ~500 floats (``Unsatisfiable``) — image- and PDE-sized operators (10^4–10^6 unknowns) need NumPy
NUMPY_DIM = 64
#: kinds of NumPy-drawn points: dense uniform in ``[-scale, scale]^n``, sparse (90% exact zeros: the kinks
#: of norms and boxes), and the zero vector (the kink of every norm)
NUMPY_KINDS = ("uniform", "sparse", "zero")


def numpy_point(n: int, recipe: dict[str, Any]) -> np.ndarray:
    """The point of ``R^n`` a recipe ``{"seed", "kind", "scale"}`` stands for (deterministic)."""
    kind, scale = recipe["kind"], float(recipe["scale"])
    if kind == "zero":
        return np.zeros(n)
    rng = np.random.default_rng(int(recipe["seed"]))
    x = rng.uniform(-scale, scale, n)
    if kind == "sparse":
        x[rng.random(n) < 0.9] = 0.0
    return x


@dataclasses.dataclass(frozen=True)
class Sample:
    """Inputs of one evaluation: points ``x1, x2``, step sizes ``λ = lam, μ = mu, ν = nu`` and time ``t``.

    ``recipe`` (large dimensions only) says how NumPy drew the points, so that a sample of a million
    coordinates is recorded and replayed by a few numbers instead of its coordinates.  ``form`` is how the
    points are passed to the operator (:mod:`verimono.checks.forms`; :meth:`in_form` makes one)."""

    x1: np.ndarray
    x2: np.ndarray
    lam: float
    mu: float
    nu: float
    t: float
    recipe: dict[str, Any] | None = dataclasses.field(default=None, compare=False)
    form: str = CONTIGUOUS

    def in_form(self, form: str) -> "Sample":
        """This sample with its points passed in ``form`` (:data:`verimono.checks.forms.FORMS`); the
        ``"integer"`` form rounds the points to integers first, so the law's arithmetic uses the same points."""
        if form not in FORMS:
            raise ValueError(f"no input form {form!r}; the forms are {FORMS}")
        if form == INTEGER:
            return dataclasses.replace(self, x1=integral(self.x1), x2=integral(self.x2), form=form)
        return dataclasses.replace(self, form=form)

    def to_dict(self) -> dict[str, Any]:
        scalars = {"lam": self.lam, "mu": self.mu, "nu": self.nu, "t": self.t}
        if self.form != CONTIGUOUS:
            scalars["form"] = self.form
        if self.recipe is not None:
            return {"recipe": dict(self.recipe), **scalars}
        return {"x1": self.x1.tolist(), "x2": self.x2.tolist(), **scalars}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "Sample":
        if "recipe" in d:
            s = _from_recipe(d["recipe"], float(d["lam"]), float(d["mu"]), float(d["nu"]), float(d["t"]))
        else:
            s = cls(np.asarray(d["x1"], dtype=float), np.asarray(d["x2"], dtype=float), float(d["lam"]),
                    float(d["mu"]), float(d["nu"]), float(d["t"]))
        form = d.get("form", CONTIGUOUS)
        return s if form == CONTIGUOUS else s.in_form(str(form))

    def __repr__(self) -> str:
        tail = "" if self.form == CONTIGUOUS else f", form={self.form!r}"
        if self.recipe is not None:
            return (f"Sample.from_dict({{'recipe': {self.recipe!r}, 'lam': {self.lam!r}, 'mu': {self.mu!r}, "
                    f"'nu': {self.nu!r}, 't': {self.t!r}" + (f", 'form': {self.form!r}" if tail else "") + "})")
        f = lambda a: np.array2string(a, precision=17, separator=", ")  # noqa: E731 - exact replay
        return (f"Sample(x1={f(self.x1)}, x2={f(self.x2)}, lam={self.lam!r}, mu={self.mu!r}, "
                f"nu={self.nu!r}, t={self.t!r}{tail})")


def with_field(s: Sample, name: str, value: Any) -> Sample:
    """``dataclasses.replace(s, **{name: value})`` without its ``__init__`` nor keyword arguments (``Sample`` has no
    ``__post_init__``; the coordinate and direction searches build thousands of samples): a copy of ``s``'s fields
    with ``name`` set to ``value`` (1.2 µs a sample against replace's 11 µs, R^3, this machine)."""
    out = object.__new__(Sample)
    d = out.__dict__
    d.update(s.__dict__)
    d[name] = value
    return out


def with_fields(s: Sample, **changes: Any) -> Sample:
    """``dataclasses.replace(s, **changes)`` the same way as :func:`with_field` (several fields at once: a point
    design moves ``x1`` and ``x2`` together)."""
    out = object.__new__(Sample)
    out.__dict__.update(s.__dict__)
    out.__dict__.update(changes)
    return out


def _from_recipe(recipe: dict[str, Any], lam: float, mu: float, nu: float, t: float) -> Sample:
    n = int(recipe["n"])
    x1 = numpy_point(n, recipe["x1"])
    if recipe.get("near"):
        x2 = x1 + numpy_point(n, recipe["x2"])
    else:
        x2 = numpy_point(n, recipe["x2"])
    return Sample(x1, x2, lam, mu, nu, t, recipe=recipe)


def _numpy_recipes(scale: float) -> st.SearchStrategy[dict[str, Any]]:
    return st.fixed_dictionaries({"seed": st.integers(0, 2 ** 32 - 1), "kind": st.sampled_from(NUMPY_KINDS),
                                  "scale": st.sampled_from([scale, scale / 10.0, scale * 1e-4])})


def law_samples(n: int, horizon: float = 1.0) -> st.SearchStrategy[Sample]:
    """Samples for the laws on ``R^n``: ``x1`` from :func:`verimono.strategies.points`, ``x2`` either
    independent or within ``10^-2`` of ``x1`` (local violations), ``λ, μ, ν ∈ [10^-3, 10]`` and
    ``t ∈ [0, horizon]``; everything shrinks toward 0, 1 and ``t = 0``.  The strategy is built once per
    ``(n, horizon)`` (building strategies inside every draw cost more than evaluating the law).

    For ``n > NUMPY_DIM`` the points come from :func:`numpy_point` (seed, kind and scale drawn and shrunk by
    hypothesis; shrinking goes toward the zero vector and seed 0), the step sizes and time as above."""
    return _law_samples(int(n), float(horizon))


@functools.lru_cache(maxsize=128)
def _law_samples(n: int, horizon: float) -> st.SearchStrategy[Sample]:
    steps, when, coin = step_sizes(), times(horizon), st.booleans()
    if n > NUMPY_DIM:
        @st.composite
        def _recipe(draw):
            near = draw(coin, label="x2 near x1")
            recipe = {"n": n, "near": near, "x1": draw(_numpy_recipes(10.0), label="x1"),
                      "x2": draw(_numpy_recipes(1e-2 if near else 10.0), label="x2")}
            lam, mu, nu = (draw(steps, label=k) for k in ("lam", "mu", "nu"))
            return _from_recipe(recipe, lam, mu, nu, draw(when, label="t"))
        return _recipe()
    pts, near = points(n), points(n, 1e-2)

    @st.composite
    def _draw(draw):
        x1 = draw(pts, label="x1")
        if draw(coin, label="x2 near x1"):
            x2 = x1 + draw(near, label="x2 - x1")
        else:
            x2 = draw(pts, label="x2")
        lam, mu, nu = (draw(steps, label=k) for k in ("lam", "mu", "nu"))
        return Sample(x1, x2, lam, mu, nu, draw(when, label="t"))
    return _draw()


__all__ = ["Sample", "with_field", "with_fields", "law_samples", "numpy_point", "NUMPY_DIM", "NUMPY_KINDS"]
