"""A process whose shutdown hangs after SIGTERM still exits, by force, at
its deadline (a child of a killed ``linecrew up`` has nobody else to stop it)."""

from __future__ import annotations

import signal
import subprocess
import sys

from linecrew_runtime.process import EXIT_OVERDUE
from tests.support.processes import Child, start, wait_until

HANGS_ON_SHUTDOWN = """
import threading
from linecrew_runtime.process import Shutdown
shutdown = Shutdown(deadline_s=1.0).install()
print("ready", flush=True)
shutdown.wait()
print("stopping", flush=True)
threading.Event().wait()  # a close that never returns
"""

STOPS = """
from linecrew_runtime.process import Shutdown
shutdown = Shutdown(deadline_s=1.0).install()
print("ready", flush=True)
shutdown.wait()
"""


def started(code: str) -> Child:
    proc = start([sys.executable, "-c", code], "shutdown")
    wait_until(lambda: "ready" in proc.output(), 30, "the process ready")
    return proc


def test_a_process_that_hangs_in_its_shutdown_exits_at_the_deadline():
    proc = started(HANGS_ON_SHUTDOWN)
    proc.popen.send_signal(signal.SIGTERM)
    try:
        code = proc.popen.wait(30)
    except subprocess.TimeoutExpired:
        proc.popen.kill()
        raise AssertionError("still running long past its deadline") from None
    assert code == EXIT_OVERDUE
    assert "stopping" in proc.output()
    assert "exiting now" in proc.output()


def test_a_process_that_stops_in_time_exits_normally():
    proc = started(STOPS)
    proc.popen.send_signal(signal.SIGTERM)
    assert proc.popen.wait(30) == 0
    assert "exiting now" not in proc.output()
