"""Property suites (pytest + hypothesis), one module per family of laws; installed as verimono.properties."""
