"""A verification run: ``verimono run`` / ``verimono check`` below the command line.

:mod:`.stages` (the registered stages and their units), :mod:`.execute` (running stages under a profile and an
executor, interrupts, resuming), :mod:`.performance` (the speed targets), :mod:`.gate` (the regression gate against
a baseline), :mod:`.progress` (the progress line) and :mod:`.targets` (``MODULE:OBJECT``).
"""
