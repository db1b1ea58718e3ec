"""What the agent reports: status with the active path, telemetry."""

from __future__ import annotations

from tests.onboard_agent.helpers import Rig, inspect_task, plan


def test_status_names_the_task_epoch_progress_and_active_path():
    rig = Rig()
    rig.agent.offer_plan(plan(inspect_task(n=2), inspect_task("t2"), epoch=4))
    rig.run_until(lambda: rig.leaf() == "Inspection")
    status = rig.agent.status()
    assert (status.uav_id, status.epoch, status.task_id, status.queue_length) == (
        "uav-1",
        4,
        "t1",
        2,
    )
    assert status.active_path[0] == "Main Tree"
    assert status.active_path[-3:] == ["Inspect Guard", "Inspection Task", "Inspection"]


def test_status_change_detection_ignores_time():
    rig = Rig()
    rig.tick()
    first = rig.agent.status()
    assert rig.agent.status_changed(first)
    rig.tick()
    assert not rig.agent.status_changed(rig.agent.status())
    rig.agent.offer_plan(plan(inspect_task()))
    rig.tick()
    assert rig.agent.status_changed(rig.agent.status())


def test_telemetry_converts_the_battery_with_the_type():
    rig = Rig(battery=0.5)
    telemetry = rig.agent.telemetry()
    assert telemetry.battery_fraction == 0.5
    assert telemetry.battery_wh == 10.0  # the paper's physical type: 20 Wh
    assert telemetry.flight_state == "landed"
