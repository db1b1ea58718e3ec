"""The README's promises: its two set-up commands exist and CI runs the same
test command."""

from __future__ import annotations

import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parent.parent


def _shell_blocks() -> list[str]:
    text = (ROOT / "README.md").read_text()
    first_screen = "\n## ".join(text.split("\n## ")[:2])  # the intro and "Start here"
    return [b.strip() for b in re.findall(r"```sh\n(.*?)```", first_screen, re.S)]


def test_first_screen_has_exactly_two_setup_commands():
    blocks = _shell_blocks()
    assert len(blocks) == 2
    assert all(len(block.splitlines()) == 1 for block in blocks)


def test_ci_runs_the_readme_test_command():
    test_command = _shell_blocks()[1]
    assert "pytest" in test_command
    assert test_command in (ROOT / ".ci" / "run").read_text()


def test_main_job_uses_a_registered_command():
    from linecrew.cli import BENCHES, COMMANDS

    words = _shell_blocks()[0].split("linecrew ", 1)[1].split()
    assert words[0] in COMMANDS or (words[0] == "bench" and words[1] in BENCHES)
