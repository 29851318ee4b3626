"""The watchdog's faulthandler backstop (verimono.execution.watchdog) is armed once for limits that follow one
another, not once per limit: each arming starts a C thread and each cancel joins it while holding the GIL, and with
every core busy (a run's two workers) the join waited for a core, ~1-4 ms of the worker's wall, ~1,700 times in a
``ci`` run's untimed stages.  One timer serves every limit it fires no earlier than ``budget + 2 x grace`` of and at
most half a grace after; left armed when no limit is open, it is cancelled by the watchdog thread before it fires,
and before a fork (a child inheriting an armed timer hangs in its own first arming)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from verimono.execution.timeouts import supported

pytestmark = pytest.mark.skipif(not supported() or not sys.platform.startswith("linux"),
                                reason="faulthandler's timer and os.fork: POSIX")

_COUNTING = r"""
import faulthandler, os, sys, time
from verimono.execution import watchdog

calls = {"arm": 0, "cancel": 0}
_arm, _cancel = faulthandler.dump_traceback_later, faulthandler.cancel_dump_traceback_later


def arm(*a, **k):
    calls["arm"] += 1
    return _arm(*a, **k)


def cancel(*a, **k):
    calls["cancel"] += 1
    return _cancel(*a, **k)


faulthandler.dump_traceback_later, faulthandler.cancel_dump_traceback_later = arm, cancel


def in_window(seconds, start):
    # the armed timer fires no earlier than budget + 2 x grace and at most half a grace later
    g = watchdog.grace(seconds)
    at = watchdog._BACKSTOP_AT
    return watchdog._BACKSTOP_ARMED and start + seconds + 2 * g - 1e-6 <= at <= time.monotonic() + seconds + 2.5 * g
"""

_ONE_AFTER_ANOTHER = _COUNTING + r"""
with watchdog.on_hang(lambda hang: None):
    for k in range(400):                          # a law's phases, the laws of a unit: limits one after another
        start = time.monotonic()
        with watchdog.limit(30.0, f"phase {k}"):
            assert in_window(30.0, start), (k, watchdog._BACKSTOP_AT - start)
            time.sleep(0.001)
    many = dict(calls)
    start = time.monotonic()
    with watchdog.limit(0.5, "an earlier deadline"):   # needs it earlier: re-armed for it
        assert in_window(0.5, start)
    assert calls["arm"] == many["arm"] + 1, (many, calls)
print("arms", many["arm"], "cancels", many["cancel"])
assert many["arm"] <= 3 and many["cancel"] == 0, many
assert not watchdog._BACKSTOP_ARMED                # the handler removed: cancelled at once
"""

_STALE = _COUNTING + r"""
with watchdog.on_hang(lambda hang: None):
    with watchdog.limit(0.01, "a short limit"):
        pass
    at = watchdog._BACKSTOP_AT
    assert watchdog._BACKSTOP_ARMED and at - time.monotonic() > watchdog.STALE_MARGIN
    while time.monotonic() < at + 1.0:            # past the moment it would have ended this process
        time.sleep(0.05)
    assert not watchdog._BACKSTOP_ARMED and calls["cancel"] == 1, calls
print("alive")
"""

_FORK = _COUNTING + r"""
def child_arms():
    pid = os.fork()
    if pid == 0:
        with watchdog.on_hang(lambda hang: None), watchdog.limit(30.0, "the child's limit"):
            pass
        os._exit(0)
    waited = time.monotonic()
    while time.monotonic() - waited < 20:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return status
        time.sleep(0.02)
    os.kill(pid, 9)
    os.waitpid(pid, 0)
    return "hung"


with watchdog.on_hang(lambda hang: None):
    start = time.monotonic()
    with watchdog.limit(30.0, "a limit open across the fork"):
        assert child_arms() == 0
        assert in_window(30.0, start)             # the parent's backstop re-armed after the fork
    assert watchdog._BACKSTOP_ARMED               # left armed, no limit open
    assert child_arms() == 0
    assert not watchdog._BACKSTOP_ARMED           # cancelled before that fork, not re-armed
print("forked")
"""


def _run(code: str) -> str:
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr
    return out.stdout


def test_limits_one_after_another_arm_the_backstop_once():
    """In an interpreter of its own (the watchdog's state is the process's): 400 limits, at most 3 armings (400
    before, each arming after the first joining the previous timer's thread), no cancel; each limit's timer in its
    window; a limit that needs it earlier re-arms it.  (A tighter limit nested in another still arms the timer
    on entry and again on exit: its window and the outer one's do not meet.)"""
    assert _run(_ONE_AFTER_ANOTHER).startswith("arms")


@pytest.mark.slow       # the timer of a limit fires 5 s after it at the least
def test_a_backstop_no_limit_needs_is_cancelled_before_it_fires():
    assert _run(_STALE).strip() == "alive"


def test_a_fork_inherits_no_armed_backstop():
    """A child forked inside a limit, and one forked after it, arm their own backstop without hanging."""
    assert _run(_FORK).strip() == "forked"
