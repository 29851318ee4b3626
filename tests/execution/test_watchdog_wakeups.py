"""The watchdog thread (verimono.execution.watchdog) is woken only when a limit's deadline is earlier than the one it
sleeps until: a law's search enters several limits one after another (each phase, the root-cause probe), and a
notification at every entry and exit switched threads twice a limit — on a loaded machine ~1-2 ms of the main thread's
wall each, about 1200 times in the operator_laws stage.  It still names a call blocked in native code in a limit that
follows many others, at that limit's own deadline."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time

import pytest

from verimono.execution import watchdog
from verimono.execution.timeouts import supported


_WAKE_ONCE = r"""
import time
from verimono.execution import watchdog


class Counting:
    def __init__(self, cond):
        self.cond, self.notified = cond, 0

    def __enter__(self):
        return self.cond.__enter__()

    def __exit__(self, *a):
        return self.cond.__exit__(*a)

    def notify_all(self):
        self.notified += 1
        self.cond.notify_all()

    def wait(self, *a):
        return self.cond.wait(*a)


with watchdog.limit(30.0, "the first"):          # the thread runs and sleeps until this limit's deadline
    waited = time.monotonic()
    while watchdog._WAKE_AT == float("inf") and time.monotonic() - waited < 30.0:
        time.sleep(0.01)                          # on a loaded machine the thread may take a while to get there
    assert watchdog._WAKE_AT != float("inf"), "the watchdog thread never read the limit"
counting = Counting(watchdog._COND)
watchdog._COND = counting
for k in range(200):                              # later deadlines, one after another, and nested ones
    with watchdog.limit(40.0, f"phase {k}"), watchdog.limit(50.0, f"inner {k}"):
        pass
assert counting.notified <= 1, counting.notified
with watchdog.limit(0.5, "an earlier deadline"):  # earlier than the one it sleeps until: woken
    assert counting.notified >= 1, counting.notified
print("woken", counting.notified)
"""


def test_limits_one_after_another_wake_the_thread_once():
    """In an interpreter of its own: the watchdog's state is the process's (a thread, the time it sleeps until),
    and another test's limits in the same pytest worker would decide what this one sees."""
    out = subprocess.run([sys.executable, "-c", _WAKE_ONCE], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.startswith("woken"), out.stdout + out.stderr


@pytest.mark.slow       # the grace after a deadline is 2 s
@pytest.mark.skipif(not supported() or not sys.platform.startswith("linux"), reason="native hangs: POSIX")
def test_a_blocked_call_after_many_limits_is_named_at_its_deadline():
    got = []
    done = threading.Event()

    def handler(h):
        got.append((h, time.monotonic()))
        done.set()
    with watchdog.on_hang(handler, backstop=False):
        for k in range(50):
            with watchdog.limit(30.0, f"phase {k}"):
                pass
        start = time.monotonic()
        with watchdog.limit(0.2, "the blocked call"):
            os.system("sleep 3.2")        # native: no Python runs in this thread until it returns
    assert done.is_set()
    (hang, at), = got
    assert hang.call == "the blocked call"
    assert 0.2 + watchdog.grace(0.2) <= at - start < 3.2, at - start
