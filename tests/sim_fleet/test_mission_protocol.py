"""The MAVLink mission protocol and AUTO, driven by a pymavlink client over UDP:
upload / download / clear with ArduPilot's results, and missions flown in AUTO
checked against the simulator's ground truth."""

from __future__ import annotations

import math
from dataclasses import dataclass

import pytest

from sim_fleet.auto_mission import WP_RADIUS_M
from sim_fleet.modes import Mode
from tests.sim_fleet.mavclient import Client, mavlink

ACCEPTED = mavlink.MAV_RESULT_ACCEPTED
REL = mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
AMSL = mavlink.MAV_FRAME_GLOBAL_INT
WP, LOITER_TIME, RTL, LAND, TAKEOFF = 16, 19, 20, 21, 22
CHANGE_SPEED, GRIPPER = 178, 211
HOME_C1 = (-8.0, 10.0, 0.0)  # uav1's home spot, beside C1's pad (proto.spots)
ARMED = mavlink.MAV_MODE_FLAG_SAFETY_ARMED


@dataclass(frozen=True)
class Item:
    command: int
    frame: int = REL
    x: int = 0
    y: int = 0
    z: float = 0.0
    params: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)


def at(fleet, east: float, north: float, z: float, *, cmd: int = WP, frame: int = REL, hold=0.0):
    """An item at site (east, north) and height z: above home, or AMSL for GLOBAL_INT."""
    lat, lon, alt = fleet.call(lambda: fleet.fleet.world.geo.to_geodetic((east, north, z)))
    return Item(cmd, frame, round(lat * 1e7), round(lon * 1e7), alt if frame == AMSL else z,
                (hold, 0.0, 0.0, 0.0))  # fmt: skip


def send_item(client: Client, seq: int, item: Item, mission_type: int = 0) -> None:
    client.conn.mav.mission_item_int_send(
        1, 1, seq, item.frame, item.command, int(seq == 0), 1, *item.params,
        item.x, item.y, item.z, mission_type,
    )  # fmt: skip


def upload(client: Client, items: list[Item]) -> int:
    """MISSION_COUNT, then every requested item; returns the MISSION_ACK type."""
    client.conn.mav.mission_count_send(1, 1, len(items), 0)
    while True:
        msg = client.wait(("MISSION_REQUEST_INT", "MISSION_ACK"))
        if msg.get_type() == "MISSION_ACK":
            return msg.type
        send_item(client, msg.seq, items[msg.seq])


def download(client: Client) -> list:
    client.conn.mav.mission_request_list_send(1, 1, 0)
    count = client.wait("MISSION_COUNT").count
    items = []
    for seq in range(count):
        client.conn.mav.mission_request_int_send(1, 1, seq, 0)
        items.append(client.wait("MISSION_ITEM_INT", lambda m, seq=seq: m.seq == seq))
    client.conn.mav.mission_ack_send(1, 1, 0, 0)
    return items


def takeoff(alt: float) -> Item:
    return Item(TAKEOFF, REL, 0, 0, alt)


def arm_in_guided(client: Client) -> None:
    assert client.set_mode(Mode.GUIDED).result == ACCEPTED
    assert client.command(mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == ACCEPTED


def progress(client: Client, last: int, timeout_s: float = 60.0) -> tuple[list[int], list[int]]:
    """MISSION_ITEM_REACHED seqs in order up to ``last``, and the distinct
    MISSION_CURRENT seqs of the running mission seen meanwhile."""
    reached: list[int] = []
    current: list[int] = []
    while not reached or reached[-1] != last:
        msg = client.wait(("MISSION_ITEM_REACHED", "MISSION_CURRENT"), timeout_s=timeout_s)
        if msg.get_type() == "MISSION_ITEM_REACHED":
            reached.append(msg.seq)
        elif msg.mission_state == mavlink.MISSION_STATE_ACTIVE and msg.seq not in current:
            current.append(msg.seq)
    return reached, current


def mission_log(fleet) -> dict[int, tuple[float, tuple[float, float, float]]]:
    """seq -> (sim time, true position) of each finished item."""
    log = fleet.call(lambda: list(fleet.fleet.endpoints["uav1"].auto.log))
    return {seq: (t, pos) for seq, t, pos in log}


def test_upload_download_round_trip(fleet, client):
    a = at(fleet, -10.0, 16.0, 5.0)
    b = at(fleet, -4.0, 16.0, 6.0, frame=AMSL)
    items = [Item(WP, 0), takeoff(5.0), a, b, Item(LAND)]
    assert upload(client, items) == mavlink.MAV_MISSION_ACCEPTED
    got = download(client)
    assert [m.command for m in got] == [WP, TAKEOFF, WP, WP, LAND]
    lat, lon, alt = fleet.call(lambda: fleet.fleet.world.geo.to_geodetic(HOME_C1))
    assert got[0].frame == mavlink.MAV_FRAME_GLOBAL  # item 0 is home, AMSL
    assert (got[0].x, got[0].y) == (round(lat * 1e7), round(lon * 1e7))
    assert got[0].z == pytest.approx(alt, abs=0.01)
    # frames come back as ArduPilot stores them: relative / absolute
    assert got[2].frame == mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT
    assert (got[2].x, got[2].y, got[2].z) == (a.x, a.y, pytest.approx(5.0))
    assert got[3].frame == mavlink.MAV_FRAME_GLOBAL
    assert (got[3].x, got[3].y, got[3].z) == (b.x, b.y, pytest.approx(b.z))
    # legacy MISSION_REQUEST is answered with a (float) MISSION_ITEM
    client.conn.mav.mission_request_send(1, 1, 2, 0)
    legacy = client.wait("MISSION_ITEM", lambda m: m.seq == 2)
    assert legacy.x == pytest.approx(a.x / 1e7, abs=1e-6)
    client.conn.mav.mission_request_int_send(1, 1, 9, 0)
    assert client.wait("MISSION_ACK").type == mavlink.MAV_MISSION_INVALID_SEQUENCE


def test_item_not_sent_is_requested_again_and_out_of_sequence_is_refused(client):
    client.conn.mav.mission_count_send(1, 1, 2, 0)
    first = client.wait("MISSION_REQUEST_INT")
    assert first.seq == 0 and first.target_system == 255
    again = client.wait("MISSION_REQUEST_INT", timeout_s=5.0)  # no reply: asked again
    assert again.seq == 0
    send_item(client, 0, Item(WP, 0))
    assert client.wait("MISSION_REQUEST_INT", lambda m: m.seq == 1).seq == 1
    send_item(client, 3, takeoff(4.0))
    assert client.wait("MISSION_ACK").type == mavlink.MAV_MISSION_INVALID_SEQUENCE
    send_item(client, 1, takeoff(4.0))  # the upload went on
    assert client.wait("MISSION_ACK").type == mavlink.MAV_MISSION_ACCEPTED
    assert [m.command for m in download(client)] == [WP, TAKEOFF]


def test_refused_uploads_keep_the_mission_and_name_the_reason(fleet, client):
    assert upload(client, [Item(WP, 0), takeoff(4.0)]) == mavlink.MAV_MISSION_ACCEPTED
    loiter_turns = Item(18)  # NAV_LOITER_TURNS: not simulated
    assert upload(client, [Item(WP, 0), loiter_turns]) == mavlink.MAV_MISSION_UNSUPPORTED
    local = Item(WP, mavlink.MAV_FRAME_LOCAL_NED, 0, 0, 5.0)
    assert upload(client, [Item(WP, 0), local]) == mavlink.MAV_MISSION_UNSUPPORTED_FRAME
    bad_lat = Item(WP, REL, 950_000_000, 0, 5.0)
    assert upload(client, [Item(WP, 0), bad_lat]) == mavlink.MAV_MISSION_INVALID_PARAM5_X
    client.conn.mav.mission_count_send(1, 1, 5000, 0)
    assert client.wait("MISSION_ACK").type == mavlink.MAV_MISSION_NO_SPACE
    assert [m.command for m in download(client)] == [WP, TAKEOFF]  # unchanged
    # no fences or rally points: empty lists, uploads unsupported
    client.conn.mav.mission_count_send(1, 1, 3, mavlink.MAV_MISSION_TYPE_FENCE)
    ack = client.wait("MISSION_ACK")
    assert (ack.type, ack.mission_type) == (mavlink.MAV_MISSION_UNSUPPORTED, 1)
    client.conn.mav.mission_request_list_send(1, 1, mavlink.MAV_MISSION_TYPE_RALLY)
    assert client.wait("MISSION_COUNT", lambda m: m.mission_type == 2).count == 0
    send_item(client, 1, takeoff(3.0))  # not uploading
    assert client.wait("MISSION_ACK").type == mavlink.MAV_MISSION_ERROR


def test_clear_all_leaves_home(client):
    assert upload(client, [Item(WP, 0), takeoff(4.0), Item(LAND)]) == 0
    client.conn.mav.mission_clear_all_send(1, 1, 0)
    assert client.wait("MISSION_ACK").type == mavlink.MAV_MISSION_ACCEPTED
    assert [m.command for m in download(client)] == [WP]
    current = client.wait("MISSION_CURRENT")
    assert current.mission_state == mavlink.MISSION_STATE_NO_MISSION


def test_set_current(client):
    assert upload(client, [Item(WP, 0), takeoff(4.0), Item(WP), Item(LAND)]) == 0
    client.conn.mav.mission_set_current_send(1, 1, 2)
    assert client.wait("MISSION_CURRENT", lambda m: m.seq == 2).total == 3
    ack = client.command(mavlink.MAV_CMD_DO_SET_MISSION_CURRENT, 9)
    assert ack.result == mavlink.MAV_RESULT_FAILED
    assert client.command(mavlink.MAV_CMD_DO_SET_MISSION_CURRENT, 1).result == ACCEPTED
    assert client.wait("MISSION_CURRENT", lambda m: m.seq == 1).mission_mode == 2  # not AUTO


def test_auto_refuses_what_arducopter_refuses(client):
    assert upload(client, [Item(WP, 0), Item(WP), Item(LAND)]) == 0
    ack = client.command(mavlink.MAV_CMD_MISSION_START)
    assert ack.result == mavlink.MAV_RESULT_FAILED  # disarmed
    arm_in_guided(client)
    assert client.set_mode(Mode.AUTO).result == mavlink.MAV_RESULT_FAILED  # landed, no takeoff
    client.wait_text(lambda t: t == "Auto: Missing Takeoff Cmd")
    assert client.command(mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 0).result == ACCEPTED
    assert client.set_mode(Mode.AUTO).result == ACCEPTED  # disarmed: any mission
    client.wait("HEARTBEAT", lambda m: m.custom_mode == Mode.AUTO)
    ack = client.command(mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    assert ack.result == mavlink.MAV_RESULT_FAILED  # AUTO is not armable (AUTO_OPTIONS 0)
    client.wait_text(lambda t: t == "Arm: Mode not armable")


def test_auto_flies_waypoints_changes_speed_and_returns_to_launch(fleet, client):
    a = at(fleet, -10.0, 16.0, 5.0)
    b = at(fleet, -4.0, 16.0, 6.0, frame=AMSL)
    speed = Item(CHANGE_SPEED, 2, params=(1.0, 2.5, -1.0, 0.0))
    items = [Item(WP, 0), takeoff(4.0), a, speed, b, Item(RTL)]
    assert upload(client, items) == 0
    arm_in_guided(client)
    assert client.command(mavlink.MAV_CMD_MISSION_START).result == ACCEPTED
    client.wait("HEARTBEAT", lambda m: m.custom_mode == Mode.AUTO)
    reached, current = progress(client, 5)
    assert reached == [1, 2, 3, 4, 5]
    assert current == [1, 2, 4, 5]  # nav items; the DO item ran on the way
    client.wait("HEARTBEAT", lambda m: not m.base_mode & ARMED, timeout_s=30)
    done = client.wait("MISSION_CURRENT", lambda m: m.mission_state == 5)
    assert done.mission_mode == 1 and done.total == 5
    log = mission_log(fleet)
    assert log[1][1][2] == pytest.approx(4.0, abs=0.1)  # took off to 4 m
    for seq, target in ((2, (-10.0, 16.0, 5.0)), (4, (-4.0, 16.0, 6.0))):
        assert math.dist(log[seq][1], target) <= WP_RADIUS_M
    world = fleet.fleet.world
    v = world.vehicle("uav1")
    assert fleet.call(lambda: v.position) == pytest.approx(HOME_C1, abs=0.1)  # RTL landed
    assert fleet.call(lambda: (v.mode, v.armed, v.speed_mps)) == (Mode.AUTO, False, 2.5)
    for text in ("Mission: 1 Takeoff", "Mission: 3 ChangeSpeed", "Mission: 5 RTL"):
        assert text in client.texts


def test_auto_loiters_then_holds_at_the_last_waypoint(fleet, client):
    p = at(fleet, -10.0, 14.0, 5.0, cmd=LOITER_TIME, hold=4.0)
    q = at(fleet, -6.0, 14.0, 5.0)
    assert upload(client, [Item(WP, 0), takeoff(3.0), p, q]) == 0
    arm_in_guided(client)
    assert client.set_mode(Mode.AUTO).result == ACCEPTED  # armed, first item a takeoff
    assert progress(client, 3)[0] == [1, 2, 3]
    client.wait("MISSION_CURRENT", lambda m: m.mission_state == mavlink.MISSION_STATE_COMPLETE)
    log = mission_log(fleet)
    assert log[2][0] - log[1][0] >= 4.0  # the loiter's 4 s hold
    v = fleet.fleet.world.vehicle("uav1")
    for _ in range(3):  # simulated seconds pass: it stays at the last waypoint, in AUTO
        client.wait("HEARTBEAT")
    assert fleet.call(lambda: v.position) == pytest.approx((-6.0, 14.0, 5.0), abs=0.05)
    assert fleet.call(lambda: (v.mode, v.armed, v.state)) == (Mode.AUTO, True, "flying")


def test_auto_mission_grabs_and_delivers_with_the_gripper(fleet, client):
    pick = at(fleet, -2.0, 5.0, 4.5, hold=4.0)  # above the hammer's station (z 3)
    drop = at(fleet, 0.0, 9.0, 5.5, hold=4.0)  # above worker W1 (z 3)
    grab, release = Item(GRIPPER, 2, params=(1, 1, 0, 0)), Item(GRIPPER, 2, params=(1, 0, 0, 0))
    land_on_pad = at(fleet, *HOME_C1, cmd=LAND)  # flies there, then descends
    items = [Item(WP, 0), takeoff(4.5), pick, grab, drop, release, land_on_pad]
    assert upload(client, items) == 0
    arm_in_guided(client)
    assert client.command(mavlink.MAV_CMD_MISSION_START).result == ACCEPTED
    assert progress(client, 6)[0] == [1, 2, 3, 4, 5, 6]
    client.wait_text(lambda t: t == "Gripper: delivered hammer to W1", timeout_s=30)
    [d] = fleet.call(lambda: list(fleet.fleet.world.deliveries))
    assert (d.tool_id, d.vehicle_id, d.worker_id) == ("hammer", "uav1", "W1")
    client.wait("HEARTBEAT", lambda m: not m.base_mode & ARMED, timeout_s=30)
    v = fleet.fleet.world.vehicle("uav1")
    assert fleet.call(lambda: v.position) == pytest.approx(HOME_C1, abs=0.1)  # landed there
