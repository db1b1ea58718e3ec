"""The CLI's fleet table says how long a present UAV has been silent."""

from __future__ import annotations

from rich.console import Console

from linecrew.client.render import fleet_table


def test_a_silent_uav_shows_its_silence_next_to_its_state():
    uavs = [
        {"uav_id": "uav-1", "state": "busy", "silent_s": 3.2},
        {"uav_id": "uav-2", "state": "idle", "silent_s": None},
    ]
    console = Console(width=120, record=True)
    console.print(fleet_table(uavs))
    text = console.export_text()
    assert "busy (silent 3 s)" in text
    assert "idle" in text and "idle (silent" not in text
