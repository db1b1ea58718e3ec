"""A sensible subset of ArduCopter's parameters, for the MAVLink parameter protocol.

Names, units and types are ArduCopter's (``RTL_ALT`` in cm, ``WPNAV_SPEED``
in cm/s, ...). Values are floats on the wire, as ArduPilot sends them (cast,
not byte-wise). Writes of a few take effect at once (see ``autopilot.set_param``);
on a real ArduCopter ``GRIP_ENABLE`` needs a reboot, here it does not.
Unknown names are ignored, as ArduPilot ignores them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from sim_fleet.battery import CELLS, NOMINAL_CELL_V
from sim_fleet.modes import Mode

if TYPE_CHECKING:
    from proto.fleet import UavType

# MAV_PARAM_TYPE
INT8 = 2
INT16 = 4
INT32 = 6
REAL32 = 9


@dataclass(frozen=True, kw_only=True)
class AutopilotParams:
    """ArduCopter-like parameters shared by all simulated vehicles."""

    rtl_alt_m: float = 15.0  # RTL_ALT
    land_final_alt_m: float = 2.0  # below this LAND descends at land_speed_mps
    land_speed_mps: float = 0.5  # LAND_SPEED
    accel_mps2: float = 2.0  # horizontal and vertical acceleration limit
    arm_min_soc: float = 0.25  # pre-arm: below this state of charge arming fails
    low_soc: float = 0.20  # "Battery 1 is low" warning
    critical_soc: float = 0.10  # "Battery 1 is critical" warning
    auto_disarm_s: float | None = 10.0  # DISARM_DELAY: armed on the ground, not flying
    initial_mode: Mode = Mode.STABILIZE
    # GPS/EKF warm-up after power-on, in simulated seconds (ArduCopter SITL takes
    # ~40 s): the GPS gets its 3-D fix half-way, then the EKF uses it, sets its
    # origin and home; until then arming fails with ArduCopter's pre-arm texts
    # and positions read lat = lon = 0. 0 skips it (an explicit choice).
    warmup_s: float = 3.0

    def __post_init__(self) -> None:
        if self.warmup_s < 0:
            raise ValueError("warmup_s must be >= 0")


@dataclass(slots=True)
class Param:
    name: str
    value: float
    type: int = REAL32
    read_only: bool = False


class ParamStore:
    """Ordered parameters of one vehicle (the order gives ``param_index``)."""

    def __init__(self, params: list[Param]) -> None:
        self._params = {p.name: p for p in params}
        self._order = [p.name for p in params]

    def __len__(self) -> int:
        return len(self._order)

    def __contains__(self, name: str) -> bool:
        return name in self._params

    def get(self, name: str) -> float:
        return self._params[name].value

    def param(self, name: str) -> Param | None:
        return self._params.get(name)

    def index_of(self, name: str) -> int:
        return self._order.index(name)

    def by_index(self, index: int) -> Param | None:
        return self._params[self._order[index]] if 0 <= index < len(self._order) else None

    def all(self) -> list[Param]:
        return [self._params[n] for n in self._order]

    def store(self, name: str, value: float) -> Param | None:
        """Write ``value`` (rounded for integer types); None if unknown or read-only."""
        p = self._params.get(name)
        if p is None or p.read_only:
            return None
        p.value = float(round(value)) if p.type != REAL32 else float(value)
        return p


def vehicle_parameters(sysid: int, t: UavType, p: AutopilotParams) -> list[Param]:
    """A vehicle's parameter file: ArduCopter names and units."""
    cells_v = NOMINAL_CELL_V * CELLS
    return [
        Param("SYSID_THISMAV", float(sysid), INT16, read_only=True),
        Param("FRAME_CLASS", 1.0, INT8, read_only=True),  # quad
        Param("ARMING_CHECK", 1.0, INT32),
        Param("DISARM_DELAY", float(p.auto_disarm_s or 0), INT8),
        Param("GRIP_ENABLE", 1.0 if t.gripper else 0.0, INT8),
        Param("RTL_ALT", round(p.rtl_alt_m * 100), INT32),
        Param("LAND_SPEED", round(p.land_speed_mps * 100), INT16),
        Param("WPNAV_SPEED", t.cruise_speed_mps * 100, REAL32),
        Param("WPNAV_SPEED_UP", t.climb_rate_mps * 100, REAL32),
        Param("WPNAV_SPEED_DN", t.climb_rate_mps * 100, REAL32),
        Param("BATT_CAPACITY", float(round(t.battery_wh / cells_v * 1000)), INT32, read_only=True),
        Param("BATT_ARM_MAH", 0.0, INT32),
        Param("SIM_WARMUP_S", p.warmup_s, REAL32, read_only=True),  # not ArduCopter's: the sim's
    ]
