"""One vehicle's MAVLink 2 endpoint on its own UDP port, speaking like ArduCopter.

Transport (the SITL shape): the endpoint *listens* on its UDP port, like
ArduPilot SITL's ``udpin``-able serial port or PX4's fixed local port. Every
address that sends it a valid MAVLink packet becomes a peer that receives
telemetry (a pymavlink ``udpout:127.0.0.1:PORT`` or MAVSDK ``udpout://``
client connects by sending anything, e.g. its GCS heartbeat). Configured
static peers (like SITL ``udpclient:HOST:PORT`` or PX4's remote port) get
telemetry from the start, so ``udpin`` clients work too. COMMAND_ACKs go only
to the address that sent the command.

This is the only pymavlink importer in ``sim_fleet``. Untrusted bytes never
raise out of here: each datagram gets a fresh parser (MAVLink over UDP puts
whole packets in a datagram, so garbage cannot eat the next one), and bad
datagrams are counted and logged once per source.

Signing: given a key, the endpoint signs everything it sends and acts only on
packets signed with that key (MAVLink 2 signing, as ArduPilot does once a key
is set); anything else is counted in ``rejected`` and never makes a peer.
Replays are refused by the signature's timestamp (one signing state per
endpoint, shared by every datagram's parser).

Peers: a learned peer heard within ``PEER_LIVE_S`` keeps its place, so a
flood of strangers cannot push the agent out of the table; a newcomer finds
room only when a peer has gone quiet (counted in ``refused_peers``).

Telemetry messages are built by ``mavlink_telemetry``, the mission protocol
is ``mavlink_missions``, the parameter protocol ``mavlink_params`` and AUTO's
execution ``auto_mission`` (advanced from ``tick``); all of them use this
module's encoder.
"""

from __future__ import annotations

import asyncio
import logging
import math
import os
import time
from collections.abc import Callable
from typing import Any, cast

os.environ["MAVLINK20"] = "1"  # for any mavutil user in this process; we use the v20 dialect
from pymavlink.dialects.v20 import ardupilotmega as mav

from linecrew_runtime.mavlink_keys import signing_timestamp
from sim_fleet import autopilot, frames, mavlink_telemetry, streams
from sim_fleet.auto_mission import AutoMission
from sim_fleet.events import Outcome, Result, Severity
from sim_fleet.mavlink_missions import MissionProtocol
from sim_fleet.mavlink_params import ParamProtocol
from sim_fleet.modes import FLAG_CUSTOM_MODE_ENABLED, Mode
from sim_fleet.vehicle import Vehicle
from sim_fleet.world import World

log = logging.getLogger(__name__)

AUTOPILOT_COMPONENT = 1
MAX_LEARNED_PEERS = 8
PEER_LIVE_S = 5.0  # a peer heard this recently is never displaced by a newcomer
POS_IGNORE = 0b111
VEL_IGNORE = 0b111000

MISSION_MESSAGES = frozenset(
    {
        "MISSION_COUNT",
        "MISSION_ITEM_INT",
        "MISSION_ITEM",
        "MISSION_REQUEST_LIST",
        "MISSION_REQUEST_INT",
        "MISSION_REQUEST",
        "MISSION_CLEAR_ALL",
        "MISSION_SET_CURRENT",
        "MISSION_ACK",
    }
)

Addr = tuple[str, int]


class VehicleEndpoint(asyncio.DatagramProtocol):
    def __init__(
        self,
        world: World,
        vehicle: Vehicle,
        *,
        rates: streams.TelemetryRates | None = None,
        static_peers: tuple[Addr, ...] = (),
        signing_key: bytes | None = None,
    ) -> None:
        self.world = world
        self.vehicle = vehicle
        self.schedule = streams.StreamSchedule(rates or streams.TelemetryRates())
        self.static_peers = tuple(static_peers)
        self.peers: dict[Addr, float] = {}  # learned peer -> last heard (monotonic)
        self.bad_datagrams = 0
        self.rejected = 0  # packets not signed with our key (signing on)
        self.refused_peers = 0  # newcomers turned away while the table was full of live peers
        self._logged_bad: set[str] = set()
        self._mav = mav.MAVLink(None, srcSystem=vehicle.sysid, srcComponent=AUTOPILOT_COMPONENT)
        self._signing = signing_key is not None
        if signing_key is not None:
            sign = self._mav.signing
            sign.secret_key, sign.sign_outgoing = signing_key, True
            sign.timestamp = signing_timestamp()
        self._home_sent = 0  # the vehicle's home_version last broadcast
        self.auto = AutoMission(world, vehicle)
        self.missions = MissionProtocol(self._mav, self._send_to, self.auto)
        self.params = ParamProtocol(self._mav, self._send_to, vehicle, self._all_peers)
        # message type -> what a message of that type addressed to this vehicle does
        self._handlers: dict[str, Callable[[Any, Addr], None]] = {
            "COMMAND_LONG": self._command_long,
            "COMMAND_INT": self._command_int,
            "SET_MODE": self._set_mode_message,
            "SET_POSITION_TARGET_GLOBAL_INT": self._global_target,
            "SET_POSITION_TARGET_LOCAL_NED": self._local_target,
            "REQUEST_DATA_STREAM": self._request_data_stream,
            **dict.fromkeys(MISSION_MESSAGES, self.missions.handle),
            "PARAM_REQUEST_LIST": self.params.request_list,
            "PARAM_REQUEST_READ": self.params.request_read,
            "PARAM_SET": self.params.set,
        }
        self._transport: asyncio.DatagramTransport | None = None

    # ---- asyncio protocol ------------------------------------------------
    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        self._transport = cast(asyncio.DatagramTransport, transport)

    @property
    def port(self) -> int:
        assert self._transport is not None
        return int(self._transport.get_extra_info("sockname")[1])

    def error_received(self, exc: Exception) -> None:
        log.debug("%s: socket error %s", self.vehicle.id, exc, extra={"uav_id": self.vehicle.id})

    def datagram_received(self, data: bytes, addr: Addr) -> None:
        if not self.vehicle.link_up():
            return
        try:
            parser = mav.MAVLink(None)
            parser.robust_parsing = True
            if self._signing:
                parser.signing = self._mav.signing
            msgs = parser.parse_buffer(data) or []
        except Exception as exc:  # untrusted bytes: any decoder failure is a bad datagram
            self._bad(addr, repr(exc))
            return
        for msg in msgs:
            if msg.get_type() == "BAD_DATA":
                if self._signing and msg.reason == "Invalid signature":
                    self.rejected += 1
                self._bad(addr, msg.reason)
                continue
            self._learn(addr)
            try:
                self._handle(msg, addr)
            except Exception:  # a bug in one handler must not take the endpoint down
                log.exception("%s: failed handling %s", self.vehicle.id, msg.get_type())

    def _bad(self, addr: Addr, why: str) -> None:
        self.bad_datagrams += 1
        if addr[0] not in self._logged_bad:
            self._logged_bad.add(addr[0])
            log.warning("%s: dropping bad datagram from %s: %s", self.vehicle.id, addr, why)

    def _learn(self, addr: Addr) -> None:
        now = time.monotonic()
        if addr not in self.peers and len(self.peers) >= MAX_LEARNED_PEERS:
            oldest = min(self.peers, key=self.peers.__getitem__)
            if now - self.peers[oldest] < PEER_LIVE_S:
                self.refused_peers += 1  # still answered directly, just not streamed to
                return
            del self.peers[oldest]
        self.peers[addr] = now

    def _all_peers(self) -> list[Addr]:
        """Every peer that gets telemetry: the static ones, then the learned."""
        return [*self.static_peers, *self.peers]

    # ---- incoming --------------------------------------------------------
    def _for_me(self, msg: Any) -> bool:
        return msg.target_system in (0, self.vehicle.sysid) and msg.target_component in (
            0,
            AUTOPILOT_COMPONENT,
        )

    def _handle(self, msg: Any, addr: Addr) -> None:
        """Act on a message addressed to this vehicle; HEARTBEAT and everything
        else only made the sender a peer."""
        handler = self._handlers.get(msg.get_type())
        if handler is not None and self._addressed(msg):
            handler(msg, addr)

    def _addressed(self, msg: Any) -> bool:
        """Whether ``msg`` is for this vehicle (SET_MODE names only a system)."""
        if msg.get_type() == "SET_MODE":
            return bool(msg.target_system == self.vehicle.sysid)
        return self._for_me(msg)

    def _command_long(self, msg: Any, addr: Addr) -> None:
        """COMMAND_LONG: a command with its location in degrees, relative altitude."""
        p = (msg.param1, msg.param2, msg.param3, msg.param4, msg.param5, msg.param6, msg.param7)
        self._command(autopilot.Command(msg.command, p), msg, addr)

    def _command_int(self, msg: Any, addr: Addr) -> None:
        """COMMAND_INT: a command with its location in ``msg.frame`` (lat/lon in 1e-7 degrees)."""
        p = (msg.param1, msg.param2, msg.param3, msg.param4, float(msg.x), float(msg.y), msg.z)
        self._command(autopilot.Command(msg.command, p, msg.frame), msg, addr)

    def _set_mode_message(self, msg: Any, addr: Addr) -> None:
        """SET_MODE, acknowledged like a command."""
        outcome = self._set_mode(msg.base_mode, msg.custom_mode)
        self._ack(mav.MAVLINK_MSG_ID_SET_MODE, outcome, msg, addr)

    def _request_data_stream(self, msg: Any, _addr: Addr) -> None:
        """REQUEST_DATA_STREAM: start or stop an ArduPilot stream group."""
        rate = float(msg.req_message_rate)
        self.schedule.request_data_stream(msg.req_stream_id, rate, bool(msg.start_stop))

    def _command(self, cmd: autopilot.Command, msg: Any, addr: Addr) -> None:
        p = cmd.params
        match cmd.command:
            case mav.MAV_CMD_SET_MESSAGE_INTERVAL if autopilot.as_int(p[0]) == streams.HEARTBEAT:
                outcome = Outcome(Result.DENIED, "Heartbeat rate is fixed")  # the link's pulse
            case mav.MAV_CMD_SET_MESSAGE_INTERVAL:
                ok = self.schedule.set_interval(autopilot.as_int(p[0]), p[1])
                text = None if ok else f"No ap_message for mavlink id ({autopilot.as_int(p[0])})"
                outcome = Outcome(Result.ACCEPTED if ok else Result.DENIED, text)
            case mav.MAV_CMD_GET_MESSAGE_INTERVAL:
                outcome = Outcome(Result.ACCEPTED)
            case mav.MAV_CMD_REQUEST_MESSAGE:
                ok = autopilot.as_int(p[0]) in streams.REQUESTABLE
                outcome = Outcome(Result.ACCEPTED if ok else Result.FAILED)
            case mav.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES:
                outcome = Outcome(Result.ACCEPTED)
            case mav.MAV_CMD_DO_REPOSITION:
                outcome = autopilot.reposition(
                    self.vehicle, self._reposition_target(cmd), autopilot.as_int(p[1])
                )
            case mav.MAV_CMD_DO_SET_MODE:
                outcome = self._set_mode(autopilot.as_int(p[0]), autopilot.as_int(p[1]))
            case mav.MAV_CMD_MISSION_START:
                outcome = self.auto.start_command()
            case mav.MAV_CMD_DO_SET_MISSION_CURRENT:
                outcome = self.missions.do_set_current(p[0], p[1])
            case _:
                outcome = autopilot.handle_command(cmd, self.vehicle, self.world)
        self._ack(cmd.command, outcome, msg, addr)
        if outcome.result is not Result.ACCEPTED:
            return
        match cmd.command:  # replies that follow the ACK, as ArduPilot sends them
            case mav.MAV_CMD_GET_MESSAGE_INTERVAL:
                iv = self.schedule.interval_us(autopilot.as_int(p[0]))
                self._send_to([addr], self._mav.message_interval_encode(autopilot.as_int(p[0]), iv))
            case mav.MAV_CMD_REQUEST_MESSAGE:
                self._send_to([addr], self._encode(autopilot.as_int(p[0])))
            case mav.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES:
                self._send_to([addr], self._encode(streams.AUTOPILOT_VERSION))

    def _set_mode(self, base: int, custom: int) -> Outcome:
        """SET_MODE / DO_SET_MODE; AUTO is entered by the mission (``auto_mission``)."""
        if custom == Mode.AUTO and base >= 0 and base & FLAG_CUSTOM_MODE_ENABLED:
            return self.auto.enter()
        return autopilot.set_mode(self.vehicle, base, custom)

    def _reposition_target(self, cmd: autopilot.Command) -> tuple[float, float, float] | None:
        """DO_REPOSITION's location in ENU; NaN / 0 lat-lon or altitude keep the current one."""
        p, v = cmd.params, self.vehicle
        if cmd.frame is None:  # COMMAND_LONG: degrees, relative altitude
            frame, lat, lon = frames.GLOBAL_RELATIVE_ALT, p[4], p[5]
        else:
            frame, lat, lon = cmd.frame, p[4] / 1e7, p[5] / 1e7
        alt = p[6]
        here = v.position
        if not math.isfinite(lat) or not math.isfinite(lon) or (lat == 0 and lon == 0):
            lat, lon, _ = self.world.geo.to_geodetic(here)
        if not math.isfinite(alt):
            frame, alt = frames.GLOBAL_RELATIVE_ALT, here[2] - v.home[2]
        target = frames.global_to_enu(self.world.geo, frame, lat, lon, alt)
        if target is not None and frame not in (frames.GLOBAL, frames.GLOBAL_INT):
            target = (target[0], target[1], target[2] + v.home[2])  # relative to home
        return target

    def _ack(self, command: int, outcome: Outcome, msg: Any, addr: Addr) -> None:
        if outcome.text:
            severity = Severity.WARNING if outcome.result else Severity.INFO
            for line in outcome.text.split("\n"):
                self._send_to([addr], self._statustext(severity, line))
        ack = self._mav.command_ack_encode(
            command, int(outcome.result), 0, 0, msg.get_srcSystem(), msg.get_srcComponent()
        )
        self._send_to([addr], ack)

    def _global_target(self, msg: Any, _addr: Addr) -> None:
        """SET_POSITION_TARGET_GLOBAL_INT: fly to a position or at a velocity
        (a target that makes no sense holds)."""
        v = self.vehicle
        pos = vel = None
        if not msg.type_mask & POS_IGNORE:
            pos = frames.global_to_enu(
                self.world.geo, msg.coordinate_frame, msg.lat_int / 1e7, msg.lon_int / 1e7, msg.alt
            )
            if pos is None:
                autopilot.hold(v)
                return
            if msg.coordinate_frame not in (frames.GLOBAL, frames.GLOBAL_INT):
                pos = (pos[0], pos[1], pos[2] + v.home[2])  # relative to home
        elif not msg.type_mask & VEL_IGNORE:
            vel = frames.ned_to_enu((msg.vx, msg.vy, msg.vz))
            if not all(math.isfinite(c) and abs(c) < 1000 for c in vel):
                autopilot.hold(v)
                return
        autopilot.position_target(v, pos, vel)

    def _local_target(self, msg: Any, _addr: Addr) -> None:
        """SET_POSITION_TARGET_LOCAL_NED: as :meth:`_global_target`, in a local frame."""
        v = self.vehicle
        frame = msg.coordinate_frame
        pos = vel = None
        if not msg.type_mask & POS_IGNORE:
            pos = frames.local_to_enu(
                frame, (msg.x, msg.y, msg.z), v.origin, v.position, v.heading_deg
            )
            if pos is None:
                autopilot.hold(v)
                return
        elif not msg.type_mask & VEL_IGNORE:
            vel = frames.local_velocity_to_enu(frame, (msg.vx, msg.vy, msg.vz), v.heading_deg)
            if vel is None:
                autopilot.hold(v)
                return
        autopilot.position_target(v, pos, vel)

    # ---- outgoing --------------------------------------------------------
    def tick(self) -> None:
        """Advance the mission; send due telemetry, pending STATUSTEXTs and mission
        progress; called after each world step."""
        self.auto.update()
        texts = self.vehicle.take_texts()
        progress = self.missions.outgoing()
        if not self.vehicle.link_up() or self._transport is None:
            return
        self.missions.tick()
        peers = self._all_peers()
        if not peers:
            return
        for t in texts:
            self._send_to(peers, self._statustext(int(t.severity), t.text))
        for msg in progress:
            self._send_to(peers, msg)
        if self.vehicle.home_set and self.vehicle.home_version != self._home_sent:
            self._home_sent = self.vehicle.home_version  # ArduPilot announces a new home
            self._send_to(peers, self._encode(streams.HOME_POSITION))
        for msg_id in self.schedule.due(self.world.time_s):
            self._send_to(peers, self._encode(msg_id))

    def _send_to(self, addrs: list[Addr], msg: Any) -> None:
        if self._transport is None or self._transport.is_closing() or msg is None:
            return
        if not self.vehicle.link_up():
            return
        buf = msg.pack(self._mav)
        for addr in addrs:
            try:
                self._transport.sendto(buf, addr)
            except OSError as exc:
                log.debug("%s: send to %s failed: %s", self.vehicle.id, addr, exc)

    def _statustext(self, severity: int, text: str) -> Any:
        return self._mav.statustext_encode(severity, text.encode("ascii", "replace")[:50])

    def _encode(self, msg_id: int) -> Any:
        """Build one telemetry message from the vehicle's state (None if unknown)."""
        if msg_id == streams.MISSION_CURRENT:
            return self.missions.mission_current()
        return mavlink_telemetry.encode(self._mav, self.world, self.vehicle, msg_id)
