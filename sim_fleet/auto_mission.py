"""AUTO mode: ArduCopter's mission execution over the vehicle's guided flight.

The uploaded items (``mavlink_missions`` fills ``AutoMission.items``; item 0
is home, as in ArduPilot) are flown with the primitives GUIDED uses
(``start_takeoff``, ``fly_to``, the LAND descent), so there is one flight
model. Rules follow ArduCopter 4.x (mode_auto.cpp, AP_Mission.cpp):

- entering AUTO armed needs a mission, and on the ground one whose first
  navigation item is a takeoff (``Auto: Missing Takeoff Cmd``); AUTO is not
  armable (AUTO_OPTIONS 0). There are no sticks here, so the throttle-up
  ArduCopter waits for before an AUTO takeoff is taken as given;
- ``MAV_CMD_MISSION_START`` needs the vehicle armed and switches to AUTO;
- leaving AUTO pauses the mission, coming back resumes the current item
  (MIS_RESTART 0); a finished mission starts over;
- DO items run as the sequence reaches them; every finished item gets a
  MISSION_ITEM_REACHED, every started one a ``Mission: N Name`` text;
- at the end the vehicle holds at the last waypoint in AUTO (loiter), or
  disarms if it has landed.

``update()`` runs once per runner tick (after the world step).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from enum import IntEnum

from sim_fleet import autopilot, frames, physics
from sim_fleet.events import ACCEPTED, Outcome, Result, Severity
from sim_fleet.modes import FlightState, Mode
from sim_fleet.physics import Vec3
from sim_fleet.vehicle import AIRBORNE, Vehicle
from sim_fleet.world import World


class Cmd(IntEnum):
    """The MAV_CMD mission items AUTO flies."""

    NAV_WAYPOINT = 16
    NAV_LOITER_TIME = 19
    NAV_RETURN_TO_LAUNCH = 20
    NAV_LAND = 21
    NAV_TAKEOFF = 22
    DO_CHANGE_SPEED = 178
    DO_GRIPPER = 211


NAV_WAYPOINT = Cmd.NAV_WAYPOINT
NAV_COMMANDS = frozenset(c for c in Cmd if c.name.startswith("NAV_"))
COMMANDS = frozenset(Cmd)
# AP_Mission::Mission_Command::type()
NAMES: dict[int, str] = {
    Cmd.NAV_WAYPOINT: "WP",
    Cmd.NAV_LOITER_TIME: "LoitTime",
    Cmd.NAV_RETURN_TO_LAUNCH: "RTL",
    Cmd.NAV_LAND: "Land",
    Cmd.NAV_TAKEOFF: "Takeoff",
    Cmd.DO_CHANGE_SPEED: "ChangeSpeed",
    Cmd.DO_GRIPPER: "Gripper",
}
# Frames a located item may use: MISSION and GLOBAL(_INT) are AMSL (as ArduPilot
# reads them), the relative and terrain ones above home (no terrain database).
AMSL_FRAMES = frozenset({frames.GLOBAL, 2, frames.GLOBAL_INT})
RELATIVE_FRAMES = frozenset(
    {
        frames.GLOBAL_RELATIVE_ALT,
        frames.GLOBAL_RELATIVE_ALT_INT,
        frames.GLOBAL_TERRAIN_ALT,
        frames.GLOBAL_TERRAIN_ALT_INT,
    }
)
LOCATED_FRAMES = AMSL_FRAMES | RELATIVE_FRAMES
WP_RADIUS_M = 2.0  # WPNAV_RADIUS default (200 cm): a waypoint is reached this close
ARRIVED_M = 0.05  # before a descent starts (LAND at a location, RTL)
# MISSION_STATE
NO_MISSION, NOT_STARTED, ACTIVE, PAUSED, COMPLETE = 1, 2, 3, 4, 5

MODE_FAILED = "Mode change to AUTO failed: init failed"


@dataclass(frozen=True, slots=True)
class MissionItem:
    """One stored mission item; its index in ``AutoMission.items`` is its seq."""

    command: int
    frame: int = frames.GLOBAL_RELATIVE_ALT_INT
    params: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    x: int = 0  # latitude, degrees * 1e7
    y: int = 0  # longitude, degrees * 1e7
    z: float = 0.0  # altitude in ``frame`` (m)
    autocontinue: int = 1


class AutoMission:
    def __init__(self, world: World, vehicle: Vehicle) -> None:
        self.world = world
        self.vehicle = vehicle
        self.items: list[MissionItem] = [MissionItem(NAV_WAYPOINT, frames.GLOBAL)]  # home
        self.current = 0  # the nav item being flown (MISSION_CURRENT.seq); 0: none yet
        self.state = NO_MISSION
        self.reached: list[int] = []  # MISSION_ITEM_REACHED seqs not yet sent
        # (seq, sim time, true position) of the items finished lately: ground truth
        self.log: deque[tuple[int, float, Vec3]] = deque(maxlen=1000)
        self._waiting = False  # entered AUTO: start (or resume) on the next update
        self._phase = ""  # of the current nav item
        self._target: Vec3 | None = None
        self._hold_until: float | None = None

    # ---- the store -------------------------------------------------------
    @property
    def count(self) -> int:
        """Items including home (MISSION_COUNT of a download)."""
        return len(self.items)

    def load(self, items: list[MissionItem]) -> None:
        """A completed upload replaces the mission (item 0 is home's place); a
        running mission restarts its current item, as ArduCopter's does."""
        was_active = self.state == ACTIVE
        self.items = [self.items[0], *items[1:]]
        if was_active:
            self._advance(min(self.current, len(self.items)))
            return
        self.current = 0
        self.state = NOT_STARTED if len(self.items) > 1 else NO_MISSION

    def clear(self) -> bool:
        """MISSION_CLEAR_ALL: only home is left; refused while the mission runs
        (AP_Mission::clear)."""
        if self.state == ACTIVE:
            return False
        self.load([])
        return True

    def set_current(self, seq: int) -> bool:
        """MISSION_SET_CURRENT: fly ``seq`` next (at once if the mission runs)."""
        if not 0 < seq < len(self.items):
            return False
        if self.state == ACTIVE:
            self._advance(seq)
        else:
            self.current = seq
            self.state = PAUSED if self.state == PAUSED else NOT_STARTED
        return True

    # ---- mode changes ----------------------------------------------------
    def enter(self) -> Outcome:
        """DO_SET_MODE / SET_MODE to AUTO (ModeAuto::init)."""
        v = self.vehicle
        if v.mode is Mode.AUTO:
            return ACCEPTED
        if v.armed:
            if len(self.items) <= 1:
                return Outcome(Result.FAILED, MODE_FAILED)
            if v.state is FlightState.LANDED and not self._starts_with_takeoff():
                return Outcome(Result.FAILED, f"Auto: Missing Takeoff Cmd\n{MODE_FAILED}")
        v.enter_mode(Mode.AUTO)  # airborne: hold here until the mission starts
        self._waiting = True
        return ACCEPTED

    def start_command(self) -> Outcome:
        """MAV_CMD_MISSION_START: armed, switch to AUTO and run the mission."""
        if not self.vehicle.armed:
            return autopilot.FAILED
        outcome = self.enter()
        if outcome.result is Result.ACCEPTED and self.state != ACTIVE:
            self._start_or_resume()
        return outcome

    def _starts_with_takeoff(self) -> bool:
        first = self._resume_index()
        for item in self.items[first:]:
            if item.command in NAV_COMMANDS:
                return item.command == Cmd.NAV_TAKEOFF
        return False

    def _resume_index(self) -> int:
        done = self.state == COMPLETE or self.current == 0
        return 1 if done else self.current

    # ---- execution -------------------------------------------------------
    def update(self) -> None:
        """Advance the mission; pause it when the vehicle has left AUTO."""
        v = self.vehicle
        if v.mode is not Mode.AUTO:
            self._waiting = False
            if self.state == ACTIVE:
                self.state = PAUSED
            return
        if self.state == ACTIVE and (not v.armed or v.state not in AIRBORNE | {FlightState.LANDED}):
            self.state = PAUSED  # disarmed in the air, fell or crashed
            return
        if self._waiting and v.armed and len(self.items) > 1:
            self._start_or_resume()
        if self.state == ACTIVE and self._nav_done():
            self._item_done(self.current)
            self._advance(self.current + 1)

    def _start_or_resume(self) -> None:
        self._waiting = False
        self._advance(self._resume_index())

    def _advance(self, seq: int) -> None:
        """Run DO items from ``seq`` on and start the next nav item, or finish."""
        self.state = ACTIVE
        while seq < len(self.items) and self.items[seq].command not in NAV_COMMANDS:
            self._announce(seq)
            self._do(self.items[seq])
            self._item_done(seq)
            seq += 1
        if seq >= len(self.items):
            self._finish()
            return
        self.current = seq
        self._announce(seq)
        self._start_nav(self.items[seq])

    def _announce(self, seq: int) -> None:
        name = NAMES.get(self.items[seq].command, str(self.items[seq].command))
        self.vehicle.say(Severity.INFO, f"Mission: {seq} {name}")

    def _item_done(self, seq: int) -> None:
        self.reached.append(seq)
        self.log.append((seq, self.vehicle.now_s, self.vehicle.position))

    def _finish(self) -> None:
        """ModeAuto::exit_mission: hold (loiter) in the air, disarm on the ground."""
        v = self.vehicle
        self.state = COMPLETE if len(self.items) > 1 else NO_MISSION
        self._phase = ""
        if v.state is FlightState.LANDED:
            v.disarm()
        elif v.state in AIRBORNE:
            v.fly_to(self._target or v.position)

    def _stop_flying(self) -> None:
        self._phase, self._target, self._hold_until = "", None, None

    # ---- DO items --------------------------------------------------------
    def _do(self, item: MissionItem) -> None:
        v, p = self.vehicle, item.params
        if item.command == Cmd.DO_CHANGE_SPEED:
            autopilot.change_speed(v, autopilot.as_int(p[0]), p[1])  # -1: no change
        elif item.command == Cmd.DO_GRIPPER:
            outcome = autopilot.gripper(v, autopilot.as_int(p[1]), self.world)
            if outcome.text:
                v.say(Severity.WARNING, outcome.text)

    # ---- nav items -------------------------------------------------------
    def _start_nav(self, item: MissionItem) -> None:
        v = self.vehicle
        self._stop_flying()
        match item.command:
            case Cmd.NAV_TAKEOFF:  # straight up; already higher: done
                z = max(self._location(item, zero_alt_is_here=False)[2], v.position[2])
                self._target = (v.position[0], v.position[1], z)
                if v.state is FlightState.LANDED:
                    v.start_takeoff(z)
                else:
                    v.fly_to(self._target)
            case Cmd.NAV_WAYPOINT | Cmd.NAV_LOITER_TIME:
                self._target = self._location(item)
                v.fly_to(self._target)
            case Cmd.NAV_LAND:  # at the location (lat = lon = 0: here)
                if item.x or item.y:
                    x, y, _ = self._location(item)
                    self._target = (x, y, v.position[2])
                    self._phase = "approach"
                    v.fly_to(self._target)
                else:
                    self._land_here()
            case Cmd.NAV_RETURN_TO_LAUNCH:  # climb to RTL_ALT, return, land
                x, y, z = v.position
                self._target = (x, y, max(z, v.home[2] + v.rtl_alt_m))
                self._phase = "climb"
                v.fly_to(self._target)

    def _nav_done(self) -> bool:
        """Whether the current nav item is complete (its verify_* function)."""
        v, item = self.vehicle, self.items[self.current]
        match item.command:
            case Cmd.NAV_TAKEOFF:
                return v.state is FlightState.FLYING and self._near(self._target, 0.1)
            case Cmd.NAV_WAYPOINT | Cmd.NAV_LOITER_TIME:
                return self._near(self._target, WP_RADIUS_M) and self._held(item.params[0])
            case Cmd.NAV_LAND:
                return self._landing_done()
            case Cmd.NAV_RETURN_TO_LAUNCH:
                return self._rtl_done()
        return True

    def _landing_done(self) -> bool:
        v = self.vehicle
        if self._phase == "approach":
            if self._arrived():
                self._land_here()
            return False
        return v.state is FlightState.LANDED

    def _rtl_done(self) -> bool:
        v = self.vehicle
        if self._phase == "climb" and self._arrived():
            self._target = (v.home[0], v.home[1], v.position[2])
            self._phase = "return"
            v.fly_to(self._target)
        elif self._phase == "return" and self._arrived():
            self._land_here()
        return self._phase == "descend" and v.state is FlightState.LANDED

    def _land_here(self) -> None:
        """Descend here with the LAND mode's descent, staying in AUTO."""
        v = self.vehicle
        self._phase = "descend"
        if v.state in AIRBORNE:
            v.enter_mode(Mode.LAND)  # the same descent and touchdown as LAND
            v.mode = Mode.AUTO  # ... but the mission flies it (ModeAuto land submode)

    def _near(self, target: Vec3 | None, radius_m: float) -> bool:
        return target is not None and physics.distance(self.vehicle.position, target) <= radius_m

    def _arrived(self) -> bool:
        v, t = self.vehicle, self._target
        return t is not None and physics.distance(v.position, t) <= ARRIVED_M

    def _held(self, hold_s: float) -> bool:
        """The waypoint's hold time (param1, s) has passed since it was reached."""
        now = self.vehicle.now_s
        if self._hold_until is None:
            self._hold_until = now + (hold_s if math.isfinite(hold_s) and hold_s > 0 else 0.0)
        return now >= self._hold_until

    def _location(self, item: MissionItem, *, zero_alt_is_here: bool = True) -> Vec3:
        """The item's point in site ENU: lat = lon = 0 is here, altitude 0 the
        current one (ModeAuto::loc_from_cmd); relative frames are above home."""
        v, geo = self.vehicle, self.world.geo
        here = v.position
        lat, lon = item.x / 1e7, item.y / 1e7
        if lat == 0 and lon == 0:
            lat, lon, _ = geo.to_geodetic(here)
        if item.frame in AMSL_FRAMES:
            x, y, z = geo.to_enu(lat, lon, item.z)
        else:
            x, y, _ = geo.to_enu(lat, lon, geo.origin.alt_m)
            z = v.home[2] + item.z
        if item.x == 0 and item.y == 0:
            x, y = here[0], here[1]
        if item.z == 0 and zero_alt_is_here:
            z = here[2]
        return x, y, z
