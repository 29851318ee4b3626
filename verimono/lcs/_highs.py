"""``linprog_highs``, now in :mod:`verimono.core._highs` (the core's QPs use it too); kept here for its importers."""

from ..core._highs import linprog_highs

__all__ = ["linprog_highs"]
