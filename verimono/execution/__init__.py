"""What a check runs under: effort, time and where it runs.

:mod:`.profiles` (``dev``, ``ci``, ``thorough``: search effort and budgets), :mod:`.timeouts` (the unit time
budget), :mod:`.watchdog` (a call blocked in native code past its budget), :mod:`.executors` (serial, worker
processes, a dask cluster), :mod:`.calibration` (the machine's speed unit) and :mod:`.timing` (noise-aware
timings and their verdicts).  The check batteries run on it; it knows the records, not the checks.
"""
