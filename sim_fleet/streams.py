"""Which telemetry messages are due when: SET_MESSAGE_INTERVAL bookkeeping.

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
ATTITUDE = 30
GLOBAL_POSITION_INT = 33
VFR_HUD = 74
AUTOPILOT_VERSION = 148
BATTERY_STATUS = 147
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
    }
)
REQUESTABLE = STREAMABLE | {AUTOPILOT_VERSION}


@dataclass(frozen=True, kw_only=True)
class TelemetryRates:
    """Default stream rates in Hz (simulated time); 0 disables a stream."""

    heartbeat_hz: float = 1.0
    position_hz: float = 5.0  # GLOBAL_POSITION_INT
    attitude_hz: float = 2.0  # ATTITUDE and VFR_HUD
    status_hz: float = 1.0  # SYS_STATUS, BATTERY_STATUS, EXTENDED_SYS_STATE

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
        }


class StreamSchedule:
    def __init__(self, rates: TelemetryRates) -> None:
        self._defaults = {k: v for k, v in rates.intervals_s().items() if v > 0}
        self.intervals = dict(self._defaults)  # message id -> interval (s)
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
