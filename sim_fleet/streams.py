"""Which telemetry messages are due when: SET_MESSAGE_INTERVAL and
REQUEST_DATA_STREAM bookkeeping.

Like an ArduCopter whose ``SRx_`` stream rates are 0, a vehicle sends only its
HEARTBEAT until a client asks for more: per message (SET_MESSAGE_INTERVAL, 0 =
the default rate below) or per ArduPilot stream group (REQUEST_DATA_STREAM).
``TelemetryRates(stream_by_default=True)`` streams the default rates from the
start instead (for tools that never ask, like the bench's sink).

Intervals are in *simulated* seconds, as ArduPilot SITL runs its scheduler on
simulated time: with a speed-up K a client sees K times as many messages per
wall second. Each message goes out at most once per runner tick, which caps
the wall rate at the tick rate.
"""

from __future__ import annotations

from dataclasses import dataclass

# MAVLink message ids the simulator can stream
HEARTBEAT = 0
SYS_STATUS = 1
GPS_RAW_INT = 24
ATTITUDE = 30
GLOBAL_POSITION_INT = 33
MISSION_CURRENT = 42
VFR_HUD = 74
AUTOPILOT_VERSION = 148
BATTERY_STATUS = 147
EKF_STATUS_REPORT = 193
HOME_POSITION = 242
EXTENDED_SYS_STATE = 245

STREAMABLE = frozenset(
    {
        HEARTBEAT,
        SYS_STATUS,
        ATTITUDE,
        GLOBAL_POSITION_INT,
        VFR_HUD,
        BATTERY_STATUS,
        EXTENDED_SYS_STATE,
        HOME_POSITION,
        GPS_RAW_INT,
        EKF_STATUS_REPORT,
        MISSION_CURRENT,
    }
)
REQUESTABLE = STREAMABLE | {AUTOPILOT_VERSION}

# MAV_DATA_STREAM groups as ArduCopter fills them (GCS_MAVLink_Copter.cpp)
STREAM_ALL = 0
DATA_STREAMS = {
    2: (SYS_STATUS, GPS_RAW_INT, EXTENDED_SYS_STATE, MISSION_CURRENT),  # EXTENDED_STATUS
    6: (GLOBAL_POSITION_INT,),  # POSITION
    10: (ATTITUDE,),  # EXTRA1
    11: (VFR_HUD,),  # EXTRA2
    12: (BATTERY_STATUS, EKF_STATUS_REPORT),  # EXTRA3
}


@dataclass(frozen=True, kw_only=True)
class TelemetryRates:
    """Default stream rates in Hz (simulated time); 0 disables a stream."""

    heartbeat_hz: float = 1.0
    position_hz: float = 5.0  # GLOBAL_POSITION_INT
    attitude_hz: float = 2.0  # ATTITUDE and VFR_HUD
    status_hz: float = 1.0  # SYS_STATUS, BATTERY_STATUS, EXT_SYS_STATE, GPS, EKF, MISSION_CURRENT
    stream_by_default: bool = False  # stream the rates above before anyone asks

    def intervals_s(self) -> dict[int, float]:
        def iv(hz: float) -> float:
            return 1.0 / hz if hz > 0 else 0.0

        return {
            HEARTBEAT: iv(self.heartbeat_hz),
            GLOBAL_POSITION_INT: iv(self.position_hz),
            ATTITUDE: iv(self.attitude_hz),
            VFR_HUD: iv(self.attitude_hz),
            SYS_STATUS: iv(self.status_hz),
            BATTERY_STATUS: iv(self.status_hz),
            EXTENDED_SYS_STATE: iv(self.status_hz),
            GPS_RAW_INT: iv(self.status_hz),
            EKF_STATUS_REPORT: iv(self.status_hz),
            MISSION_CURRENT: iv(self.status_hz),
        }


class StreamSchedule:
    def __init__(self, rates: TelemetryRates) -> None:
        self._defaults = {k: v for k, v in rates.intervals_s().items() if v > 0}
        if rates.stream_by_default:
            self.intervals = dict(self._defaults)  # message id -> interval (s)
        else:
            self.intervals = {k: v for k, v in self._defaults.items() if k == HEARTBEAT}
        self._next_due: dict[int, float] = {}

    def set_interval(self, msg_id: int, interval_us: float) -> bool:
        """SET_MESSAGE_INTERVAL semantics: -1 disable, 0 default, else microseconds."""
        if msg_id not in STREAMABLE:
            return False
        if interval_us < 0:
            self.intervals.pop(msg_id, None)
        elif interval_us == 0:
            if msg_id in self._defaults:
                self.intervals[msg_id] = self._defaults[msg_id]
            else:
                self.intervals.pop(msg_id, None)
        else:
            self.intervals[msg_id] = interval_us / 1e6
        self._next_due.pop(msg_id, None)
        return True

    def request_data_stream(self, stream_id: int, rate_hz: float, start: bool) -> bool:
        """REQUEST_DATA_STREAM: a group of messages at ``rate_hz`` (stop: off)."""
        if stream_id == STREAM_ALL:
            ids = [m for group in DATA_STREAMS.values() for m in group]
        elif stream_id in DATA_STREAMS:
            ids = list(DATA_STREAMS[stream_id])
        else:
            return False
        for msg_id in ids:
            if start and rate_hz > 0:
                self.intervals[msg_id] = 1.0 / rate_hz
            else:
                self.intervals.pop(msg_id, None)
            self._next_due.pop(msg_id, None)
        return True

    def interval_us(self, msg_id: int) -> int:
        """MESSAGE_INTERVAL reply value: -1 when the stream is off."""
        iv = self.intervals.get(msg_id)
        return -1 if iv is None else round(iv * 1e6)

    def due(self, now_s: float) -> list[int]:
        """Message ids to send now; each is rescheduled one interval later."""
        out = []
        for msg_id, iv in self.intervals.items():
            nxt = self._next_due.get(msg_id, now_s)
            if now_s >= nxt:
                out.append(msg_id)
                # catch up without bursts when ticks are coarser than the interval
                self._next_due[msg_id] = max(nxt + iv, now_s + iv * 0.5)
        return out
