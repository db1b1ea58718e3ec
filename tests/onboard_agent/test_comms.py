"""The agent on a real router: resync by query, epoch fencing on the plan
key, outcomes held while no ground station is alive, telemetry and status,
the traffic report, worker poses trusted only on their own worker's key."""

from __future__ import annotations

import asyncio

from linecrew_runtime.bus import Bus
from onboard_agent.comms import Comms
from proto.geo import GeoPoint, Point
from proto.keys import KeySpace, Role
from proto.rpc import GetPlans, PlansReply
from proto.telemetry import (
    AgentStatus,
    HumanPose,
    TaskOutcome,
    Telemetry,
    Traffic,
    TrafficEntry,
)
from tests.onboard_agent.conftest import until
from tests.onboard_agent.helpers import Rig, inspect_task, plan

KEYS = KeySpace("default")


def test_comms_round_trip(bus_config):
    rig = Rig(gs_alive=False)
    mission = rig.mission
    got: dict[str, list] = {"outcome": [], "status": [], "telemetry": []}
    requests: list[GetPlans] = []

    def serve_plans(request: GetPlans) -> PlansReply:
        requests.append(request)
        return PlansReply(plans=[plan(inspect_task("from-query"), epoch=7)])

    async def main() -> None:
        with Bus.open(bus_config) as agent_bus, Bus.open(bus_config) as gs_bus:
            comms = Comms(agent_bus, KEYS, rig.agent)
            gs_bus.serve(KEYS.plan("uav-1"), GetPlans, serve_plans)
            for topic, kind in (
                ("outcome", TaskOutcome),
                ("status", AgentStatus),
                ("telemetry", Telemetry),
            ):
                key = KEYS.uav("uav-1", topic)
                gs_bus.subscribe(key, kind, lambda _k, m, t=topic: got[t].append(m))
            running = asyncio.create_task(comms.run())
            await until(lambda: gs_bus.alive(KEYS.alive(Role.AGENT, "uav-1")), what="agent token")

            token = gs_bus.declare_token(KEYS.alive(Role.GROUND_STATION, "gs"))
            await until(lambda: mission.epoch == 7, what="plan resync by query")
            assert requests[0].uav_id == "uav-1"

            gs_bus.publish(KEYS.plan("uav-1"), plan(inspect_task("old"), epoch=6))
            gs_bus.publish(KEYS.plan("uav-1"), plan(inspect_task("new"), epoch=8))
            await until(lambda: mission.epoch == 8, what="newer plan")
            assert mission.head.task_id == "new"

            token.close()
            await until(lambda: not rig.agent.emergency.link_up, what="gs gone")
            mission.fail(mission.head, "test failure")
            comms.after_tick(0.0)
            assert [o.task_id for o in mission.outbox] == ["new"]  # held back

            token = gs_bus.declare_token(KEYS.alive(Role.GROUND_STATION, "gs"))
            await until(lambda: rig.agent.emergency.link_up, what="gs back")
            comms.after_tick(1.0)
            await until(lambda: got["outcome"], what="outcome delivered")
            assert got["outcome"][0].task_id == "new" and got["outcome"][0].epoch == 8
            await until(lambda: got["telemetry"] and got["status"], what="telemetry and status")

            there = Point(x_m=1.0, y_m=2.0, z_m=5.0)
            report = Traffic(uavs=[TrafficEntry(uav_id="uav-2", position=there, airborne=True)])
            gs_bus.publish(KEYS.traffic(), report)
            traffic = rig.agent.ctx.traffic
            await until(lambda: traffic.holder(there, 1.0, rig.clock()), what="traffic report")
            assert traffic.holder(there, 1.0, rig.clock()).uav_id == "uav-2"

            surroundings = rig.agent.ctx.surroundings
            site_w1 = surroundings.worker_position("W1")
            moved = Point(x_m=site_w1.x_m + 40.0, y_m=site_w1.y_m, z_m=site_w1.z_m)
            pose = HumanPose(worker_id="W1", stamp_s=1.0, position=moved, geo=GeoPoint())
            gs_bus.publish(KEYS.human_pose("W2"), pose)  # W2's tracker speaking for W1
            await until(lambda: comms.refused == 1, what="spoofed pose refused")
            assert surroundings.worker_position("W1") == site_w1
            gs_bus.publish(KEYS.human_pose("W1"), pose)
            await until(lambda: surroundings.worker_position("W1") == moved, what="own pose")
            running.cancel()
            token.close()

    asyncio.run(main())


def test_a_held_plan_wakes_the_tick_loop_when_an_announcement_covers_it(bus_config):
    """A restarted agent holds a plan far ahead of any announced epoch; the
    traffic report announcing it adopts it and wakes the tick loop at once."""
    rig = Rig(gs_alive=False)
    wakes: list[int] = []

    async def main() -> None:
        with Bus.open(bus_config) as agent_bus, Bus.open(bus_config) as gs_bus:
            comms = Comms(
                agent_bus, KEYS, rig.agent, on_plan=lambda: wakes.append(rig.mission.epoch)
            )
            running = asyncio.create_task(comms.run())
            await until(lambda: gs_bus.alive(KEYS.alive(Role.AGENT, "uav-1")), what="agent token")
            gs_bus.publish(KEYS.plan("uav-1"), plan(inspect_task("far"), epoch=500))
            await until(lambda: wakes, what="the plan offered")
            assert rig.mission.epoch != 500  # held: nothing announced yet
            gs_bus.publish(KEYS.traffic(), Traffic(uavs=[], generation="gs-a", epoch=500))
            await until(lambda: rig.mission.epoch == 500, what="adopted on announcement")
            await until(lambda: wakes[-1] == 500, what="tick loop woken for it")
            running.cancel()

    asyncio.run(main())
