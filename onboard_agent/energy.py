"""The energy model of the UAV's type: what a leg or a hover costs.

Energy = power x time (system design section 4): flying at the type's
cruise speed (horizontal) and climb rate (vertical) draws ``flight_power_w``,
holding a position draws ``hover_power_w``. A ``margin`` factor covers wind
and estimation error; ``reserve_wh`` must remain at every landing.
"""

from __future__ import annotations

import math

from proto.fleet import UavType
from proto.geo import Point

JOULES_PER_WH = 3600.0


class EnergyModel:
    """Predictions in watt-hours for one UAV type."""

    def __init__(self, uav_type: UavType, reserve_fraction: float, margin: float = 1.0) -> None:
        self.type = uav_type
        self.margin = margin
        self.capacity_wh = uav_type.battery_wh
        self.reserve_wh = reserve_fraction * uav_type.battery_wh

    def flight_s(self, a: Point, b: Point) -> float:
        """Seconds to fly from ``a`` to ``b`` (horizontal and vertical in turn)."""
        horizontal = math.hypot(a.x_m - b.x_m, a.y_m - b.y_m)
        vertical = abs(a.z_m - b.z_m)
        return horizontal / self.type.cruise_speed_mps + vertical / self.type.climb_rate_mps

    def travel_wh(self, a: Point, b: Point) -> float:
        """Energy to fly from ``a`` to ``b``, margin included."""
        seconds = self.flight_s(a, b)
        return self.margin * self.type.flight_power_w * seconds / JOULES_PER_WH

    def hover_wh(self, seconds: float) -> float:
        """Energy to hold a position for ``seconds``, margin included."""
        return self.margin * self.type.hover_power_w * max(0.0, seconds) / JOULES_PER_WH

    def energy_wh(self, fraction: float) -> float:
        """Energy in the pack at state of charge ``fraction``."""
        return fraction * self.capacity_wh

    def reaches(self, fraction: float, a: Point, b: Point) -> bool:
        """Whether a pack at ``fraction`` flies from ``a`` to ``b`` and keeps the reserve."""
        return self.energy_wh(fraction) >= self.travel_wh(a, b) + self.reserve_wh
