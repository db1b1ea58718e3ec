"""The MAVLink link to one autopilot (ArduCopter GUIDED conventions).

With :mod:`~onboard_agent.autopilot.reports` (what the autopilot's messages
say about the vehicle) the only pymavlink importer of the agent. All state lives on the
asyncio loop: a UDP link (non-blocking socket) is read by the loop itself
(``add_reader``: no thread, no wake-up without a datagram); other links
(TCP with reconnection, serial) by a daemon thread blocking in
``recv_match`` that hands every message over with
``loop.call_soon_threadsafe``. Commands
are asyncio tasks: each sends a COMMAND_LONG and waits for its COMMAND_ACK,
resending up to ``command_retries`` times; a refusal becomes
:class:`CommandDenied` carrying the autopilot's last STATUSTEXT as the reason.
Position targets (SET_POSITION_TARGET_GLOBAL_INT) have no ACK in MAVLink, so
callers repeat them. A silent autopilot (no HEARTBEAT for
``heartbeat_timeout_s``) shows as ``state.link_ok == False``.

One altitude frame (:mod:`linecrew.site_frame`): positions are site-local,
z the height above the site origin, read from the AMSL altitude
(GLOBAL_POSITION_INT.alt, never relative_alt: ArduCopter re-homes at every
arming, so "relative" means above wherever it last armed); targets go out
AMSL (MAV_FRAME_GLOBAL_INT). Only NAV_TAKEOFF takes an altitude above home.

ArduCopter streams only what it is asked for (``SRx_`` rates may be 0): on
finding the autopilot, and again after a heartbeat loss or when positions
stop while heartbeats go on, the link asks for its telemetry by stream group
(REQUEST_DATA_STREAM) and per message (SET_MESSAGE_INTERVAL), including the
readiness reports (SYS_STATUS, GPS_RAW_INT, EKF_STATUS_REPORT, HOME_POSITION).

Only the configured autopilot is heard: a ``udpout:`` socket is connected to
its address (the kernel drops datagrams from anyone else), messages from any
other system or component id are dropped, and with a signing key every
packet is signed and only packets signed with that key are accepted (MAVLink
2 signing; replays fail on the signature's timestamp). Everything dropped is
counted in ``dropped``.
"""

from __future__ import annotations

import asyncio
import logging
import os
import socket
import threading
import time
from collections.abc import Callable
from typing import Any

os.environ["MAVLINK20"] = "1"  # before importing mavutil: speak MAVLink 2
from pymavlink import mavutil

from linecrew_runtime.mavlink_keys import signing_timestamp
from onboard_agent.autopilot.errors import CommandDenied, CommandTimeout, LinkLost
from onboard_agent.autopilot.protocol import VehicleState
from onboard_agent.autopilot.reports import MODE_NUMBERS, VehicleReports
from onboard_agent.config import AgentConfig
from proto.geo import Point, SiteFrame

log = logging.getLogger(__name__)
mav = mavutil.mavlink

POSITION_ONLY = 0b110111111000  # SET_POSITION_TARGET type_mask: use x, y, z only
STREAMS_HZ = {
    "GLOBAL_POSITION_INT": 5.0,
    "BATTERY_STATUS": 1.0,
    "EXTENDED_SYS_STATE": 1.0,
    "SYS_STATUS": 1.0,
    "GPS_RAW_INT": 1.0,
    "EKF_STATUS_REPORT": 1.0,
    "HOME_POSITION": 0.5,
}
DATA_STREAMS_HZ = {  # the ArduPilot stream groups holding the above (REQUEST_DATA_STREAM)
    mav.MAV_DATA_STREAM_EXTENDED_STATUS: 1,
    mav.MAV_DATA_STREAM_POSITION: 5,
    mav.MAV_DATA_STREAM_EXTRA3: 1,
}
STREAMS_STALE_S = 3.0  # no position this long with heartbeats arriving: ask again


class MavlinkLink:
    """One autopilot over any pymavlink connection string (``udpout:``,
    ``udpin:``, ``tcp:``, serial). Use :meth:`start` then ``await run()``."""

    def __init__(
        self,
        url: str,
        frame: SiteFrame,
        config: AgentConfig,
        *,
        clock: Callable[[], float] = time.monotonic,
        source_system: int = 255,
        source_component: int = 190,
        signing_key: bytes | None = None,
    ) -> None:
        self.url = url
        self.frame = frame
        self.config = config
        self.clock = clock
        self._source = (source_system, source_component)
        self._signing_key = signing_key
        self.dropped = 0  # messages from another sender, or not signed with our key
        self.reports = VehicleReports(frame, clock)
        self._target: tuple[int, int] | None = None
        self._found: asyncio.Event | None = None
        self._acks: dict[int, asyncio.Future[Any]] = {}
        self._conn: Any = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._reading_fd: int | None = None  # the UDP socket the loop reads
        self._closing = threading.Event()
        self._tasks: set[asyncio.Task[Any]] = set()
        self._streams_asked = -1e9
        self._streams_task: asyncio.Task[None] | None = None

    # -- lifecycle ---------------------------------------------------------------

    def start(self) -> None:
        """Open the connection and start receiving (call on the loop)."""
        self._loop = asyncio.get_running_loop()
        self._found = asyncio.Event()
        system, component = self._source
        self._conn = mavutil.mavlink_connection(
            self.url, source_system=system, source_component=component, autoreconnect=True
        )
        if self._signing_key is not None:
            self._conn.setup_signing(
                self._signing_key, initial_timestamp=signing_timestamp(), link_id=0
            )
        udp = isinstance(self._conn, mavutil.mavudp)
        if udp and not self._conn.udp_server:
            host, port = self._conn.destination_addr  # udpout: hear only that address
            self._conn.port.connect((socket.gethostbyname(host), port))
        if udp:
            self._loop.add_reader(self._conn.port.fileno(), self._on_readable)
            self._reading_fd = self._conn.port.fileno()
        else:
            self._thread = threading.Thread(target=self._receive, name="mavlink-rx", daemon=True)
            self._thread.start()
        self._send_heartbeat()  # a udpout peer learns our address from what we send

    async def run(self) -> None:
        """Send our heartbeat at 1 Hz and watch the autopilot's, until closed."""
        while not self._closing.is_set():
            self._send_heartbeat()
            reports = self.reports
            silent = self.clock() - reports.last_heartbeat > self.config.heartbeat_timeout_s
            if silent and reports.state.link_ok:
                log.warning("autopilot heartbeat lost", extra={"url": self.url})
                reports.update(link_ok=False)
            now = self.clock()
            starved = now - reports.last_position > STREAMS_STALE_S
            if reports.state.link_ok and starved and now - self._streams_asked > STREAMS_STALE_S:
                self._request_streams()  # a rebooted autopilot forgets what it was asked
            await asyncio.sleep(1.0)

    def close(self) -> None:
        """Stop the receive thread and close the connection; idempotent."""
        self._closing.set()
        for task in list(self._tasks):
            task.cancel()
        if self._reading_fd is not None and self._loop is not None:
            self._loop.remove_reader(self._reading_fd)
            self._reading_fd = None
        if self._thread is not None:
            self._thread.join(2.0)
        if self._conn is not None:
            self._conn.close()
            self._conn = None

    @property
    def state(self) -> VehicleState:
        return self.reports.state

    # -- commands (call on the loop thread) ----------------------------------------

    def set_mode(self, mode: str) -> asyncio.Task[None]:
        number = MODE_NUMBERS[mode]
        return self._spawn(self._command(f"mode {mode}", mav.MAV_CMD_DO_SET_MODE, 1, number))

    def arm(self) -> asyncio.Task[None]:
        return self._spawn(self._command("arm", mav.MAV_CMD_COMPONENT_ARM_DISARM, 1))

    def disarm(self) -> asyncio.Task[None]:
        return self._spawn(self._command("disarm", mav.MAV_CMD_COMPONENT_ARM_DISARM, 0))

    def takeoff(self, z_m: float) -> asyncio.Task[None]:
        """Climb to the site height ``z_m``. NAV_TAKEOFF is above home, which
        ArduCopter sets where it arms (the new HOME_POSITION may still be on
        its way): above where the vehicle stands."""
        above = z_m - self.reports.state.position.z_m
        return self._spawn(
            self._command("takeoff", mav.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, above)
        )

    def land(self) -> asyncio.Task[None]:
        return self._spawn(self._command("land", mav.MAV_CMD_NAV_LAND))

    def grab(self) -> asyncio.Task[None]:
        self.reports.update(gripper_text="")
        return self._spawn(self._command("gripper grab", mav.MAV_CMD_DO_GRIPPER, 1, 1))

    def release(self) -> asyncio.Task[None]:
        self.reports.update(gripper_text="")
        return self._spawn(self._command("gripper release", mav.MAV_CMD_DO_GRIPPER, 1, 0))

    def change_speed(self, speed_mps: float) -> asyncio.Task[None]:
        return self._spawn(self._command("speed", mav.MAV_CMD_DO_CHANGE_SPEED, 1, speed_mps, -1))

    def goto(self, target: Point) -> asyncio.Task[None]:
        """Send a position target (AMSL altitude from the site z); no ACK exists."""
        return self._spawn(self._goto(target))

    async def _goto(self, target: Point) -> None:
        system, component = await self._wait_target()
        geo = self.frame.to_geodetic(target)
        self._conn.mav.set_position_target_global_int_send(
            0, system, component, mav.MAV_FRAME_GLOBAL_INT, POSITION_ONLY,
            round(geo.lat_deg * 1e7), round(geo.lon_deg * 1e7), geo.alt_m,
            0, 0, 0, 0, 0, 0, 0, 0,  # velocity, acceleration, yaw, yaw rate: ignored
        )  # fmt: skip

    async def _command(self, name: str, command: int, *params: float) -> None:
        system, component = await self._wait_target()
        p = [float(x) for x in params] + [0.0] * (7 - len(params))
        assert self._loop is not None
        sent_at = self.clock()
        for attempt in range(self.config.command_retries + 1):
            future: asyncio.Future[Any] = self._loop.create_future()
            self._acks[command] = future
            self._conn.mav.command_long_send(system, component, command, attempt, *p)
            try:
                ack = await asyncio.wait_for(future, self.config.command_ack_timeout_s)
            except TimeoutError:
                log.info("%s: no ACK (attempt %d)", name, attempt + 1)
                continue
            finally:
                if self._acks.get(command) is future:
                    del self._acks[command]
            if ack.result == mav.MAV_RESULT_ACCEPTED:
                return
            result = mav.enums["MAV_RESULT"][ack.result].name.removeprefix("MAV_RESULT_")
            raise CommandDenied(name, result, self.reports.texts_since(sent_at))
        tries = self.config.command_retries + 1
        raise CommandTimeout(f"{name}: no COMMAND_ACK after {tries} tries")

    async def _wait_target(self) -> tuple[int, int]:
        assert self._found is not None
        if self._target is None:
            try:
                await asyncio.wait_for(self._found.wait(), self.config.heartbeat_timeout_s)
            except TimeoutError:
                raise LinkLost(f"no autopilot heartbeat on {self.url}") from None
        assert self._target is not None
        return self._target

    def _spawn(self, coro: Any) -> asyncio.Task[Any]:
        task = asyncio.get_running_loop().create_task(coro)
        self._tasks.add(task)
        task.add_done_callback(self._reap)
        return task

    def _reap(self, task: asyncio.Task[Any]) -> None:
        """Forget a finished command; its error is retrieved here so that one
        nobody awaits (a position target, a cancelled behaviour's command)
        never becomes "Task exception was never retrieved"."""
        self._tasks.discard(task)
        if not task.cancelled() and task.exception() is not None:
            log.debug("command ended: %s", task.exception())

    # -- receiving -------------------------------------------------------------------

    def _receive(self) -> None:
        """The receive thread of a link the loop cannot read itself."""
        while not self._closing.is_set():
            try:
                msg = self._conn.recv_match(blocking=True, timeout=0.2)
            except Exception as exc:  # a bad packet or a closed socket must not kill the thread
                if self._closing.is_set():
                    return
                log.debug("mavlink receive failed: %s", exc)
                continue
            if msg is None:
                continue
            try:
                assert self._loop is not None
                self._loop.call_soon_threadsafe(self._dispatch, msg)
            except RuntimeError:  # the loop is closed: we are shutting down
                return

    def _on_readable(self) -> None:
        """Parse every message waiting on the UDP socket (on the loop)."""
        while True:
            try:
                msg = self._conn.recv_msg()
            except Exception as exc:  # a bad packet or a socket error: wait for the next
                log.debug("mavlink receive failed: %s", exc)
                return
            if msg is None:
                return
            self._dispatch(msg)

    def _dispatch(self, msg: Any) -> None:
        if msg.get_type() == "BAD_DATA":
            if msg.reason == "Invalid signature":
                self._drop(f"unsigned or wrongly signed {msg.reason!r}")
            return
        self._on_message(msg)

    def _drop(self, what: str) -> None:
        """Count a message we do not act on; log the first and every 100th."""
        self.dropped += 1
        if self.dropped % 100 == 1:
            log.warning("dropped MAVLink from a stranger (%d so far): %s", self.dropped, what)

    def _from_autopilot(self, msg: Any) -> bool:
        """Whether ``msg`` comes from our autopilot; counts the rest."""
        sender = (msg.get_srcSystem(), msg.get_srcComponent())
        if sender == self._target:
            return True
        if msg.get_type() == "HEARTBEAT" and msg.type == mav.MAV_TYPE_GCS:
            return False  # another ground station on a shared link: not ours, not hostile
        self._drop(f"{msg.get_type()} from system {sender[0]} component {sender[1]}")
        return False

    def _on_message(self, msg: Any) -> None:
        kind = msg.get_type()
        if kind == "HEARTBEAT" and self._target is None:
            self._find(msg)
        if self._target is None or not self._from_autopilot(msg):
            return
        if kind == "HEARTBEAT":
            returned = self.reports.heartbeat(msg)
            if returned and (self._streams_task is None or self._streams_task.done()):
                self._request_streams()  # back after a loss: it may have rebooted
        elif kind == "COMMAND_ACK":
            future = self._acks.get(msg.command)
            final = msg.result != mav.MAV_RESULT_IN_PROGRESS
            if future is not None and not future.done() and final:
                future.set_result(msg)
        else:
            self.reports.fold(msg)

    def _find(self, msg: Any) -> None:
        """Take the sender of ``msg`` as our autopilot if it is one we may fly."""
        if msg.type == mav.MAV_TYPE_GCS or msg.autopilot == mav.MAV_AUTOPILOT_INVALID:
            return
        system, component = msg.get_srcSystem(), msg.get_srcComponent()
        wanted = self.config.autopilot_system
        if (wanted and system != wanted) or component != self.config.autopilot_component:
            return
        self._target = (system, component)
        assert self._found is not None
        self._found.set()
        log.info("autopilot found: system %d on %s", system, self.url)
        self._request_streams()

    def _request_streams(self) -> None:
        if self._streams_task is not None and not self._streams_task.done():
            return
        self._streams_asked = self.clock()
        self._streams_task = self._spawn(self._streams())

    async def _streams(self) -> None:
        """Ask for the telemetry we use: by stream group (older autopilots),
        then per message (one at a time: the ACKs carry no message id); a
        refusal only means the autopilot streams by default."""
        system, component = await self._wait_target()
        for stream, group_hz in DATA_STREAMS_HZ.items():
            self._conn.mav.request_data_stream_send(system, component, stream, group_hz, 1)
        for name, hz in STREAMS_HZ.items():
            msg_id = getattr(mav, f"MAVLINK_MSG_ID_{name}")
            interval_us = 1e6 / hz
            try:
                await self._command(
                    f"stream {name}", mav.MAV_CMD_SET_MESSAGE_INTERVAL, msg_id, interval_us
                )
            except (CommandDenied, CommandTimeout) as exc:
                log.debug("stream request refused: %s", exc)
        try:  # home now, if set (ArduPilot also announces it when it changes)
            await self._command(
                "request home",
                mav.MAV_CMD_REQUEST_MESSAGE,
                mav.MAVLINK_MSG_ID_HOME_POSITION,
            )
        except (CommandDenied, CommandTimeout) as exc:
            log.debug("home request refused: %s", exc)

    def _send_heartbeat(self) -> None:
        if self._conn is not None:
            self._conn.mav.heartbeat_send(mav.MAV_TYPE_GCS, mav.MAV_AUTOPILOT_INVALID, 0, 0, 0)
