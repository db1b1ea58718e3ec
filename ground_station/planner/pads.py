"""Shared charging pads: a per-station timeline of reservations."""

from __future__ import annotations

from bisect import insort
from collections.abc import Callable

from ground_station.planner.energy import EPS_S

Ignore = tuple[str, float] | None
"""(uav_id, from_s): that UAV's reservations starting at or after from_s are
ignored (they are being re-planned)."""


class Pads:
    """Reservations ``(start_s, end_s, uav_id)`` per charging-station index."""

    __slots__ = ("capacity", "slots")

    def __init__(self, capacity: list[int]) -> None:
        self.capacity = capacity
        self.slots: list[list[tuple[float, float, str]]] = [[] for _ in capacity]

    def copy(self) -> Pads:
        other = Pads(self.capacity)
        other.slots = [list(s) for s in self.slots]
        return other

    def _fits(self, busy: list[tuple[float, float]], cap: int, t: float, end: float) -> bool:
        live = [(s, e) for s, e in busy if s < end - EPS_S and e > t + EPS_S]
        if len(live) < cap:
            return True
        events = sorted([(max(s, t), 1) for s, _ in live] + [(e, -1) for _, e in live])
        level = 0
        for _, delta in events:
            level += delta
            if level >= cap:
                return False
        return True

    def earliest(self, si: int, t_from: float, duration_s: float, ign: Ignore) -> float:
        """Earliest start >= ``t_from`` with a free pad for ``duration_s``."""
        cap = self.capacity[si]
        slots = self.slots[si]
        if len(slots) < cap:
            return t_from
        if cap == 1:  # reservations never overlap and are sorted by start
            t = t_from
            uid, from_s = ign if ign is not None else ("", float("inf"))
            from_s -= EPS_S
            for s, e, u in slots:
                if e <= t + EPS_S or (u == uid and s >= from_s):
                    continue
                if s >= t + duration_s - EPS_S:
                    break
                t = e
            return t
        lo = t_from + EPS_S
        if ign is None:
            busy = [(s, e) for s, e, _ in slots if e > lo]
        else:
            uid, from_s = ign
            from_s -= EPS_S
            busy = [(s, e) for s, e, u in slots if e > lo and not (u == uid and s >= from_s)]
        if len(busy) < cap:
            return t_from
        if self._fits(busy, cap, t_from, t_from + duration_s):
            return t_from
        t = t_from
        for cand in sorted({e for _, e in busy}):
            t = cand
            if self._fits(busy, cap, t, t + duration_s):
                return t
        return t

    def first_fit(
        self,
        si: int,
        t_from: float,
        t_max: float,
        duration: Callable[[float], float],
        min_s: float,
        ign: Ignore,
    ) -> tuple[float, float] | None:
        """Earliest (start, length) with start in [t_from, t_max] and a free pad
        for ``duration(start)`` seconds (which shrinks as start grows), at
        least ``min_s``; None if there is none."""
        cap = self.capacity[si]
        if cap == 1:
            t = t_from
            uid, from_s = ign if ign is not None else ("", float("inf"))
            from_s -= EPS_S
            for s, e, u in self.slots[si]:
                if e <= t + EPS_S or (u == uid and s >= from_s):
                    continue
                if s >= t + duration(t) - EPS_S:
                    break
                t = e
            if t > t_max + EPS_S:
                return None
            d = duration(t)
            if d < min_s - EPS_S or d <= EPS_S:
                return None
            return t, d
        if ign is None:
            busy = [(s, e) for s, e, _ in self.slots[si] if e > t_from + EPS_S]
        else:
            uid, from_s = ign
            busy = [
                (s, e)
                for s, e, u in self.slots[si]
                if e > t_from + EPS_S and not (u == uid and s >= from_s - EPS_S)
            ]
        for start in [t_from, *sorted({e for _, e in busy})]:
            if start > t_max + EPS_S:
                return None
            d = duration(start)
            if d < min_s - EPS_S or d <= EPS_S:
                return None
            if len(busy) < cap or self._fits(busy, cap, start, start + d):
                return start, d
        return None

    def remove_uav(self, uav_id: str, from_s: float, until_s: float = float("inf")) -> None:
        """Drop ``uav_id``'s reservations starting in [from_s, until_s)."""
        lo, hi = from_s - EPS_S, until_s - EPS_S
        for i, lst in enumerate(self.slots):
            if any(u == uav_id for _, _, u in lst):
                self.slots[i] = [r for r in lst if not (r[2] == uav_id and lo <= r[0] < hi)]

    def add(self, si: int, start_s: float, end_s: float, uav_id: str) -> None:
        insort(self.slots[si], (start_s, end_s, uav_id))
