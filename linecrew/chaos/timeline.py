"""Timed cuts and heals run on a thread of their own at their due time, so
a slow REST call in the runner's sampling loop (up to the gateway's RPC
timeout while the ground station is cut off) never stretches a cut or
delays a heal. Never start a supervised child from a step: its
PR_SET_PDEATHSIG would kill it when this thread ends."""

from __future__ import annotations

import heapq
import itertools
import logging
import threading
from collections.abc import Callable

log = logging.getLogger(__name__)

Step = Callable[[], None]


class Timeline:
    """``at(due_s, step)`` runs ``step`` once ``clock() >= due_s``, in due order;
    :meth:`close` runs what is left at once. A step that raises is logged."""

    def __init__(self, clock: Callable[[], float]) -> None:
        self._clock = clock
        self._steps: list[tuple[float, int, Step]] = []
        self._serial = itertools.count()
        self._busy = 0  # steps popped, not yet finished
        self._closed = False
        self._wake = threading.Condition()
        self._thread: threading.Thread | None = None  # started by the first step

    def at(self, due_s: float, step: Step) -> None:
        """Run ``step`` at ``due_s`` on the clock."""
        with self._wake:
            if not self._closed:
                heapq.heappush(self._steps, (due_s, next(self._serial), step))
                self._wake.notify()
                if self._thread is None:
                    self._thread = threading.Thread(
                        target=self._run, name="chaos-timeline", daemon=True
                    )
                    self._thread.start()
                return
        _do(step)

    def pending(self) -> int:
        """Steps not yet finished."""
        with self._wake:
            return len(self._steps) + self._busy

    def close(self) -> None:
        """Run every step left now (in due order) and stop the thread; later
        steps run at once on the caller's thread."""
        with self._wake:
            self._closed = True
            self._wake.notify()
            thread = self._thread
        if thread is not None:
            thread.join()

    def _run(self) -> None:
        while True:
            with self._wake:
                while not self._closed and (not self._steps or self._steps[0][0] > self._clock()):
                    wait = self._steps[0][0] - self._clock() if self._steps else None
                    self._wake.wait(wait)
                if not self._steps:
                    return  # closed and drained
                step = heapq.heappop(self._steps)[2]
                self._busy += 1
            _do(step)
            with self._wake:
                self._busy -= 1


def _do(step: Step) -> None:
    try:
        step()
    except Exception:
        log.exception("chaos step failed")
