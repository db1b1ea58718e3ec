"""Charging stations: pads that recharge docked UAVs, and a FIFO queue for the rest.

A UAV is *docked* at a station while it sits landed and disarmed within the
dock radius (the world decides that each step and calls ``update_docked``).
Docked UAVs take a free pad in arrival order; the others queue. Leaving (arming,
taking off) frees the pad or the queue slot at once; an unfinished swap is lost.
"""

from __future__ import annotations

from dataclasses import dataclass

from proto import site
from sim_fleet.battery import Battery


@dataclass
class PadSession:
    vehicle_id: str
    elapsed_s: float = 0.0
    done: bool = False


class ChargingStation:
    def __init__(self, spec: site.ChargingStation) -> None:
        self.spec = spec
        self.on_pads: list[PadSession] = []
        self.queue: list[str] = []

    @property
    def id(self) -> str:
        return self.spec.id

    def status_of(self, vehicle_id: str) -> str | None:
        """``"charging"``, ``"charged"``, ``"queued"`` or None (not here)."""
        for s in self.on_pads:
            if s.vehicle_id == vehicle_id:
                return "charged" if s.done else "charging"
        return "queued" if vehicle_id in self.queue else None

    def update_docked(self, docked: list[str]) -> list[tuple[str, str]]:
        """Sync with the UAVs docked now; returns (vehicle_id, notice) pairs."""
        present = set(docked)
        self.on_pads = [s for s in self.on_pads if s.vehicle_id in present]
        self.queue = [v for v in self.queue if v in present]
        known = {s.vehicle_id for s in self.on_pads} | set(self.queue)
        self.queue.extend(v for v in docked if v not in known)
        notices: list[tuple[str, str]] = []
        while self.queue and len(self.on_pads) < self.spec.pads:
            vid = self.queue.pop(0)
            self.on_pads.append(PadSession(vid))
            notices.append((vid, f"Pad: recharging at {self.id}"))
        notices.extend(
            (vid, f"Pad: queued at {self.id}, place {i + 1}")
            for i, vid in enumerate(self.queue)
            if vid not in known
        )
        return notices

    def step(self, dt_s: float, batteries: dict[str, Battery]) -> list[tuple[str, str]]:
        """Recharge the UAVs on pads for ``dt_s``; returns (vehicle_id, notice) pairs."""
        model = self.spec.recharge
        notices: list[tuple[str, str]] = []
        for s in self.on_pads:
            if s.done:
                continue
            battery = batteries[s.vehicle_id]
            s.elapsed_s += dt_s
            if isinstance(model, site.BatterySwap):
                if s.elapsed_s < model.swap_s:
                    continue
                battery.set_soc(1.0)
            else:
                battery.add(battery.capacity_wh * dt_s / model.full_charge_s)
            if battery.soc >= 1.0:
                s.done = True
                notices.append((s.vehicle_id, f"Pad: battery full at {self.id}"))
        return notices
