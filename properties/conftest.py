"""Property suites: the hypothesis profile (``dev``, ``ci``, ``thorough``; ``$HYPOTHESIS_PROFILE``, else ``ci``
when ``$CI`` is set) and the ``verimono checks`` summary of every battery run here (counts and skip reasons)."""

from verimono.testing import load_hypothesis_profile, pytest_configure  # noqa: F401  (pytest hook)

load_hypothesis_profile()
