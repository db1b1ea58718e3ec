"""Reports of finished runs: ``linecrew report RUN_DIR`` (one HTML page) and
``linecrew export RUN_DIR --format jsonl`` (JSON lines).

``data`` reads a run directory, ``svg`` draws, ``html`` assembles the page,
``export`` writes the JSON lines, ``cli`` holds the two commands."""

from linecrew.report.html import write_report

__all__ = ["write_report"]
