"""Real MAVLink 2 over UDP on loopback: a pymavlink client flies a simulated copter."""

from __future__ import annotations

import socket

import pytest

from sim_fleet import Fleet, FleetConfig, FleetThread
from sim_fleet.modes import Mode
from sim_fleet.params import AutopilotParams
from tests.sim_fleet.mavclient import SPEEDUP, Client, mavlink
from tests.sim_fleet.small_world import small_world

ACCEPTED = mavlink.MAV_RESULT_ACCEPTED


def test_heartbeat_is_an_arducopter_quad(client):
    hb = client.wait("HEARTBEAT", lambda m: m.get_srcSystem() == 1)
    assert hb.type == mavlink.MAV_TYPE_QUADROTOR
    assert hb.autopilot == mavlink.MAV_AUTOPILOT_ARDUPILOTMEGA
    assert hb.custom_mode == Mode.STABILIZE
    assert hb.base_mode & mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
    assert not hb.base_mode & mavlink.MAV_MODE_FLAG_SAFETY_ARMED
    assert hb.get_msgbuf()[0] == 0xFD  # MAVLink 2 framing
    bat = client.wait("BATTERY_STATUS")
    assert bat.battery_remaining == 100 and bat.voltages[0] > 16000
    ext = client.wait("EXTENDED_SYS_STATE")
    assert ext.landed_state == mavlink.MAV_LANDED_STATE_ON_GROUND


def test_each_vehicle_has_its_own_port_and_system_id(fleet):
    ports = fleet.fleet.ports
    assert len(set(ports.values())) == 2
    c2 = Client(ports["uav2"], target_system=2)
    try:
        hb = c2.wait("HEARTBEAT")
        assert hb.get_srcSystem() == 2
    finally:
        c2.close()


def test_guided_arm_takeoff_goto_land(fleet, client):
    world = fleet.fleet.world
    assert client.set_mode(Mode.GUIDED).result == ACCEPTED
    client.wait("HEARTBEAT", lambda m: m.custom_mode == Mode.GUIDED)
    assert client.command(mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == ACCEPTED
    client.wait("HEARTBEAT", lambda m: m.base_mode & mavlink.MAV_MODE_FLAG_SAFETY_ARMED)
    assert client.command(mavlink.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 5).result == ACCEPTED
    client.wait("GLOBAL_POSITION_INT", lambda m: m.relative_alt > 4900, timeout_s=20)
    client.wait("EXTENDED_SYS_STATE", lambda m: m.landed_state == mavlink.MAV_LANDED_STATE_IN_AIR)

    lat, lon, _ = fleet.call(lambda: world.geo.to_geodetic((0.0, 5.0, 0.0)))
    client.goto_global(lat, lon, 6.0)

    def arrived(m):
        near = abs(m.lat - lat * 1e7) < 5 and abs(m.lon - lon * 1e7) < 5
        return near and m.relative_alt > 5900

    client.wait("GLOBAL_POSITION_INT", arrived, timeout_s=30)
    here = fleet.call(lambda: world.vehicle("uav1").position)
    assert here == pytest.approx((0.0, 5.0, 6.0), abs=0.1)  # 1e-7 deg is about 1 cm

    assert client.command(mavlink.MAV_CMD_NAV_LAND).result == ACCEPTED
    client.wait("HEARTBEAT", lambda m: m.custom_mode == Mode.LAND)
    client.wait(
        "EXTENDED_SYS_STATE",
        lambda m: m.landed_state == mavlink.MAV_LANDED_STATE_ON_GROUND,
        timeout_s=30,
    )
    client.wait("HEARTBEAT", lambda m: not m.base_mode & mavlink.MAV_MODE_FLAG_SAFETY_ARMED)
    bat = client.wait("BATTERY_STATUS")
    assert bat.energy_consumed > 0 and bat.battery_remaining < 100


def test_refused_commands_get_the_arducopter_result(client):
    # DO_CHANGE_SPEED with a non-positive speed: DENIED
    ack = client.command(mavlink.MAV_CMD_DO_CHANGE_SPEED, 1, 0)
    assert ack.result == mavlink.MAV_RESULT_DENIED
    assert ack.target_system == 255
    # takeoff while disarmed: FAILED
    ack = client.command(mavlink.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 5)
    assert ack.result == mavlink.MAV_RESULT_FAILED
    # arming in LAND: FAILED with ArduCopter's reason
    client.set_mode(Mode.LAND)
    ack = client.command(mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    assert ack.result == mavlink.MAV_RESULT_FAILED
    assert "Arm: Mode not armable" in client.texts
    # a command ArduCopter does not know
    ack = client.command(31000)
    assert ack.result == mavlink.MAV_RESULT_UNSUPPORTED


def test_set_mode_message_is_acked_and_denied_without_custom_flag(client):
    client.conn.mav.set_mode_send(1, 0, Mode.GUIDED)
    ack = client.wait("COMMAND_ACK", lambda m: m.command == mavlink.MAVLINK_MSG_ID_SET_MODE)
    assert ack.result == mavlink.MAV_RESULT_DENIED
    client.conn.mav.set_mode_send(1, mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, Mode.GUIDED)
    ack = client.wait("COMMAND_ACK", lambda m: m.command == mavlink.MAVLINK_MSG_ID_SET_MODE)
    assert ack.result == ACCEPTED


def test_gripper_unsupported_on_vehicle_without_one(fleet):
    c2 = Client(fleet.fleet.ports["uav2"], target_system=2)
    try:
        ack = c2.command(mavlink.MAV_CMD_DO_GRIPPER, 1, 1)
        assert ack.result == mavlink.MAV_RESULT_UNSUPPORTED
    finally:
        c2.close()


def test_message_interval_and_request_message(client):
    ack = client.command(mavlink.MAV_CMD_SET_MESSAGE_INTERVAL, 33, -1)
    assert ack.result == ACCEPTED
    ack = client.command(mavlink.MAV_CMD_GET_MESSAGE_INTERVAL, 33)
    assert ack.result == ACCEPTED
    iv = client.wait("MESSAGE_INTERVAL", lambda m: m.message_id == 33)
    assert iv.interval_us == -1
    ack = client.command(mavlink.MAV_CMD_REQUEST_MESSAGE, mavlink.MAVLINK_MSG_ID_HOME_POSITION)
    assert ack.result == ACCEPTED
    home = client.wait("HOME_POSITION")
    assert home.latitude != 0
    ack = client.command(mavlink.MAV_CMD_REQUEST_MESSAGE, 9999)
    assert ack.result == mavlink.MAV_RESULT_FAILED
    ack = client.command(mavlink.MAV_CMD_SET_MESSAGE_INTERVAL, 9999, 1000)
    assert ack.result == mavlink.MAV_RESULT_DENIED


def test_garbage_datagrams_do_not_kill_the_endpoint(fleet, client):
    port = fleet.fleet.ports["uav1"]
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for junk in (b"", b"\x00" * 3, b"\xfd\xff" + b"\x01" * 300, bytes(range(256)) * 4):
            s.sendto(junk, ("127.0.0.1", port))
        # a truncated real packet too
        enc = mavlink.MAVLink(None, 255, 190)
        pkt = enc.command_long_encode(1, 1, 400, 0, 1, 0, 0, 0, 0, 0, 0).pack(enc)
        s.sendto(pkt[:-3], ("127.0.0.1", port))
    ack = client.command(mavlink.MAV_CMD_DO_CHANGE_SPEED, 1, 0)
    assert ack.result == mavlink.MAV_RESULT_DENIED
    assert fleet.call(lambda: fleet.fleet.endpoints["uav1"].bad_datagrams) >= 1
    assert not fleet.call(lambda: fleet.fleet.world.vehicle("uav1").armed)


def test_link_drop_silences_the_vehicle(fleet, client):
    client.wait("HEARTBEAT")
    fleet.call(lambda: fleet.fleet.world.vehicle("uav1").drop_link(3600.0))
    # drain what is in flight, then expect silence
    client.conn.recv_match(blocking=True, timeout=0.3)
    while client.conn.recv_match(blocking=False) is not None:
        pass
    assert client.conn.recv_match(type="HEARTBEAT", blocking=True, timeout=1.0) is None


def test_local_ned_flight_grab_and_deliver_a_tool(fleet, client):
    world = fleet.fleet.world
    client.set_mode(Mode.GUIDED)
    client.command(mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    client.command(mavlink.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 4)
    client.wait("GLOBAL_POSITION_INT", lambda m: m.relative_alt > 3900, timeout_s=20)

    ox, oy, _ = fleet.call(lambda: world.vehicle("uav1").origin)  # its home spot at C1

    def local_goto(east, north, up):  # LOCAL_NED is about the EKF origin
        client.conn.mav.set_position_target_local_ned_send(
            0, 1, 1, mavlink.MAV_FRAME_LOCAL_NED, 0b110111111000,
            north - oy, east - ox, -up, 0, 0, 0, 0, 0, 0, 0, 0,
        )  # fmt: skip
        lat, lon, _ = fleet.call(lambda: world.geo.to_geodetic((east, north, 0.0)))

        def there(m):  # at the target and still (hovering before it moves is neither)
            near = abs(m.lat - lat * 1e7) < 5 and abs(m.lon - lon * 1e7) < 5
            return near and abs(m.relative_alt - up * 1000) < 50 and abs(m.vx) + abs(m.vy) < 5

        client.wait("GLOBAL_POSITION_INT", there, timeout_s=30)
        pos = fleet.call(lambda: world.vehicle("uav1").position)
        assert pos == pytest.approx((east, north, up), abs=0.1)

    local_goto(-2.0, 5.0, 4.0)  # the hammer's pick-up point is (-2, 5, 3)
    assert client.command(mavlink.MAV_CMD_DO_GRIPPER, 1, 1).result == ACCEPTED
    client.wait_text(lambda t: t.startswith("Gripper: grabbed hammer"))
    local_goto(0.0, 9.0, 5.0)  # worker W1 stands at (0, 10, 3)
    assert client.command(mavlink.MAV_CMD_DO_GRIPPER, 1, 0).result == ACCEPTED
    client.wait_text(lambda t: t == "Gripper: delivered hammer to W1")
    [d] = fleet.call(lambda: list(world.deliveries))
    assert (d.tool_id, d.vehicle_id, d.worker_id) == ("hammer", "uav1", "W1")


def test_rtl_returns_home_lands_and_disarms(fleet, client):
    client.set_mode(Mode.GUIDED)
    client.command(mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    client.command(mavlink.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 3)
    client.wait("GLOBAL_POSITION_INT", lambda m: m.relative_alt > 2900, timeout_s=20)
    home = client.wait("GLOBAL_POSITION_INT")
    assert client.command(mavlink.MAV_CMD_NAV_RETURN_TO_LAUNCH).result == ACCEPTED
    client.wait("HEARTBEAT", lambda m: m.custom_mode == Mode.RTL)
    client.wait("GLOBAL_POSITION_INT", lambda m: m.relative_alt > 14900, timeout_s=30)
    client.wait("HEARTBEAT", lambda m: not m.base_mode & mavlink.MAV_MODE_FLAG_SAFETY_ARMED, 60)
    final = client.wait("GLOBAL_POSITION_INT")
    assert abs(final.relative_alt) < 10
    assert abs(final.lat - home.lat) < 5 and abs(final.lon - home.lon) < 5


def test_static_peer_gets_telemetry_without_speaking_first():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        peer_port = probe.getsockname()[1]
    from pymavlink import mavutil

    listener = mavutil.mavlink_connection(f"udpin:127.0.0.1:{peer_port}")
    cfg = FleetConfig(speedup=SPEEDUP, base_port=0, static_peers=(("127.0.0.1", peer_port),))
    runner = FleetThread(Fleet(small_world(1), cfg)).start()
    try:
        hb = listener.recv_match(type="HEARTBEAT", blocking=True, timeout=10)
        assert hb is not None and hb.get_srcSystem() == 1
    finally:
        runner.stop()
        listener.close()


@pytest.fixture
def warming():
    """One vehicle with a 40 s (simulated, 2 s of wall time) GPS/EKF warm-up."""
    cfg = FleetConfig(
        speedup=SPEEDUP, rate_hz=50.0, base_port=0, params=AutopilotParams(warmup_s=40.0)
    )
    runner = FleetThread(Fleet(small_world(1), cfg)).start()
    c = Client(runner.fleet.ports["uav1"], target_system=1)
    try:
        yield runner, c
    finally:
        c.close()
        runner.stop()


def test_nothing_but_heartbeats_until_a_client_asks():
    cfg = FleetConfig(speedup=SPEEDUP, rate_hz=50.0, base_port=0)
    runner = FleetThread(Fleet(small_world(1), cfg)).start()
    c = Client(runner.fleet.ports["uav1"], target_system=1, streams_hz=0)
    try:
        c.wait("HEARTBEAT")
        assert c.conn.recv_match(type="GLOBAL_POSITION_INT", blocking=True, timeout=1.0) is None
        ack = c.command(mavlink.MAV_CMD_SET_MESSAGE_INTERVAL, 33, 200_000)
        assert ack.result == ACCEPTED
        c.wait("GLOBAL_POSITION_INT")
        assert c.conn.recv_match(type="GPS_RAW_INT", blocking=True, timeout=0.5) is None
        c.request_streams(5.0)  # REQUEST_DATA_STREAM, every group
        for kind in ("GPS_RAW_INT", "EKF_STATUS_REPORT", "SYS_STATUS", "BATTERY_STATUS"):
            c.wait(kind)
    finally:
        c.close()
        runner.stop()


def test_warm_up_refuses_arming_with_arducopter_texts_then_arms_and_rehomes(warming):
    runner, c = warming
    world = runner.fleet.world
    pos = c.wait("GLOBAL_POSITION_INT")
    assert (pos.lat, pos.lon) == (0, 0)  # no position before the EKF has an origin
    assert c.wait("GPS_RAW_INT").fix_type < 3
    ekf = c.wait("EKF_STATUS_REPORT")
    assert ekf.flags & mavlink.EKF_CONST_POS_MODE
    status = c.wait("SYS_STATUS")
    assert status.onboard_control_sensors_present & mavlink.MAV_SYS_STATUS_PREARM_CHECK
    assert not status.onboard_control_sensors_health & mavlink.MAV_SYS_STATUS_PREARM_CHECK
    assert c.set_mode(Mode.GUIDED).result == ACCEPTED  # disarmed: any mode, as ArduCopter
    ack = c.command(mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    assert ack.result == mavlink.MAV_RESULT_FAILED
    c.wait_text(lambda t: t == "PreArm: AHRS: waiting for home")
    c.wait_text(lambda t: t == "PreArm: GPS 1: Bad fix")
    assert c.command(mavlink.MAV_CMD_REQUEST_MESSAGE, 242).result == ACCEPTED
    home = c.wait("HOME_POSITION", timeout_s=10.0)  # sent when set, at the end of the warm-up
    assert home.latitude != 0 and runner.call(lambda: world.time_s) >= 40.0
    c.wait("GPS_RAW_INT", lambda m: m.fix_type == 3 and m.satellites_visible > 0)
    c.wait("EKF_STATUS_REPORT", lambda m: not m.flags & mavlink.EKF_CONST_POS_MODE)
    c.wait(
        "SYS_STATUS",
        lambda m: m.onboard_control_sensors_health & mavlink.MAV_SYS_STATUS_PREARM_CHECK,
    )
    c.wait("GLOBAL_POSITION_INT", lambda m: m.lat != 0)
    c.texts.clear()
    assert c.command(mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == ACCEPTED
    rehomed = c.wait("HOME_POSITION")  # ArduCopter re-homes (and says so) on arming
    assert (rehomed.latitude, rehomed.longitude) == (home.latitude, home.longitude)
    assert runner.call(lambda: world.vehicle("uav1").home_version) == 2


def test_parameters_list_read_set_and_grip_enable(fleet, client):
    client.conn.mav.param_request_list_send(1, 1)
    values = {}
    while len(values) < 5:
        m = client.wait("PARAM_VALUE")
        values[m.param_id] = m
    count = next(iter(values.values())).param_count
    while len(values) < count:
        m = client.wait("PARAM_VALUE")
        values[m.param_id] = m
    assert values["GRIP_ENABLE"].param_value == 1.0  # uav1 carries a gripper
    assert values["RTL_ALT"].param_value == 1500.0
    assert sorted(m.param_index for m in values.values()) == list(range(count))
    client.conn.mav.param_request_read_send(1, 1, b"RTL_ALT", -1)
    assert client.wait("PARAM_VALUE", lambda m: m.param_id == "RTL_ALT").param_value == 1500
    client.conn.mav.param_set_send(1, 1, b"GRIP_ENABLE", 0, mavlink.MAV_PARAM_TYPE_INT8)
    assert client.wait("PARAM_VALUE", lambda m: m.param_id == "GRIP_ENABLE").param_value == 0
    ack = client.command(mavlink.MAV_CMD_DO_GRIPPER, 1, 1)
    assert ack.result == mavlink.MAV_RESULT_FAILED  # ArduCopter: gripper not enabled
    client.conn.mav.param_set_send(1, 1, b"GRIP_ENABLE", 1, mavlink.MAV_PARAM_TYPE_INT8)
    client.wait("PARAM_VALUE", lambda m: m.param_id == "GRIP_ENABLE" and m.param_value == 1)
    assert client.command(mavlink.MAV_CMD_DO_GRIPPER, 1, 1).result == ACCEPTED
    client.conn.mav.param_set_send(1, 1, b"RTL_ALT", 2500, mavlink.MAV_PARAM_TYPE_INT32)
    client.wait("PARAM_VALUE", lambda m: m.param_id == "RTL_ALT" and m.param_value == 2500)
    assert fleet.call(lambda: fleet.fleet.world.vehicle("uav1").rtl_alt_m) == 25.0


def test_reposition_brake_and_loiter(fleet, client):
    world = fleet.fleet.world
    client.set_mode(Mode.GUIDED)
    client.command(mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    client.command(mavlink.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, 4)
    client.wait("GLOBAL_POSITION_INT", lambda m: m.relative_alt > 3900, timeout_s=20)
    assert client.set_mode(Mode.BRAKE).result == ACCEPTED
    lat, lon, _ = fleet.call(lambda: world.geo.to_geodetic((-10.0, 16.0, 0.0)))
    frame = mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
    ack = client.command_int(
        mavlink.MAV_CMD_DO_REPOSITION, frame, -1, 0, 0, 0, lat * 1e7, lon * 1e7, 6
    )
    assert ack.result == mavlink.MAV_RESULT_DENIED  # not GUIDED and no change-mode flag
    ack = client.command_int(
        mavlink.MAV_CMD_DO_REPOSITION, frame, -1, 1, 0, 0, lat * 1e7, lon * 1e7, 6
    )
    assert ack.result == ACCEPTED
    client.wait("HEARTBEAT", lambda m: m.custom_mode == Mode.GUIDED)
    client.wait("GLOBAL_POSITION_INT", lambda m: abs(m.relative_alt - 6000) < 50, timeout_s=30)
    assert client.set_mode(Mode.LOITER).result == ACCEPTED
    here = fleet.call(lambda: world.vehicle("uav1").position)
    client.wait("HEARTBEAT", lambda m: m.custom_mode == Mode.LOITER)
    client.goto_global(lat, lon, 10.0)  # ignored outside GUIDED
    client.wait("HEARTBEAT")
    assert fleet.call(lambda: world.vehicle("uav1").position) == pytest.approx(here, abs=0.5)
