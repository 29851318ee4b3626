"""Analytic reference problems: each a :class:`verimono.Problem` with its exact solution, the expected
order of the proximal scheme on it and where that order comes from (``problem.order.source``).

``catalog()`` returns them all; ``get(name)`` one by its name or its id; ``names()`` their names; ``ids()`` their
ids.  A reference's *id* is short, lower-case ASCII (``tnorm-1``, ``example-ramp``) and stable: it is what a
command line takes (``verimono run --reference tnorm-1``), whereas a display name may hold characters a keyboard
does not type (the Unicode minus of ``Example ex, v = (−t, 0)``).
"""

from __future__ import annotations

import functools

from verimono.core.problem import Problem

from . import lcs_example, linear, subdifferential, sweeping

#: (id, builder) of every reference, in the catalog's order; an id never changes once given
_BUILDERS = [
    ("tnorm-1", lambda: subdifferential.t_norm((1.0,))),
    ("tnorm-3", lambda: subdifferential.t_norm((0.6, -0.8, 0.5))),
    ("c-over-x", subdifferential.log_barrier),
    ("static-ball-inside", sweeping.static_inside),
    ("static-ball-outside", sweeping.static_outside),
    ("play-sine", sweeping.play_smooth),
    ("play-piecewise-linear", sweeping.play_piecewise_linear),
    ("moving-half-space", sweeping.moving_half_space),
    ("moving-box", sweeping.moving_box),
    ("translating-ball", sweeping.translating_ball),
    ("linear", linear.linear),
    ("lipschitz-input", linear.lipschitz_input),
    ("example-ramp", lcs_example.ramp_problem),
    ("example-sine", lcs_example.sine_problem),
]


def catalog() -> list[Problem]:
    """Every analytic reference problem, freshly built."""
    return [build() for _, build in _BUILDERS]


@functools.cache
def names() -> frozenset[str]:
    """The names of the catalog's problems, the catalog built once per process to read them (an order check's
    reproduction script built it each time it asked whether its problem is a reference: 1 ms a build here,
    3 ms the first)."""
    return frozenset(ids().values())


@functools.cache
def _ids() -> tuple[tuple[str, str], ...]:
    return tuple((rid, build().name) for rid, build in _BUILDERS)


def ids() -> dict[str, str]:
    """``{id: display name}`` of every reference, in the catalog's order."""
    return dict(_ids())


def _plain(text: str) -> str:
    """``text`` as typed on a keyboard: the Unicode minus (U+2212) as an ASCII hyphen-minus."""
    return text.replace("\u2212", "-")


def get(name: str) -> Problem:
    """The reference whose id or display name is ``name`` (a display name typed with an ASCII ``-`` for its
    Unicode minus too); :class:`KeyError` listing the ids and names otherwise."""
    for rid, build in _BUILDERS:
        if name == rid:
            return build()
    for p in catalog():
        if p.name == name or (isinstance(name, str) and _plain(p.name) == _plain(name)):
            return p
    known = "; ".join(f"{rid} ({shown})" for rid, shown in _ids())
    raise KeyError(f"no reference named {name!r}; known (id and name): {known}")


__all__ = ["catalog", "get", "names", "ids"]
