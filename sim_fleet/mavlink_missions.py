"""The MAVLink mission protocol, as ArduPilot's MissionItemProtocol speaks it.

Upload: MISSION_COUNT -> MISSION_REQUEST_INT for seq 0..n-1 (re-sent after
``RETRY_S`` of silence, given up after ``UPLOAD_TIMEOUT_S`` with
OPERATION_CANCELLED) -> MISSION_ITEM_INT (or legacy MISSION_ITEM) -> MISSION_ACK.
An item out of sequence is answered INVALID_SEQUENCE and the upload goes on;
an item that cannot be flown ends it with its MAV_MISSION_RESULT and leaves
the stored mission as it was (it is replaced only when the upload completes).
Download: MISSION_REQUEST_LIST -> MISSION_COUNT, MISSION_REQUEST_INT (or
MISSION_REQUEST) -> MISSION_ITEM_INT (MISSION_ITEM); item 0 is home, frames
come back as ArduPilot stores them (GLOBAL, GLOBAL_RELATIVE_ALT). Fences and
rally points: none are stored, so lists of them are empty, clearing them
succeeds and uploading them is UNSUPPORTED.

Transfer timers run on wall time: they pace the link, as the client's do.
Messages are built with the endpoint's encoder, so pymavlink stays imported
by ``mavlink_endpoint`` alone.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from sim_fleet import auto_mission
from sim_fleet.auto_mission import AutoMission, MissionItem
from sim_fleet.events import ACCEPTED as CMD_ACCEPTED
from sim_fleet.events import Outcome, Result
from sim_fleet.modes import Mode

Addr = tuple[str, int]
Send = Callable[[list[Addr], Any], None]

# MAV_MISSION_TYPE
MISSION, FENCE, RALLY, ALL = 0, 1, 2, 255
# MAV_MISSION_RESULT
ACCEPTED = 0
ERROR = 1
UNSUPPORTED_FRAME = 2
UNSUPPORTED = 3
NO_SPACE = 4
INVALID_PARAM5_X = 10
INVALID_PARAM6_Y = 11
INVALID_PARAM7 = 12
INVALID_SEQUENCE = 13
DENIED = 14
OPERATION_CANCELLED = 15

MAX_ITEMS = 700  # home included (ArduPilot's limit depends on the board's storage)
RETRY_S = 1.0  # re-request an item not received for this long (ArduPilot: 1 s)
UPLOAD_TIMEOUT_S = 8.0  # give up on a silent upload (ArduPilot upload_timeout_ms)
UINT16_MAX = 65535
FRAME_AS_STORED = {5: 0, 6: 3, 11: 10}  # *_INT frames come back as their float twins


@dataclass(slots=True)
class _Upload:
    addr: Addr
    sysid: int
    compid: int
    count: int
    requested_at: float
    heard_at: float
    items: list[MissionItem] = field(default_factory=list)


class MissionProtocol:
    def __init__(
        self,
        mav: Any,
        send: Send,
        auto: AutoMission,
        *,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._mav = mav
        self._send = send
        self.auto = auto
        self._clock = clock
        self._upload: _Upload | None = None
        self._announced: tuple[int, int] | None = None  # (seq, state) last broadcast

    # ---- incoming --------------------------------------------------------
    def handle(self, msg: Any, addr: Addr) -> None:
        """One MISSION_* message addressed to this vehicle."""
        match msg.get_type():
            case "MISSION_COUNT":
                self._count(msg, addr)
            case "MISSION_ITEM_INT":
                self._item(msg, addr, msg.x, msg.y)
            case "MISSION_ITEM":
                self._item(msg, addr, _e7(msg.x), _e7(msg.y))
            case "MISSION_REQUEST_LIST":
                self._request_list(msg, addr)
            case "MISSION_REQUEST_INT" | "MISSION_REQUEST":
                self._request(msg, addr)
            case "MISSION_CLEAR_ALL":
                self._clear(msg, addr)
            case "MISSION_SET_CURRENT":
                self.auto.set_current(msg.seq)
                self._send([addr], self.mission_current())
            case "MISSION_ACK":
                up = self._upload
                if up is not None and up.addr == addr and msg.type == OPERATION_CANCELLED:
                    self._upload = None  # the client gave up

    def do_set_current(self, seq: float, reset: float) -> Outcome:
        """MAV_CMD_DO_SET_MISSION_CURRENT: param1 the item, param2 1 resets the
        mission so that the next start begins at that item."""
        if not math.isfinite(seq) or not self.auto.set_current(int(seq)):
            return Outcome(Result.FAILED)
        if reset == 1 and self.auto.state != auto_mission.ACTIVE:
            self.auto.state = auto_mission.NOT_STARTED
        return CMD_ACCEPTED

    def _count(self, msg: Any, addr: Addr) -> None:
        kind = msg.mission_type
        if kind != MISSION:
            self._ack(addr, msg, UNSUPPORTED)
            return
        up = self._upload
        now = self._clock()
        if up is not None and up.addr != addr and now - up.heard_at < UPLOAD_TIMEOUT_S:
            self._ack(addr, msg, DENIED)  # someone else is uploading
            return
        if msg.count > MAX_ITEMS:
            self._ack(addr, msg, NO_SPACE)
            return
        if msg.count == 0:
            self._upload = None
            self._ack(addr, msg, ACCEPTED if self.auto.clear() else ERROR)
            return
        self._upload = _Upload(
            addr, msg.get_srcSystem(), msg.get_srcComponent(), msg.count, now, now
        )
        self._request_next()

    def _item(self, msg: Any, addr: Addr, lat_e7: int, lon_e7: int) -> None:
        up = self._upload
        if msg.mission_type != MISSION:
            self._ack(addr, msg, UNSUPPORTED)
            return
        if up is None or up.addr != addr:
            self._ack(addr, msg, ERROR)  # not uploading
            return
        up.heard_at = self._clock()
        if msg.seq != len(up.items):
            self._ack(addr, msg, INVALID_SEQUENCE)  # the upload goes on
            return
        result = check_item(msg.seq, msg.command, msg.frame, lat_e7, lon_e7, msg.z)
        if result != ACCEPTED:
            self._upload = None
            self._ack(addr, msg, result)
            return
        params = (msg.param1, msg.param2, msg.param3, msg.param4)
        up.items.append(
            MissionItem(msg.command, msg.frame, params, lat_e7, lon_e7, msg.z, msg.autocontinue)
        )
        if len(up.items) < up.count:
            self._request_next()
            return
        self._upload = None
        self.auto.load(up.items)
        self._ack(addr, msg, ACCEPTED)

    def _request_list(self, msg: Any, addr: Addr) -> None:
        kind = msg.mission_type
        if kind not in (MISSION, FENCE, RALLY):
            self._ack(addr, msg, UNSUPPORTED)
            return
        count = self.auto.count if kind == MISSION else 0
        src = (msg.get_srcSystem(), msg.get_srcComponent())
        self._send([addr], self._mav.mission_count_encode(*src, count, kind))

    def _request(self, msg: Any, addr: Addr) -> None:
        if msg.mission_type != MISSION or msg.seq >= self.auto.count:
            self._ack(addr, msg, INVALID_SEQUENCE)
            return
        legacy = msg.get_type() == "MISSION_REQUEST"
        self._send([addr], self._encode_item(msg.seq, msg, legacy=legacy))

    def _clear(self, msg: Any, addr: Addr) -> None:
        kind = msg.mission_type
        if kind in (FENCE, RALLY):
            self._ack(addr, msg, ACCEPTED)  # none stored
        elif kind in (MISSION, ALL):
            self._upload = None
            self._ack(addr, msg, ACCEPTED if self.auto.clear() else ERROR)
        else:
            self._ack(addr, msg, UNSUPPORTED)

    # ---- outgoing --------------------------------------------------------
    def tick(self) -> None:
        """Re-request a missing item; abandon an upload that went silent."""
        up = self._upload
        if up is None:
            return
        now = self._clock()
        if now - up.heard_at >= UPLOAD_TIMEOUT_S:
            self._upload = None
            ack = self._mav.mission_ack_encode(up.sysid, up.compid, OPERATION_CANCELLED, MISSION)
            self._send([up.addr], ack)
        elif now - up.requested_at >= RETRY_S:
            self._request_next()

    def outgoing(self) -> list[Any]:
        """MISSION_ITEM_REACHED for items just finished, and MISSION_CURRENT
        when the current item or the mission's state changed."""
        out = [self._mav.mission_item_reached_encode(seq) for seq in self.auto.reached]
        self.auto.reached.clear()
        now = (self.auto.current, self.auto.state)
        if now != self._announced:
            self._announced = now
            out.append(self.mission_current())
        return out

    def mission_current(self) -> Any:
        a = self.auto
        in_auto = 1 if a.vehicle.mode is Mode.AUTO else 2  # MISSION_CURRENT.mission_mode
        return self._mav.mission_current_encode(a.current, a.count - 1, a.state, in_auto)

    def _request_next(self) -> None:
        up = self._upload
        assert up is not None
        up.requested_at = self._clock()
        seq = len(up.items)
        self._send(
            [up.addr], self._mav.mission_request_int_encode(up.sysid, up.compid, seq, MISSION)
        )

    def _ack(self, addr: Addr, msg: Any, result: int) -> None:
        kind = getattr(msg, "mission_type", MISSION)
        ack = self._mav.mission_ack_encode(
            msg.get_srcSystem(), msg.get_srcComponent(), result, kind
        )
        self._send([addr], ack)

    def _encode_item(self, seq: int, msg: Any, *, legacy: bool) -> Any:
        item = self._home_item() if seq == 0 else self.auto.items[seq]
        frame = FRAME_AS_STORED.get(item.frame, item.frame)
        current = 1 if seq == self.auto.current else 0
        src = (msg.get_srcSystem(), msg.get_srcComponent())
        if legacy:
            return self._mav.mission_item_encode(
                *src, seq, frame, item.command, current, item.autocontinue, *item.params,
                item.x / 1e7, item.y / 1e7, item.z, MISSION,
            )  # fmt: skip
        return self._mav.mission_item_int_encode(
            *src, seq, frame, item.command, current, item.autocontinue, *item.params,
            item.x, item.y, item.z, MISSION,
        )  # fmt: skip

    def _home_item(self) -> MissionItem:
        """Item 0: home, AMSL (zeros before the EKF has set it)."""
        v, geo = self.auto.vehicle, self.auto.world.geo
        if not v.home_set:
            return MissionItem(auto_mission.NAV_WAYPOINT, 0)
        lat, lon, alt = geo.to_geodetic(v.home)
        return MissionItem(
            auto_mission.NAV_WAYPOINT, 0, x=round(lat * 1e7), y=round(lon * 1e7), z=alt
        )


def check_item(seq: int, command: int, frame: int, lat_e7: int, lon_e7: int, z: float) -> int:
    """MAV_MISSION_RESULT for one uploaded item (AP_Mission::mavlink_int_to_mission_cmd).
    Item 0 is home's place: anything goes, home replaces it."""
    if seq == 0:
        return ACCEPTED
    if command not in auto_mission.COMMANDS:
        return UNSUPPORTED
    if command in auto_mission.NAV_COMMANDS:
        if frame not in auto_mission.LOCATED_FRAMES:
            return UNSUPPORTED_FRAME
        if abs(lat_e7) > 900_000_000:
            return INVALID_PARAM5_X
        if abs(lon_e7) > 1_800_000_000:
            return INVALID_PARAM6_Y
        if not math.isfinite(z):
            return INVALID_PARAM7
    return ACCEPTED


def _e7(deg: float) -> int:
    """Legacy MISSION_ITEM degrees as 1e7 integers (out-of-range when not finite)."""
    return round(deg * 1e7) if math.isfinite(deg) else 2_000_000_000
