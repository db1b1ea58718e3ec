"""The benches' child processes, which print a line once they are ready."""

from __future__ import annotations

import subprocess


def wait_ready(child: subprocess.Popen[bytes]) -> None:
    """Block until ``child`` (started with ``stdout=PIPE``) prints its first line."""
    if child.stdout is None:
        raise ValueError("the child's stdout is not a pipe")
    child.stdout.readline()
