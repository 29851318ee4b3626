"""The solver core: what an evolution inclusion ``x' ∈ −F(t, x) + f(x) + u(t)`` is and how it is solved.

* the problem and its operators: :mod:`.problem` (``Problem``, ``Order``), :mod:`.operators` (maximal monotone
  ``F(t, ·)`` through their resolvents), :mod:`.sets` (moving convex sets and their projections, some through the
  verified QPs of :mod:`.qp`), :mod:`.prox` (operators from proximal maps, ``∂g``);
* the scheme: :mod:`.stepping` (``solve``: the paper's ``eq:iteration`` on any partition), :mod:`.grids`
  (partitions), :mod:`.claims` (what a stepper says it is);
* measuring: :mod:`.convergence` (studies against exact solutions), :mod:`.pseudo_distance`
  (``def:dis``), :mod:`.tolerances` (round-off in the precision a subject computes in), :mod:`.arrays`
  (array libraries and precision);
* :mod:`.errors` (every typed error of verimono), :mod:`.naming`, :mod:`.display` and ``_``-helpers.

The core imports nothing else of verimono: the models (``lcs``, ``reference``, ``strategies``), the records, the
execution machinery, the checks and the run are built on it (``tests/project/test_layers.py``).
"""
