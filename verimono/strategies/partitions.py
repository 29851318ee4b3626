"""Time grids: partitions ``0 = t_0 < … < t_K = T`` (the module is not called ``grids``: that is the name of
the strategy :func:`verimono.strategies.grids`).  Bounds: :mod:`verimono.strategies`."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

from ..core.grids import validate_grid
from .values import MAX_CELLS, floats


def grids(T: float = 1.0, max_cells: int = MAX_CELLS, uniform: bool | None = None
          ) -> st.SearchStrategy[np.ndarray]:
    """Partitions ``0 = t_0 < … < t_K = T`` with ``1 ≤ K ≤ max_cells``: uniform, or nonuniform with
    cell weights in ``[1, 100]`` (step ratio ``≤ 100``); validated by :func:`verimono.validate_grid`."""
    @st.composite
    def _draw(draw):
        K = draw(st.integers(1, max_cells), label="K")
        uni = draw(st.booleans(), label="uniform") if uniform is None else uniform
        if uni or K == 1:
            t = np.linspace(0.0, T, K + 1)
        else:
            w = np.array(draw(st.lists(floats(1.0, 100.0), min_size=K, max_size=K), label="weights"))
            t = np.concatenate([[0.0], T * np.cumsum(w) / np.sum(w)])
        t[-1] = T
        return validate_grid(t, T)
    return _draw()
