"""One simulated multirotor: body, battery, gripper, flight state and faults.

The vehicle knows *how* to fly (takeoff, go to, land, return, fall); the
ArduCopter rules about *whether* a command is allowed live in ``autopilot``.
``step(dt_s, now_s)`` advances it on the injected simulation clock.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable

from proto.fleet import UavSpec, UavType
from proto.site import Tool
from sim_fleet import physics
from sim_fleet.battery import Battery
from sim_fleet.events import Severity, StatusText
from sim_fleet.modes import FlightState, Mode
from sim_fleet.params import AutopilotParams, ParamStore, vehicle_parameters
from sim_fleet.physics import Vec3
from sim_fleet.terrain import flat

log = logging.getLogger(__name__)

MOVING_MPS = 0.2  # above this speed a UAV draws flight power, below it hover power
VELOCITY_TIMEOUT_S = 3.0  # GUIDED velocity commands expire (ArduCopter GUID_TIMEOUT)
AIRBORNE = frozenset({FlightState.TAKING_OFF, FlightState.FLYING, FlightState.LANDING})


class Vehicle:
    def __init__(
        self,
        spec: UavSpec,
        vtype: UavType,
        *,
        sysid: int,
        home: Vec3,
        params: AutopilotParams | None = None,
        ground: Callable[[float, float], float] = flat,
    ) -> None:
        self.id = spec.id
        self.spec = spec
        self.type = vtype
        self.sysid = sysid
        self.params = params or AutopilotParams()
        self.ground = ground  # the ground's height under (x, y): a deck's top, else terrain
        self.home: Vec3 = (home[0], home[1], ground(home[0], home[1]))
        self.origin: Vec3 = self.home  # EKF origin (LOCAL_NED frames): the power-on spot
        self.home_set = self.params.warmup_s <= 0
        self.home_version = 0  # bumped when home is set or moved (HOME_POSITION goes out)
        self.position: Vec3 = self.home
        self.velocity: Vec3 = (0.0, 0.0, 0.0)
        self.heading_deg = 0.0
        self.battery = Battery(vtype.battery_wh)
        self.armed = False
        self.mode = self.params.initial_mode
        self.state = FlightState.LANDED
        self.speed_mps = vtype.cruise_speed_mps
        self.climb_mps = vtype.climb_rate_mps
        self.descent_mps = vtype.climb_rate_mps  # proto has one vertical rate
        self.target: Vec3 | None = None  # position target while flying
        self.velocity_cmd: Vec3 | None = None
        self._velocity_cmd_until = 0.0
        self.rtl_phase: str | None = None  # "climb" | "return" | "descend"
        self._rtl_alt_m = 0.0
        self._land_at: Vec3 = self.home
        self.holding: Tool | None = None
        self.now_s = 0.0
        self._ground_armed_s = 0.0
        self._warned = 0  # 1: low, 2: critical
        self._texts: list[StatusText] = []
        # faults
        self.motors_failed = False
        self.gripper_failed = False
        self.drain_multiplier = 1.0
        self.link_down_until = 0.0
        self.gps_frozen: tuple[Vec3, Vec3] | None = None
        self.gps_frozen_until = math.inf
        self.parameters = ParamStore(vehicle_parameters(sysid, vtype, self.params))

    # ---- status ----------------------------------------------------------
    @property
    def airborne(self) -> bool:
        return self.state in AIRBORNE or self.state is FlightState.FALLING

    @property
    def has_gripper(self) -> bool:
        return self.type.gripper

    @property
    def gps_fix(self) -> bool:
        """The GPS has a 3-D fix (half-way through the warm-up)."""
        return self.now_s >= 0.5 * self.params.warmup_s

    @property
    def ekf_ok(self) -> bool:
        """The EKF has an absolute position (origin and home set)."""
        return self.home_set

    def prearm_failures(self) -> list[str]:
        """ArduCopter's pre-arm check texts that fail now (empty when armable)."""
        failures = []
        if self.state in (FlightState.CRASHED, FlightState.FALLING) or self.motors_failed:
            failures.append("PreArm: Motors: check failed")
        if self.parameters.get("ARMING_CHECK") == 0:
            return failures
        if not self.ekf_ok:
            failures.append("PreArm: AHRS: waiting for home")
        if not self.gps_fix:
            failures.append("PreArm: GPS 1: Bad fix")
        if self.battery.soc < self.params.arm_min_soc:
            failures.append("PreArm: Battery 1 below minimum arming capacity")
        return failures

    @property
    def disarm_delay_s(self) -> float | None:
        delay = self.parameters.get("DISARM_DELAY")
        return None if delay <= 0 else delay

    @property
    def rtl_alt_m(self) -> float:
        return self.parameters.get("RTL_ALT") / 100.0

    def ground_z(self) -> float:
        """The ground's height under the vehicle (a raised deck's top, else terrain)."""
        return self.ground(self.position[0], self.position[1])

    def say(self, severity: Severity, text: str) -> None:
        log.info("%s: %s", self.id, text, extra={"uav_id": self.id})
        self._texts.append(StatusText(severity, text))

    def take_texts(self) -> list[StatusText]:
        texts, self._texts = self._texts, []
        return texts

    def link_up(self) -> bool:
        return self.now_s >= self.link_down_until

    def reported_position(self) -> tuple[Vec3, Vec3]:
        """(position, velocity) as the GPS reports them (frozen by a GPS fault)."""
        if self.gps_frozen is not None and self.now_s < self.gps_frozen_until:
            return self.gps_frozen
        self.gps_frozen = None
        return self.position, self.velocity

    def limits(self, *, down_mps: float | None = None) -> physics.Limits:
        return physics.Limits(
            horizontal_mps=self.speed_mps,
            up_mps=self.climb_mps,
            down_mps=down_mps if down_mps is not None else self.descent_mps,
            accel_mps2=self.params.accel_mps2,
        )

    # ---- primitives used by the autopilot rules --------------------------
    def arm(self) -> None:
        self.armed = True
        self._ground_armed_s = 0.0
        self.home = self.position  # ArduCopter re-homes where it arms
        self.home_version += 1

    def disarm(self, reason: str = "Disarming motors") -> None:
        if not self.armed:
            return
        self.armed = False
        self.say(Severity.INFO, reason)
        if self.state in AIRBORNE:
            self._start_falling()

    def enter_mode(self, mode: Mode) -> None:
        self.mode = mode
        self.velocity_cmd = None
        self.rtl_phase = None
        if self.state not in AIRBORNE:
            if self.armed and self.state is FlightState.LANDED and mode in (Mode.LAND, Mode.RTL):
                self.disarm()
            return
        if mode is Mode.LAND:
            self.state = FlightState.LANDING
            self._land_at = (self.position[0], self.position[1], self.ground_z())
        elif mode is Mode.RTL:
            self.state = FlightState.FLYING
            self.rtl_phase = "climb"
            self._rtl_alt_m = max(self.position[2], self.home[2] + self.rtl_alt_m)
        else:
            self.state = FlightState.FLYING
            self.target = self.position  # GUIDED/STABILIZE entry: hold here

    def start_takeoff(self, z_m: float) -> None:
        """Climb straight up to the site height ``z_m``."""
        self.state = FlightState.TAKING_OFF
        self.target = (self.position[0], self.position[1], z_m)

    def fly_to(self, target: Vec3) -> None:
        self.velocity_cmd = None
        x, y, z = target
        self.target = (x, y, max(self.ground(x, y), z))
        if self.state is FlightState.TAKING_OFF:
            self.state = FlightState.FLYING

    def fly_velocity(self, velocity: Vec3) -> None:
        self.velocity_cmd = velocity
        self._velocity_cmd_until = self.now_s + VELOCITY_TIMEOUT_S
        if self.state is FlightState.TAKING_OFF:
            self.state = FlightState.FLYING

    # ---- faults -----------------------------------------------------------
    def fail_motors(self) -> None:
        """Motor failure: an airborne vehicle falls and crashes; it cannot fly again."""
        self.motors_failed = True
        if self.airborne and self.state is not FlightState.FALLING:
            self._start_falling()
        self.armed = False

    def drop_link(self, duration_s: float) -> None:
        """No MAVLink in or out for ``duration_s`` simulated seconds."""
        self.link_down_until = max(self.link_down_until, self.now_s + duration_s)

    def kill(self) -> None:
        """Vehicle lost: no more heartbeats, and it falls."""
        self.fail_motors()
        self.link_down_until = math.inf

    def freeze_gps(self, duration_s: float | None = None) -> None:
        """Reported position stops updating (forever when ``duration_s`` is None)."""
        self.gps_frozen = (self.position, self.velocity)
        self.gps_frozen_until = math.inf if duration_s is None else self.now_s + duration_s

    def set_battery_soc(self, soc: float) -> None:
        self.battery.set_soc(soc)
        self._warned = 0

    # ---- simulation -------------------------------------------------------
    def step(self, dt_s: float, now_s: float) -> None:
        self.now_s = now_s
        if not self.home_set and now_s >= self.params.warmup_s:
            self._set_home()
        if self.state is FlightState.FALLING:
            self.position, self.velocity = physics.step_falling(self.position, self.velocity, dt_s)
            self.battery.load_w = 0.0
            if self.position[2] <= self.ground_z():
                self._crash()
            return
        if self.state in (FlightState.LANDED, FlightState.CRASHED):
            self.battery.load_w = 0.0
            self._ground_tick(dt_s)
            return
        self._fly(dt_s)
        if self.state in (FlightState.LANDED, FlightState.CRASHED):
            return
        power_w = (
            self.type.flight_power_w
            if physics.speed(self.velocity) >= MOVING_MPS
            else self.type.hover_power_w
        )
        self.battery.draw(power_w * self.drain_multiplier, dt_s)
        self._battery_warnings()
        if self.battery.empty:
            self.say(Severity.EMERGENCY, "Battery 1 empty: motors stopped")
            self.armed = False
            self._start_falling()

    def _ground_tick(self, dt_s: float) -> None:
        if not self.armed:
            return
        if self.battery.empty or self.motors_failed:
            self.disarm()
            return
        self._ground_armed_s += dt_s
        limit = self.disarm_delay_s
        if limit is not None and self._ground_armed_s >= limit:
            self.disarm("Disarming motors (auto)")

    def _fly(self, dt_s: float) -> None:
        if self.state is FlightState.LANDING:
            self._descend(dt_s)
            return
        if self.mode is Mode.RTL and self.state is FlightState.FLYING:
            self._rtl(dt_s)
            return
        if self.velocity_cmd is not None and self.now_s > self._velocity_cmd_until:
            self.velocity_cmd = None
            self.target = self.position
        if self.velocity_cmd is not None:
            self.position, self.velocity = physics.step_velocity(
                self.position, self.velocity, self.velocity_cmd, self.limits(), dt_s
            )
        else:
            target = self.target or self.position
            self.position, self.velocity = physics.step_to_target(
                self.position, self.velocity, target, self.limits(), dt_s
            )
            if self.state is FlightState.TAKING_OFF and self.position == target:
                self.state = FlightState.FLYING
        self._update_heading()
        if self.position[2] <= self.ground_z() and self.state is FlightState.FLYING:
            self._crash()  # flown into the ground (or a deck): only LAND and RTL touch down

    def _descend(self, dt_s: float) -> None:
        ground_z = self.ground_z()
        final = self.position[2] - ground_z <= self.params.land_final_alt_m
        down = min(self.params.land_speed_mps, self.descent_mps) if final else self.descent_mps
        self.position, self.velocity = physics.step_to_target(
            self.position, self.velocity, self._land_at, self.limits(down_mps=down), dt_s
        )
        if self.position[2] <= ground_z + 1e-3:
            self._touchdown()

    def _rtl(self, dt_s: float) -> None:
        x, y, z = self.position
        hx, hy, _ = self.home
        cruise_alt = self._rtl_alt_m
        if self.rtl_phase == "climb":
            goal: Vec3 = (x, y, cruise_alt)
            if z >= cruise_alt - 1e-3:
                self.rtl_phase = "return"
        if self.rtl_phase == "return":
            goal = (hx, hy, cruise_alt)
            if physics.horizontal_distance(self.position, self.home) < 1e-2:
                self.rtl_phase = "descend"
                self.state = FlightState.LANDING
                self._land_at = (hx, hy, self.ground(hx, hy))  # down to home's ground
                return
        self.position, self.velocity = physics.step_to_target(
            self.position, self.velocity, goal, self.limits(), dt_s
        )
        self._update_heading()

    def _update_heading(self) -> None:
        vx, vy = self.velocity[0], self.velocity[1]
        if math.hypot(vx, vy) > MOVING_MPS:
            self.heading_deg = math.degrees(math.atan2(vx, vy)) % 360.0

    def _set_home(self) -> None:
        """End of the warm-up: the EKF uses the GPS, sets its origin and home here."""
        self.home_set = True
        self.origin = self.home = self.position
        self.home_version += 1
        self.say(Severity.INFO, "EKF3 IMU0 is using GPS")
        self.say(Severity.INFO, "EKF3 IMU0 origin set")

    def _touchdown(self) -> None:
        self.position = (self.position[0], self.position[1], self.ground_z())
        self.velocity = (0.0, 0.0, 0.0)
        self.state = FlightState.LANDED
        self.target = None
        self.velocity_cmd = None
        self.rtl_phase = None
        self.battery.load_w = 0.0
        self._ground_armed_s = 0.0
        if self.mode in (Mode.LAND, Mode.RTL):
            self.disarm("Land complete: disarming")

    def _start_falling(self) -> None:
        self.state = FlightState.FALLING
        self.target = None
        self.velocity_cmd = None
        self.battery.load_w = 0.0

    def _crash(self) -> None:
        self.position = (self.position[0], self.position[1], self.ground_z())
        self.velocity = (0.0, 0.0, 0.0)
        self.state = FlightState.CRASHED
        self.target = None
        self.velocity_cmd = None
        self.battery.load_w = 0.0
        self.armed = False
        self.say(Severity.EMERGENCY, "Crash: Disarming")

    def _battery_warnings(self) -> None:
        soc = self.battery.soc
        level = 2 if soc <= self.params.critical_soc else 1 if soc <= self.params.low_soc else 0
        if level > self._warned:
            word = "critical" if level == 2 else "low"
            self.say(
                Severity.CRITICAL,
                f"Battery 1 is {word} {self.battery.voltage_v():.2f}V used "
                f"{self.battery.consumed_mah():.0f} mAh",
            )
        self._warned = max(self._warned, level)
