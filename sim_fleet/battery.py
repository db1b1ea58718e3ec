"""A LiPo pack: energy bookkeeping and a voltage curve from state of charge."""

from __future__ import annotations

import bisect

# Resting voltage of one LiPo cell against state of charge (0..1).
_SOC_POINTS = (0.0, 0.05, 0.10, 0.20, 0.40, 0.60, 0.80, 0.90, 1.0)
_CELL_VOLTS = (3.30, 3.50, 3.60, 3.70, 3.78, 3.85, 3.98, 4.08, 4.20)
NOMINAL_CELL_V = 3.7
CELLS = 4
"""LiPo cells in series in every simulated pack."""
INTERNAL_RESISTANCE_OHM_PER_CELL = 0.005


def cell_voltage(soc: float) -> float:
    """Open-circuit voltage of one cell at ``soc`` (piecewise linear)."""
    soc = min(1.0, max(0.0, soc))
    i = bisect.bisect_right(_SOC_POINTS, soc)
    if i >= len(_SOC_POINTS):
        return _CELL_VOLTS[-1]
    s0, s1 = _SOC_POINTS[i - 1], _SOC_POINTS[i]
    v0, v1 = _CELL_VOLTS[i - 1], _CELL_VOLTS[i]
    return v0 + (v1 - v0) * (soc - s0) / (s1 - s0)


class Battery:
    """Energy in watt-hours; ``load_w`` is the power being drawn right now."""

    def __init__(self, capacity_wh: float, soc: float = 1.0, cells: int = CELLS) -> None:
        if capacity_wh <= 0:
            raise ValueError("capacity_wh must be positive")
        self.capacity_wh = capacity_wh
        self.energy_wh = capacity_wh * min(1.0, max(0.0, soc))
        self.cells = cells
        self.load_w = 0.0
        self.drawn_wh = 0.0  # total energy ever drawn (for tests and stats)

    @property
    def soc(self) -> float:
        return self.energy_wh / self.capacity_wh

    @property
    def empty(self) -> bool:
        return self.energy_wh <= 0.0

    @property
    def consumed_wh(self) -> float:
        """Energy missing from a full pack (what BATTERY_STATUS reports)."""
        return self.capacity_wh - self.energy_wh

    def draw(self, power_w: float, dt_s: float) -> float:
        """Draw ``power_w`` for ``dt_s``; returns the seconds actually powered."""
        self.load_w = power_w
        if power_w <= 0.0 or dt_s <= 0.0:
            return dt_s
        need_wh = power_w * dt_s / 3600.0
        if need_wh <= self.energy_wh:
            self.energy_wh -= need_wh
            self.drawn_wh += need_wh
            return dt_s
        powered_s = self.energy_wh * 3600.0 / power_w
        self.drawn_wh += self.energy_wh
        self.energy_wh = 0.0
        return powered_s

    def add(self, energy_wh: float) -> None:
        self.energy_wh = min(self.capacity_wh, self.energy_wh + max(0.0, energy_wh))

    def set_soc(self, soc: float) -> None:
        self.energy_wh = self.capacity_wh * min(1.0, max(0.0, soc))

    def open_circuit_v(self) -> float:
        return cell_voltage(self.soc) * self.cells

    def current_a(self) -> float:
        if self.load_w <= 0.0:
            return 0.0
        return self.load_w / self.open_circuit_v()

    def voltage_v(self) -> float:
        """Terminal voltage: open-circuit minus the sag of the present load."""
        sag = self.current_a() * INTERNAL_RESISTANCE_OHM_PER_CELL * self.cells
        return max(0.0, self.open_circuit_v() - sag)

    def consumed_mah(self) -> float:
        return self.consumed_wh / (NOMINAL_CELL_V * self.cells) * 1000.0
