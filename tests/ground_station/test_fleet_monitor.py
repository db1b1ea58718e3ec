"""The watchdog on a fake clock: brief drop-outs are only told (silent,
heard again), long ones make a UAV lost, its return makes it back."""

from __future__ import annotations

import msgspec
import pytest

from ground_station.fleet_monitor import Change, FleetMonitor, unknown_tasks
from proto import (
    AgentState,
    AgentStatus,
    FlightState,
    GeoPoint,
    Plan,
    Point,
    Telemetry,
    UavOpState,
    WaitTask,
)


def telemetry(uav: str, flight: FlightState = FlightState.FLYING) -> Telemetry:
    return Telemetry(
        uav_id=uav,
        stamp_s=0,
        position=Point(x_m=0, y_m=0),
        geo=GeoPoint(),
        battery_wh=10,
        battery_fraction=0.5,
        flight_state=flight,
    )


def present(monitor: FleetMonitor, uav: str, now: float) -> None:
    monitor.on_token(uav, True, now)
    monitor.on_telemetry(telemetry(uav), now)


def test_never_heard_uavs_start_lost_without_an_event():
    monitor = FleetMonitor(["u1"], 5.0)
    assert monitor.state("u1") == UavOpState.LOST
    assert monitor.check(100.0) == []


def test_appearing_is_back_and_a_short_silence_changes_nothing():
    monitor = FleetMonitor(["u1"], 5.0)
    present(monitor, "u1", 0.0)
    assert monitor.check(0.0) == [("u1", Change.BACK)]
    present(monitor, "u1", 1.0)
    monitor.on_token("u1", False, 1.0)
    assert monitor.check(5.9) == [("u1", Change.SILENT)]  # 4.9 s: within the grace, told
    assert monitor.silence_s("u1", 5.9) == pytest.approx(4.9)
    present(monitor, "u1", 5.9)
    assert monitor.check(6.0) == [("u1", Change.HEARD)]
    assert monitor.state("u1") == UavOpState.IDLE


def test_token_loss_longer_than_the_timeout_is_lost_once():
    monitor = FleetMonitor(["u1"], 5.0)
    present(monitor, "u1", 0.0)
    monitor.check(0.0)
    monitor.on_token("u1", False, 1.0)
    monitor.on_telemetry(telemetry("u1"), 3.0)  # late samples do not hide a lost token
    assert monitor.check(5.5) == [("u1", Change.SILENT)]
    assert monitor.check(6.0) == [("u1", Change.LOST)]
    assert monitor.check(7.0) == []
    assert monitor.state("u1") == UavOpState.LOST
    assert not monitor.available("u1")


def test_stale_telemetry_with_a_live_token_is_lost_too():
    monitor = FleetMonitor(["u1"], 5.0)
    present(monitor, "u1", 0.0)
    monitor.check(0.0)
    assert monitor.check(4.99) == [("u1", Change.SILENT)]
    assert monitor.check(5.0) == [("u1", Change.LOST)]
    present(monitor, "u1", 9.0)
    assert monitor.check(9.0) == [("u1", Change.BACK)]


def test_states_follow_the_agent_and_crashes():
    monitor = FleetMonitor(["u1"], 5.0)
    present(monitor, "u1", 0.0)
    monitor.check(0.0)
    assert monitor.state("u1") == UavOpState.IDLE
    monitor.on_status(AgentStatus(uav_id="u1", stamp_s=0, state=AgentState.RECHARGING))
    assert monitor.state("u1") == UavOpState.RECHARGING and monitor.available("u1")
    monitor.on_status(AgentStatus(uav_id="u1", stamp_s=0, state=AgentState.EMERGENCY))
    assert not monitor.available("u1")
    monitor.on_telemetry(telemetry("u1", FlightState.CRASHED), 1.0)
    assert monitor.state("u1") == UavOpState.FAILED


def test_a_fallen_uav_is_shown_holding_off_for_nobody():
    """An agent's last status said it held off for another UAV; once its
    vehicle crashed that is no longer so (the operator saw "failed, holding
    off for uav-1")."""
    monitor = FleetMonitor(["u1"], 5.0)
    present(monitor, "u1", 0.0)
    monitor.check(0.0)
    busy = AgentStatus(uav_id="u1", stamp_s=0, state=AgentState.BUSY, holding_for="u2")
    monitor.on_status(busy)
    [row] = monitor.snapshot({})
    assert row.status is not None and row.status.holding_for == "u2"
    monitor.on_telemetry(telemetry("u1", FlightState.CRASHED), 1.0)
    [row] = monitor.snapshot({})
    assert row.state == UavOpState.FAILED
    assert row.status is not None and row.status.holding_for is None


def test_unknown_uavs_are_ignored():
    monitor = FleetMonitor(["u1"], 5.0)
    monitor.on_token("intruder", True, 0.0)
    monitor.on_telemetry(telemetry("intruder"), 0.0)
    assert not monitor.known("intruder")
    assert [s.uav_id for s in monitor.snapshot({})] == ["u1"]


def test_a_silent_uav_shows_how_long_it_has_been_silent_until_heard_or_lost():
    monitor = FleetMonitor(["u1"], 5.0)
    present(monitor, "u1", 0.0)
    monitor.check(0.5)
    assert monitor.snapshot({})[0].silent_s is None  # heard half a second ago: normal
    monitor.check(3.0)
    (shown,) = monitor.snapshot({})
    assert shown.state != UavOpState.LOST and shown.silent_s == pytest.approx(3.0)
    present(monitor, "u1", 3.5)
    monitor.check(3.6)
    assert monitor.snapshot({})[0].silent_s is None
    monitor.check(9.0)
    (lost,) = monitor.snapshot({})
    assert lost.state == UavOpState.LOST and lost.silent_s is None


def test_an_agent_that_reported_failed_and_recovers_is_back():
    """A restarted agent may report failed until its autopilot answers; once
    it reports healthy it must get a fresh plan (a BACK), not go on with the
    plan it resynced while it could take no work."""
    monitor = FleetMonitor(["u1"], 5.0)
    present(monitor, "u1", 0.0)
    monitor.check(0.0)
    monitor.on_status(AgentStatus(uav_id="u1", stamp_s=1, state=AgentState.FAILED))
    assert monitor.check(1.0) == [("u1", Change.FAILED)]
    assert monitor.check(1.5) == []
    present(monitor, "u1", 2.0)
    monitor.on_status(AgentStatus(uav_id="u1", stamp_s=2, state=AgentState.BUSY))
    assert monitor.check(2.0) == [("u1", Change.BACK)]
    assert monitor.available("u1")
    assert monitor.check(2.5) == []


def test_an_agent_not_ready_takes_no_work_until_it_is_ready():
    monitor = FleetMonitor(["u1"], 5.0)
    present(monitor, "u1", 0.0)
    monitor.check(0.0)
    monitor.on_status(AgentStatus(uav_id="u1", stamp_s=0, state=AgentState.NOT_READY))
    assert monitor.state("u1") == UavOpState.NOT_READY
    assert not monitor.available("u1")
    assert monitor.check(0.5) == [("u1", Change.NOT_READY)]  # its work goes elsewhere
    assert monitor.check(1.0) == []  # said once
    monitor.on_status(AgentStatus(uav_id="u1", stamp_s=1, state=AgentState.IDLE))
    assert monitor.check(1.5) == [("u1", Change.BACK)]  # ready: it gets work again
    assert monitor.available("u1")


def test_traffic_says_where_each_uav_was_heard_and_for_how_long_lost_ones_too():
    monitor = FleetMonitor(["u1", "u2", "u3", "u4"], 5.0)
    present(monitor, "u1", 10.0)
    monitor.on_telemetry(telemetry("u2", FlightState.LANDED), 10.0)
    present(monitor, "u3", 0.0)  # silent since: lost, but may hover on where it was
    monitor.check(10.0)
    report = monitor.traffic(12.0)
    entries = {e.uav_id: (e.airborne, e.age_s) for e in report.uavs}
    assert entries == {"u1": (True, 2.0), "u2": (False, 2.0), "u3": (True, 12.0)}  # u4: never heard
    assert [e.uav_id for e in monitor.traffic(75.0).uavs] == []  # all older than a minute


def test_traffic_passes_on_the_target_each_uav_was_flying_to():
    monitor = FleetMonitor(["u1"], 5.0)
    target = Point(x_m=3.0, y_m=4.0, z_m=5.0)
    sample = msgspec.structs.replace(telemetry("u1", FlightState.FLYING), target=target)
    monitor.on_telemetry(sample, 10.0)
    [entry] = monitor.traffic(11.0).uavs
    assert entry.target == target


class Clocks:
    """The watchdog's clock (``now``) and a mission clock on it: x10 from 1000 s."""

    def __init__(self) -> None:
        self.now = 0.0

    def mission(self) -> float:
        return 1000.0 + 10 * self.now


def x10() -> tuple[FleetMonitor, Clocks]:
    clocks = Clocks()
    return FleetMonitor(["u1"], 5.0, mission_clock=clocks.mission), clocks


def heard(
    monitor: FleetMonitor, clocks: Clocks, now: float, status: AgentStatus | None = None
) -> None:
    clocks.now = now
    present(monitor, "u1", now)
    if status is not None:
        monitor.on_status(status, now)


def test_a_silent_spell_is_told_once_when_it_begins_and_once_when_it_ends():
    monitor, clocks = x10()
    heard(monitor, clocks, 0.0)
    assert monitor.check(0.0) == [("u1", Change.BACK)]
    heard(monitor, clocks, 1.0)
    assert monitor.check(2.9) == []  # 1.9 s: not silent yet
    assert monitor.check(3.0) == [("u1", Change.SILENT)]
    assert monitor.silent_since("u1") == pytest.approx(1010.0)  # mission time last heard
    assert [monitor.check(t) for t in (3.5, 4.0, 5.9)] == [[], [], []]  # no storm
    (shown,) = monitor.snapshot({})
    assert shown.silent_s == pytest.approx(4.9) and shown.silent_since_s == pytest.approx(1010.0)
    heard(monitor, clocks, 5.95)
    assert monitor.check(6.0) == [("u1", Change.HEARD)]
    assert monitor.check(6.5) == [] and monitor.silent_since("u1") is None
    (normal,) = monitor.snapshot({})
    assert normal.silent_s is None and normal.silent_since_s is None


def test_a_spell_ended_by_the_link_timeout_is_lost_not_heard():
    monitor, clocks = x10()
    heard(monitor, clocks, 0.0)
    monitor.check(0.0)
    assert monitor.check(2.5) == [("u1", Change.SILENT)]
    assert monitor.check(5.0) == [("u1", Change.LOST)]
    assert monitor.silent_since("u1") is None
    heard(monitor, clocks, 8.0)
    assert monitor.check(8.0) == [("u1", Change.BACK)]  # no HEARD for the old spell
    assert monitor.check(8.5) == []


def test_silence_begins_when_the_token_vanished_if_that_came_first():
    monitor, clocks = x10()
    heard(monitor, clocks, 0.0)
    monitor.check(0.0)
    clocks.now = 1.0
    monitor.on_token("u1", False, 1.0)
    clocks.now = 1.5
    monitor.on_telemetry(telemetry("u1"), 1.5)  # a last sample after the token vanished
    assert monitor.check(3.2) == [("u1", Change.SILENT)]
    assert monitor.silent_since("u1") == pytest.approx(1010.0)


def plan(*task_ids: str) -> Plan:
    return Plan(uav_id="u1", epoch=3, tasks=[WaitTask(task_id=t, until_s=0.0) for t in task_ids])


def test_a_silent_uav_s_running_and_pending_tasks_are_unknown_until_it_is_heard():
    monitor, clocks = x10()
    busy = AgentStatus(uav_id="u1", stamp_s=0, state=AgentState.BUSY, task_id="a.t2")
    heard(monitor, clocks, 0.0, busy)
    monitor.check(0.0)
    plans = {"u1": plan("a.t1", "a.t2", "a.t3")}
    assert monitor.snapshot(plans)[0].unknown_tasks == []  # heard: its tasks are as reported
    monitor.check(2.5)
    (silent,) = monitor.snapshot(plans)
    assert silent.unknown_tasks == ["a.t2", "a.t3"]  # the one it ran and those after it
    assert silent.state == UavOpState.BUSY  # not failed, not lost
    assert monitor.snapshot({})[0].unknown_tasks == []  # no plan: nothing unknown
    heard(monitor, clocks, 3.0, busy)
    monitor.check(3.0)
    assert monitor.snapshot(plans)[0].unknown_tasks == []


def test_every_task_is_unknown_when_the_uav_reported_none_of_them():
    idle = AgentStatus(uav_id="u1", stamp_s=0, state=AgentState.IDLE)
    assert unknown_tasks(plan("a.t1", "a.t2"), idle) == ["a.t1", "a.t2"]
    assert unknown_tasks(plan("a.t1"), None) == ["a.t1"]
