"""Runs that die on purpose, for the tests of what a killed run leaves behind (tests/run)."""

from __future__ import annotations

import textwrap


def stage_killer(stage: str) -> str:
    """Python source for ``python -c``: the verimono CLI (its arguments from the command line), with the stage
    ``stage`` replaced by one that SIGKILLs the process when it starts."""
    return textwrap.dedent(f'''
        import os, signal, sys
        import verimono.run.stages as stages
        from verimono.cli import main

        real = stages.STAGES[{stage!r}]

        def killed(profile, context):
            os.kill(os.getpid(), signal.SIGKILL)

        stages.STAGES[{stage!r}] = stages.Stage({stage!r}, killed, real.description)
        sys.exit(main(sys.argv[1:]))
    ''')
