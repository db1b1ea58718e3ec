"""What an autopilot's messages say about its vehicle: each MAVLink message
from it folds into one :class:`VehicleState` (pure bookkeeping: no I/O; the
link decides which messages are the autopilot's and hands them over).

Positions are site-local (:class:`proto.geo.SiteFrame`), read from the AMSL
altitude. A GLOBAL_POSITION_INT of lat = lon = 0 (no EKF origin yet) or
without a 3-D fix leaves the position unknown; the battery is unknown until
reported (BATTERY_STATUS, else SYS_STATUS). A crash (ArduCopter's
"Crash:" text, an emergency heartbeat, a disarm in the air) is kept.
"""

from __future__ import annotations

import collections
import dataclasses
import logging
from collections.abc import Callable
from typing import Any

from pymavlink.dialects.v20 import ardupilotmega as mav

from onboard_agent.autopilot.protocol import VehicleState
from proto.geo import GeoPoint, SiteFrame, Vector
from proto.telemetry import FlightState

log = logging.getLogger(__name__)

# ArduCopter custom_mode numbers
COPTER_MODES = {
    0: "STABILIZE",
    2: "ALT_HOLD",
    3: "AUTO",
    4: "GUIDED",
    5: "LOITER",
    6: "RTL",
    9: "LAND",
    17: "BRAKE",
}
MODE_NUMBERS = {name: number for number, name in COPTER_MODES.items()}
LANDED_STATES = {
    mav.MAV_LANDED_STATE_ON_GROUND: FlightState.LANDED,
    mav.MAV_LANDED_STATE_IN_AIR: FlightState.FLYING,
    mav.MAV_LANDED_STATE_TAKEOFF: FlightState.TAKING_OFF,
    mav.MAV_LANDED_STATE_LANDING: FlightState.LANDING,
}
PREARM_BIT = mav.MAV_SYS_STATUS_PREARM_CHECK
ARM_TEXTS = ("PreArm:", "Arm:")  # ArduCopter's reasons for refusing to arm
CRASH_TEXT = "Crash:"  # ArduCopter's crash check ("Crash: Disarming")
GRIPPER_TEXT = "Gripper:"  # what a gripper says it did (our simulator; a load sensor's driver)
TEXT_FRESH_S = 2.0  # a STATUSTEXT this recent explains a refused command


class VehicleReports:
    """The vehicle as its autopilot last described it."""

    def __init__(self, frame: SiteFrame, clock: Callable[[], float]) -> None:
        self.frame = frame
        self.clock = clock
        self.state = VehicleState()
        self.last_heartbeat = -1e9
        self.last_position = -1e9  # when the last GLOBAL_POSITION_INT came
        self._battery_status_seen = False
        self._last_text = ("", -1e9)
        self._texts: collections.deque[tuple[str, float]] = collections.deque(maxlen=8)

    def update(self, **changes: Any) -> None:
        """Change fields of the state (the link's own knowledge: link lost, a
        gripper command sent)."""
        self.state = dataclasses.replace(self.state, **changes)

    def heartbeat(self, msg: Any) -> bool:
        """Fold a HEARTBEAT; True if it ends a loss of the link."""
        self.last_heartbeat = self.clock()
        armed = bool(msg.base_mode & mav.MAV_MODE_FLAG_SAFETY_ARMED)
        mode = COPTER_MODES.get(msg.custom_mode, str(msg.custom_mode))
        returned = not self.state.link_ok
        if returned:
            log.info("autopilot heartbeat received")
        s = self.state
        in_air = s.flight_state in (FlightState.FLYING, FlightState.TAKING_OFF)
        fell = s.armed and not armed and in_air and mode not in ("LAND", "RTL")
        if msg.system_status == mav.MAV_STATE_EMERGENCY or fell:
            self.crashed("emergency state" if armed else "disarmed in the air")
        self.update(armed=armed, mode=mode, link_ok=True)
        return returned

    def fold(self, msg: Any) -> None:
        """Fold any other message of the autopilot (those we do not use are ignored)."""
        s = self.state
        match msg.get_type():
            case "GLOBAL_POSITION_INT":
                self._position(msg)
            case "EXTENDED_SYS_STATE" if s.flight_state is not FlightState.CRASHED:
                self.update(flight_state=LANDED_STATES.get(msg.landed_state, FlightState.UNKNOWN))
            case "BATTERY_STATUS" if msg.battery_remaining >= 0:
                self._battery_status_seen = True
                charging = msg.charge_state == mav.MAV_BATTERY_CHARGE_STATE_CHARGING
                fraction = msg.battery_remaining / 100
                self.update(battery_fraction=fraction, charging=charging, battery_known=True)
            case "SYS_STATUS":
                self._sys_status(msg)
            case "GPS_RAW_INT":
                self.update(gps_fix_type=msg.fix_type)
                if msg.fix_type < 3 and s.known:
                    self.update(known=False)
            case "EKF_STATUS_REPORT":
                self.update(ekf_flags=msg.flags)
            case "HOME_POSITION":
                lat, lon = msg.latitude / 1e7, msg.longitude / 1e7
                home = GeoPoint(lat_deg=lat, lon_deg=lon, alt_m=msg.altitude / 1000)
                if home != s.home:
                    log.info("autopilot home %s", home)
                self.update(home=home)
            case "STATUSTEXT":
                self._text(msg.text)

    def crashed(self, why: str) -> None:
        """The vehicle fell or hit the ground: it reports CRASHED from now on."""
        if self.state.flight_state is not FlightState.CRASHED:
            log.warning("vehicle crashed: %s", why)
            self.update(flight_state=FlightState.CRASHED)

    def texts_since(self, since: float) -> str:
        """Every STATUSTEXT since ``since`` (ArduCopter sends one per failed
        pre-arm check before the ACK), else the last one if fresh."""
        texts = [text for text, stamp in self._texts if stamp >= since]
        if texts:
            return "; ".join(dict.fromkeys(texts))
        text, stamp = self._last_text
        return text if self.clock() - stamp <= TEXT_FRESH_S else ""

    def _position(self, msg: Any) -> None:
        self.last_position = self.clock()
        s = self.state
        no_fix = 0 <= s.gps_fix_type < 3
        if (msg.lat == 0 and msg.lon == 0) or no_fix:  # no position yet: not 0 N 0 E
            self.update(known=False)
            return
        geo = GeoPoint(lat_deg=msg.lat / 1e7, lon_deg=msg.lon / 1e7, alt_m=msg.alt / 1000)
        velocity = Vector(east_mps=msg.vy / 100, north_mps=msg.vx / 100, up_mps=-msg.vz / 100)
        heading = msg.hdg / 100 if msg.hdg != 65535 else s.heading_deg
        self.update(
            position=self.frame.to_local(geo),
            geo=geo,
            velocity=velocity,
            heading_deg=heading,
            known=True,
        )

    def _sys_status(self, msg: Any) -> None:
        changes: dict[str, Any] = {}
        if msg.onboard_control_sensors_present & PREARM_BIT:
            ok = bool(msg.onboard_control_sensors_health & PREARM_BIT)
            changes["prearm_ok"] = ok
            if ok:
                changes["arm_text"] = ""
        if msg.battery_remaining >= 0 and not self._battery_status_seen:
            changes["battery_fraction"] = msg.battery_remaining / 100
            changes["battery_known"] = True
        if changes:
            self.update(**changes)

    def _text(self, text: str) -> None:
        self._last_text = (text, self.clock())
        self._texts.append(self._last_text)
        if text.startswith(ARM_TEXTS):
            self.update(arm_text=text)
        if text.startswith(GRIPPER_TEXT):
            self.update(gripper_text=text)
        elif text.startswith(CRASH_TEXT):
            self.crashed(text)
        log.info("autopilot: %s", text)
