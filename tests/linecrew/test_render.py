"""The CLI's fleet table says since when (mission clock) and how long a
present UAV has been silent, and that its tasks are unknown meanwhile."""

from __future__ import annotations

from rich.console import Console

from linecrew.client.render import fleet_table

SINCE_S = 86_400.0 * 196_000 + 3_723.5  # mission seconds whose time of day is 01:02:03


def shown(uavs: list[dict]) -> str:
    console = Console(width=160, record=True)
    console.print(fleet_table(uavs))
    return console.export_text()


def test_a_silent_uav_shows_since_when_and_how_long_next_to_its_state():
    text = shown(
        [
            {"uav_id": "uav-1", "state": "busy", "silent_s": 3.2, "silent_since_s": SINCE_S},
            {"uav_id": "uav-2", "state": "idle", "silent_s": None},
        ]
    )
    assert "busy (silent since 01:02:03, 3 s)" in text
    assert "idle" in text and "idle (silent" not in text


def test_a_silent_uav_s_tasks_are_shown_unknown_not_failed_nor_running():
    status = {"task_id": "act-1.pick", "epoch": 4}
    silent = {
        "uav_id": "uav-1",
        "state": "busy",
        "silent_s": 2.5,
        "silent_since_s": SINCE_S,
        "status": status,
        "unknown_tasks": ["act-1.pick", "act-1.drop", "uav-1.home"],
    }
    text = shown([silent])
    assert "act-1.pick unknown, +2 pending" in text and "failed" not in text
    heard = {**silent, "silent_s": None, "silent_since_s": None, "unknown_tasks": []}
    text = shown([heard])
    assert "act-1.pick" in text and "unknown" not in text
