"""The records: what a check returns and where it goes.

:mod:`.results` (``CheckResult``, ``Report``: the records and their collection), :mod:`.schema` (the results
document's layout, read and written with type checks), :mod:`.atomic` (files written whole or not at all, the
in-progress mark), :mod:`.environment` (the machine a run ran on) and :mod:`.report` (the HTML report, its plots
and the notebook display).  Records know no producer: the checks and the run import them, never the reverse.
"""
