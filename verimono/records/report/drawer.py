"""The command line's drawer: a forked copy of the ``verimono`` process that draws the report's plots while the
run goes on (:func:`drawer_pipe`, :func:`serve`).

The command line forks it before its imports, with the run's first calibration
(:class:`verimono.execution.calibration.PendingCalibration`, whose ``then`` it is): it imports matplotlib on the other core
while the run imports the checks, then draws each plot :func:`verimono.records.report.plots.draw_ahead` asks for as the
units deliver their studies, and keeps it until the report fetches it.  It answers only when asked, so it never
waits on the run; a thread takes the requests off its connection as they come, so the run never waits on it.  A
drawer that dies, or cannot draw a plot, leaves it to the report (drawn in the run's process, as without one).
"""

from __future__ import annotations

import threading
from typing import Any, Callable

from . import plots


class _Drawer:
    """This process's end of the drawer (:func:`serve`): plots asked for by
    :func:`verimono.records.report.plots.draw_ahead`, fetched when the report needs them.  A drawer that dies or cannot
    draw a plot leaves it to this process (drawn here, as without a drawer)."""

    def __init__(self, conn: Any) -> None:
        self.conn = conn
        self.asked: dict[int, Any] = {}       # id(subject) -> subject, asked and not yet fetched

    def ask(self, kind: str, subject: Any) -> None:
        key = id(subject)
        if key in self.asked:
            return
        try:
            self.conn.send(("draw", key, kind, subject))
        except Exception:  # noqa: BLE001 - a subject that cannot be sent, or a drawer gone: drawn here instead
            return
        self.asked[key] = subject

    def take(self, subject: Any) -> tuple[Any, str] | None:
        """The drawer's plot of ``subject`` (waiting for it when asked), or ``None``."""
        key = id(subject)
        if self.asked.pop(key, None) is None:
            return None
        try:
            self.conn.send(("send", key))
            got, html = self.conn.recv()
        except Exception:  # noqa: BLE001 - the drawer died: what it owes is drawn here
            self.asked.clear()
            return None
        return (subject, html) if got == key and html is not None else None

    def forget(self) -> None:
        """Fetch nothing of what was asked (the report that wanted it is written)."""
        self.asked.clear()

    def close(self) -> None:
        try:
            self.conn.close()
        except OSError:  # pragma: no cover
            pass


#: this process's end of its drawer, once connected
_CONNECTED: list[_Drawer] = []


def drawer_pipe() -> tuple[Callable[[], None], Callable[[bool], None]]:
    """``(serve_it, connect)``: before a fork, the two ends of a drawer — ``serve_it()`` runs :func:`serve` in
    the forked copy (its ``then``: :class:`verimono.execution.calibration.PendingCalibration`); ``connect(True)`` makes
    this process's :func:`verimono.records.report.plots.draw_ahead` send its plots there once the copy is forked, ``connect(False)`` closes
    both ends when it was not."""
    from multiprocessing import Pipe

    here, there = Pipe(duplex=True)

    def serve_it() -> None:
        here.close()
        serve(there)

    def connect(forked: bool) -> None:
        there.close()
        if forked:
            _CONNECTED.append(_Drawer(here))
            plots.use_drawer(_CONNECTED[-1])
        else:
            here.close()

    return serve_it, connect


def serve(conn: Any) -> None:
    """The drawer's loop (in a forked copy of the command line): import matplotlib
    (:func:`verimono.records.report.plots.warm_up`), then draw every ``("draw", key, kind, subject)`` as it comes and
    keep it, and answer ``("send", key)`` with ``(key, html)`` (``None`` where it could not draw it), until the
    connection closes.  It answers only when asked, so it never waits on the asking process; a thread takes
    the requests off the connection as they come, so the asking process never waits on it."""
    import queue

    inbox: queue.SimpleQueue = queue.SimpleQueue()

    def receive() -> None:
        while True:
            try:
                inbox.put(conn.recv())
            except Exception:  # noqa: BLE001 - closed (or garbled): the loop ends
                inbox.put(None)
                return

    threading.Thread(target=receive, name="verimono-drawer-inbox", daemon=True).start()
    plots.warm_up()
    draw = {"convergence": plots.convergence_plot, "trajectory": plots.trajectory_plot}
    drawn: dict[int, str | None] = {}
    while (msg := inbox.get()) is not None:
        if msg[0] == "draw":
            _, key, kind, subject = msg
            try:
                drawn[key] = draw[kind](subject)
            except Exception:  # noqa: BLE001 - the asking process draws it again and reports the error there
                drawn[key] = None
            plots.forget()
        else:
            try:
                conn.send((msg[1], drawn.pop(msg[1], None)))
            except OSError:
                return


def disconnect() -> None:
    """Close this process's end of the drawer (it then ends); plots are drawn here again."""
    if _CONNECTED:
        plots.use_drawer(None)
        _CONNECTED.pop().close()


__all__ = ["drawer_pipe", "serve", "disconnect"]
