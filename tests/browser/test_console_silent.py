"""The console in a real browser while one UAV's agent is frozen (SIGSTOP)
for less than the ground station's link timeout, every process real, x10:
the fleet table says since when it is silent, its Gantt bars and its
action are shown unknown (not failed), an alert says it fell silent; thawed,
all goes back to normal and an alert says it was heard again."""

from __future__ import annotations

import re
import time

import pytest

from ground_station.config import GsConfig
from linecrew.launch.local_run import LocalRun, RunOptions
from tests.browser.test_console_live import PAPER, SPEEDUP, open_console, shoot, wait_loaded
from tests.support.freeze import frozen
from tests.support.processes import wait_until

LINK_TIMEOUT_S = GsConfig().link_timeout_s


@pytest.fixture(scope="module")
def run(tmp_path_factory, browser):
    options = RunOptions(speedup=SPEEDUP, run_dir=tmp_path_factory.mktemp("silent") / "run")
    with LocalRun(PAPER, options) as fleet:
        yield fleet


def working_on(gateway, action_id: str) -> str | None:
    """The UAV whose agent reports a task of ``action_id`` as its own."""
    for uav in gateway.call("GET", "/v1/fleet"):
        if ((uav.get("status") or {}).get("task_id") or "").startswith(f"{action_id}."):
            return uav["uav_id"]
    return None


def test_a_frozen_uav_is_shown_silent_since_a_time_with_its_tasks_unknown(run, new_page, artefacts):
    gateway = run.gateway()
    page, log = open_console(new_page, run)
    wait_loaded(page)
    body = {"type": "monitor", "worker_id": "W2", "uavs": 1, "duration_s": 120}
    watch = gateway.call("POST", "/v1/actions", json=body)["action_id"]
    victim: list = [None]

    def found() -> str | None:
        victim[0] = working_on(gateway, watch)
        return victim[0]

    wait_until(found, 60, "a UAV works on the watch", period_s=0.2)
    uav = victim[0]
    page.locator(f"#gantt .bar[data-uav='{uav}'][data-action='{watch}']").first.wait_for()
    row = page.locator(f"#fleet tr[data-uav='{uav}']")
    action = page.locator(f"#actions tr[data-action='{watch}']")

    with frozen(run, f"agent-{uav}") as stopped:

        def left_ms() -> float:  # shown before the ground station would declare it lost
            return max(1.0, (stopped + LINK_TIMEOUT_S - 0.7 - time.monotonic()) * 1000)

        page.locator(f"#fleet tr[data-uav='{uav}'][data-silent=yes]").wait_for(timeout=left_ms())
        bar = page.locator(f"#gantt .bar.unknown[data-uav='{uav}'][data-action='{watch}']")
        bar.first.wait_for(timeout=left_ms())
        page.locator(f"#actions tr[data-action='{watch}'][data-fate=unknown]").wait_for(
            timeout=left_ms()
        )
        state, task = row.locator(".c-state").inner_text(), row.locator(".c-task").inner_text()
        title = bar.first.locator("title").text_content()
        shown_state = action.locator(".c-state").inner_text()
        if left_ms() > 600:
            shoot(page, artefacts, "silent")
    assert re.search(r"\(silent since \d\d:\d\d:\d\d, \d+ s\)", state), state
    assert task.endswith(" unknown"), task
    assert f"fate unknown: {uav} silent since" in title
    assert re.fullmatch(r"(planned|in_progress) · unknown", shown_state), shown_state
    assert page.locator("#gantt-legend .fate-unknown").count() == 1

    page.locator(f"#fleet tr[data-uav='{uav}'][data-silent='']").wait_for(timeout=15_000)
    page.locator(f"#actions tr[data-action='{watch}'][data-fate='']").wait_for()
    assert page.locator("#gantt .bar.unknown").count() == 0
    assert "silent" not in row.locator(".c-state").inner_text()
    assert action.get_attribute("data-state") in ("planned", "in_progress", "completed")
    for title in ("UAV silent", "UAV heard again"):
        page.locator("#alerts li.alert", has_text=title).filter(has_text=uav).wait_for()
    shoot(page, artefacts, "heard-again")
    assert not log.errors, log.errors
