"""The search engine of the laws: what a law's "for all" is searched over, and how.

* :mod:`.search` — the driver of the operator laws: NumPy draws, hypothesis, the scale sweep, the coordinate
  search, the verdict of a search (its statuses, what was searched);
* :mod:`.samples` — a sample ``(x1, x2, λ, μ, ν, t)`` and its hypothesis strategy; :mod:`.sweep` — the seeded
  draws and the scale sweep, greedy shrinking;
* :mod:`.coordinates` — each coordinate of the worst sample searched (the step over every decade the precision
  represents, the time, the offset from the boundary, the scale); :mod:`.directions` — the direction of
  ``x2 − x1`` over the sphere; :mod:`.forms` — the form the input is passed in (integer, views, read-only);
* :mod:`.supremum` — the one-dimensional supremum (design, coverage, DIRECT, Brent) of every law over ``t``,
  ``λ`` or a distance, with its resolution; :mod:`.batches` — batched subjects' calls;
* :mod:`.times` — the time coordinate of the assumption laws, by count (jittered strata, both ends, refined by
  :mod:`.supremum`); :mod:`.sphere` — the largest value of a function of a direction over ``S^{n-1}``;
* :mod:`.scales` — the scale phase: the worst sample's points over every decade the precision represents;
  :mod:`.data_scale` — the operator's own scale (stated, or inferred from its domain) and the re-judgement of a
  failure at it.

The laws (:mod:`verimono.checks.operator_laws`, ...) and the batteries import from here; the engine imports only
the checks' core (declarations, records, members) and the layers below.
"""
