"""The Main Tree's priorities: mission over, battery, wrong tool, task."""

from __future__ import annotations

import asyncio
import gc

import py_trees

from onboard_agent.behaviours.base import CommandSlot
from proto.telemetry import FlightState
from tests.onboard_agent.helpers import SCENARIO, Rig, inspect_task, on_a_spot, plan, point

C1 = SCENARIO.site.station("C1").position
C3 = SCENARIO.site.station("C3").position


def flying_at(rig: Rig, where) -> None:
    rig.autopilot.update(position=where, flight_state=FlightState.FLYING, armed=True, mode="GUIDED")


def test_nothing_to_do_on_the_pad_sends_nothing():
    rig = Rig()
    rig.tick(20)
    assert rig.autopilot.calls == []
    assert rig.agent.active_path()[:3] == ["Main Tree", "Mission Over", "Back To Station"]
    assert rig.agent.status().state == "idle"


def test_mission_over_in_the_air_goes_back_to_the_nearest_station():
    rig = Rig()
    flying_at(rig, point(8, 9, 3))
    rig.run_until(lambda: rig.autopilot.state.landed)
    assert on_a_spot(rig.autopilot.state.position, "C3")  # a shared one, never uav-3's
    assert rig.autopilot.names()[-1] == "land"


def test_low_battery_recharges_until_full_before_the_task():
    rig = Rig(battery=0.22)
    rig.agent.offer_plan(plan(inspect_task()))
    rig.tick(3)
    assert "Recharge" in rig.agent.active_path()
    assert rig.agent.status().state == "recharging"
    rig.autopilot.update(battery_fraction=0.6)  # enough again, but not full: keep charging
    rig.tick(5)
    assert rig.leaf() == "Recharge"
    assert "takeoff" not in rig.autopilot.names()
    rig.autopilot.update(battery_fraction=0.96)
    rig.run_until(lambda: "takeoff" in rig.autopilot.names(), max_ticks=10)
    rig.run_until(lambda: rig.mission.head is None)


def test_battery_not_enough_in_flight_heads_for_the_nearest_charging_station():
    rig = Rig(battery=0.3)
    flying_at(rig, point(8, 9, 3))
    far = inspect_task(n=3, service_s=200.0)  # hovering 200 s costs ~10 Wh
    rig.agent.offer_plan(plan(far))
    rig.tick()
    assert "Recharge" in rig.agent.active_path()
    assert rig.mission.head is far  # the task waits; nothing was abandoned
    rig.run_until(lambda: rig.leaf() == "Recharge")
    assert on_a_spot(rig.autopilot.state.position, "C3")


def test_the_tree_never_finishes():
    rig = Rig()
    rig.agent.offer_plan(plan(inspect_task()))
    for _ in range(300):
        rig.tick()
        assert rig.agent.tree.root.status in (
            py_trees.common.Status.RUNNING,
            py_trees.common.Status.SUCCESS,  # only via "Mission Over" (landed at a station)
        )
    assert rig.mission.head is None


def test_a_command_dropped_after_it_failed_leaves_no_unretrieved_exception():
    """A command the tree stops waiting for (cancelled, or replaced by the
    next one) has its exception retrieved: asyncio never logs "Task
    exception was never retrieved" for it."""

    async def refused() -> None:
        raise RuntimeError("denied")

    async def main() -> list[dict]:
        seen: list[dict] = []
        asyncio.get_running_loop().set_exception_handler(lambda _loop, ctx: seen.append(ctx))
        slot = CommandSlot()
        slot.issue("arm", asyncio.ensure_future(refused()))
        await asyncio.sleep(0.01)  # it failed; nobody checked
        slot.issue("arm", asyncio.ensure_future(refused()))  # replaced
        await asyncio.sleep(0.01)
        slot.cancel()  # and dropped
        await asyncio.sleep(0.01)
        gc.collect()
        await asyncio.sleep(0.01)
        return seen

    assert asyncio.run(main()) == []
