"""Whom the MAVLink link believes, over real UDP against sim_fleet vehicles:
only its own autopilot's address and ids, only signed packets once keyed;
strangers neither fly a vehicle, nor feed the agent a false state, nor push
it out of the vehicle's peer table."""

from __future__ import annotations

import asyncio
import dataclasses
import hashlib
import socket
import time

import pytest
from pymavlink.dialects.v20 import ardupilotmega as dialect

from onboard_agent import LinkLost
from onboard_agent.autopilot.link import MavlinkLink
from proto.geo import SiteFrame
from proto.telemetry import FlightState
from tests.onboard_agent.conftest import (
    LINK_CONFIG,
    fast_scenario,
    fly,
    start_fleet,
    until,
)
from tests.sim_fleet.mavclient import Client

KEY = hashlib.sha256(b"uav-1 test passphrase").digest()
FORCE_DISARM = 21196
LOCAL = "127.0.0.1"
SITE = fast_scenario().site


@pytest.fixture
def signed_fleet():
    """uav-1 holds KEY; the other vehicles are unsigned."""
    runner = start_fleet(signing_keys={"uav-1": KEY})
    try:
        yield runner
    finally:
        runner.stop()


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind((LOCAL, 0))
        return probe.getsockname()[1]


def forged(*, key: bytes | None = None) -> list[bytes]:
    """Frames claiming to be autopilot 1: battery 3 %, a position 3,800 km away."""
    mav = dialect.MAVLink(None, srcSystem=1, srcComponent=1)
    if key is not None:
        mav.signing.secret_key, mav.signing.sign_outgoing = key, True
        mav.signing.timestamp = 2**40
    far = mav.global_position_int_encode(0, 340_000_000, 0, 10_000, 10_000, 0, 0, 0, 0)
    battery = mav.battery_status_encode(0, 0, 0, 32767, [11000] + [65535] * 9, 100, 0, 0, 3, 0, 0)
    return [far.pack(mav), battery.pack(mav)]


def assert_believes_only_the_sim(link, seconds: float = 1.0) -> None:
    """Over ``seconds`` the link's battery and position stay the vehicle's."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        assert link.state.battery_fraction > 0.5
        assert abs(link.state.position.y_m) < 1_000
        time.sleep(0.02)


def test_a_signed_link_flies_and_a_stranger_without_the_key_cannot(signed_fleet):
    vehicle = signed_fleet.fleet.world.vehicle("uav-1")
    endpoint = signed_fleet.fleet.endpoints["uav-1"]
    stranger = Client(signed_fleet.fleet.ports["uav-1"], 1, streams_hz=0)

    def stranger_command(command: int, *params: float) -> None:
        p = [*params, *[0.0] * (7 - len(params))]
        stranger.conn.mav.command_long_send(1, 1, command, 0, *p)

    async def scenario(link):
        stranger_command(dialect.MAV_CMD_COMPONENT_ARM_DISARM, 1, FORCE_DISARM)
        await until(lambda: endpoint.rejected >= 2, what="the stranger's packets rejected")
        assert stranger.conn.recv_match(type="COMMAND_ACK", blocking=True, timeout=0.5) is None
        assert not vehicle.armed
        assert stranger.conn.port.getsockname() not in endpoint.peers  # gets no telemetry
        await link.set_mode("GUIDED")
        await link.arm()
        await link.takeoff(4.0)
        await until(lambda: link.state.position.z_m > 3.5, what="climb on the signed link")
        rejected = endpoint.rejected
        stranger_command(dialect.MAV_CMD_COMPONENT_ARM_DISARM, 0, FORCE_DISARM)
        await until(lambda: endpoint.rejected > rejected, what="the disarm rejected")
        assert vehicle.armed and link.state.flight_state is not FlightState.CRASHED

    try:
        fly(signed_fleet, "uav-1", scenario, signing_key=KEY)
    finally:
        stranger.close()


def never_finds_its_autopilot(fleet, config=LINK_CONFIG, **options) -> None:
    """A link to uav-1 that hears no autopilot it may fly: commands raise LinkLost."""

    async def main() -> None:
        url = f"udpout:{LOCAL}:{fleet.fleet.ports['uav-1']}"
        link = MavlinkLink(url, SiteFrame(SITE.origin), config, **options)
        link.start()
        try:
            with pytest.raises(LinkLost):
                await link.arm()
            assert not link.state.link_ok and not link.state.known
        finally:
            link.close()

    asyncio.run(main())


@pytest.mark.parametrize("key", [None, hashlib.sha256(b"another passphrase").digest()])
def test_an_agent_without_the_vehicles_key_is_neither_heard_nor_streamed_to(signed_fleet, key):
    endpoint = signed_fleet.fleet.endpoints["uav-1"]
    never_finds_its_autopilot(signed_fleet, signing_key=key)
    assert endpoint.rejected > 0 and not endpoint.peers


def test_frames_forged_to_the_agents_port_are_not_believed(fleet):
    async def scenario(link):
        port = link._conn.port.getsockname()[1]
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as liar:
            for frame in forged() * 5:
                liar.sendto(frame, (LOCAL, port))
        await asyncio.to_thread(assert_believes_only_the_sim, link)

    fly(fleet, "uav-1", scenario)


def test_a_keyed_link_drops_and_counts_frames_not_signed_with_its_key():
    port = free_udp_port()
    runner = start_fleet(signing_keys={"uav-1": KEY}, static_peers=((LOCAL, port),))

    async def scenario(link):
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as liar:
            for frame in forged() + forged(key=hashlib.sha256(b"wrong").digest()):
                liar.sendto(frame, (LOCAL, port))
        await until(lambda: link.dropped >= 4, what="forged frames counted")
        await asyncio.to_thread(assert_believes_only_the_sim, link, 0.5)

    try:
        # udpin: the agent listens, the vehicle streams to it (SITL udpclient)
        fly(runner, "uav-1", scenario, url=f"udpin:{LOCAL}:{port}", signing_key=KEY)
    finally:
        runner.stop()


def test_another_systems_heartbeat_is_not_taken_for_the_autopilot(fleet):
    never_finds_its_autopilot(
        fleet, dataclasses.replace(LINK_CONFIG, autopilot_system=2)
    )  # uav-1: 1


def test_strangers_can_neither_crowd_out_the_agent_nor_silence_its_heartbeat(fleet):
    endpoint = fleet.fleet.endpoints["uav-1"]
    port = fleet.fleet.ports["uav-1"]

    async def scenario(link):
        strangers = [Client(port, 1, streams_hz=0) for _ in range(9)]
        try:
            strangers[0].conn.mav.command_long_send(
                1, 1, dialect.MAV_CMD_SET_MESSAGE_INTERVAL, 0, 0, -1, 0, 0, 0, 0, 0
            )
            denied = strangers[0].wait("COMMAND_ACK", timeout_s=5.0)
            assert denied.result == dialect.MAV_RESULT_DENIED
            deadline = time.monotonic() + 2.0
            while time.monotonic() < deadline:  # a flood of hellos from 9 addresses
                for stranger in strangers:
                    stranger.hello()
                assert link.state.link_ok
                await asyncio.sleep(0.05)
            assert endpoint.refused_peers > 0
            assert link._conn.port.getsockname() in endpoint.peers
        finally:
            for stranger in strangers:
                stranger.close()

    fly(fleet, "uav-1", scenario)


def test_a_forced_disarm_in_flight_is_reported_as_a_crash(fleet):
    stranger = Client(fleet.fleet.ports["uav-1"], 1, streams_hz=0)

    async def scenario(link):
        await link.set_mode("GUIDED")
        await link.arm()
        await link.takeoff(6.0)
        await until(lambda: link.state.position.z_m > 5.0, what="climb")
        stranger.conn.mav.command_long_send(
            1, 1, dialect.MAV_CMD_COMPONENT_ARM_DISARM, 0, 0, FORCE_DISARM, 0, 0, 0, 0, 0
        )
        await until(lambda: link.state.flight_state is FlightState.CRASHED, what="crash seen")

    try:
        fly(fleet, "uav-1", scenario)
    finally:
        stranger.close()
