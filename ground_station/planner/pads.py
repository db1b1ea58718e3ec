"""Shared charging pads: a per-station timeline of reservations."""

from __future__ import annotations

from bisect import bisect_left, insort
from collections.abc import Iterable

from ground_station.planner.energy import EPS_S
from ground_station.planner.state import Booking

Ignore = tuple[str, float] | None
"""(uav_id, from_s): that UAV's reservations starting at or after from_s are
ignored (they are being re-planned)."""

Reservation = tuple[float, float, str]
"""(start_s, end_s, uav_id) on one resource. The timelines keep plain tuples,
always unpacked: they are searched with ``bisect`` probes such as ``(t,)``,
and a named tuple measurably slowed full plans (its constructor is a Python
function; tuples of scalars also leave the garbage collector's lists)."""
UavReservation = tuple[float, float, int]
"""(start_s, end_s, resource) of one UAV, likewise."""

_NONE: list[Reservation] = []


class Pads:
    """Reservations per resource index (a charging station's pads
    (``capacity``), or after them a hold point, taken one UAV at a time),
    sorted by start. Sparse: only resources ever reserved hold a list, and
    each UAV's reservations are indexed by start (``by_uav``), so that
    thousands of hold points cost nothing until used and dropping a UAV's
    reservations costs what it drops."""

    __slots__ = ("by_uav", "capacity", "longest", "slots")

    def __init__(self, capacity: list[int]) -> None:
        self.capacity = capacity  # per charging station; any later index has 1
        self.slots: dict[int, list[Reservation]] = {}
        self.longest: dict[int, float] = {}  # no reservation was ever longer (s)
        self.by_uav: dict[str, list[UavReservation]] = {}

    def copy(self) -> Pads:
        other = Pads(self.capacity)
        other.slots = dict(self.slots)  # the lists are never changed in place
        other.longest = dict(self.longest)
        other.by_uav = {u: list(r) for u, r in self.by_uav.items()}
        return other

    def _cap(self, si: int) -> int:
        return self.capacity[si] if si < len(self.capacity) else 1

    def _after(self, si: int, t: float) -> list[Reservation]:
        """Resource ``si``'s reservations less those that surely end before
        ``t`` (they start too early to last until then)."""
        slots = self.slots.get(si, _NONE)
        if not slots:
            return slots
        i = bisect_left(slots, (t - self.longest[si] - 1.0,))
        return slots[i:] if i else slots

    def _fits(self, busy: list[tuple[float, float]], cap: int, t: float, end: float) -> bool:
        lo, hi = t + EPS_S, end - EPS_S
        live = [(s, e) for s, e in busy if s < hi and e > lo]
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
        cap = self._cap(si)
        slots = self._after(si, t_from)
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
        busy = _busy(slots, t_from, ign)
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
        self, si: int, t_from: float, t_max: float, full_s: float, min_s: float, ign: Ignore
    ) -> tuple[float, float] | None:
        """Earliest (start, length) with start in [t_from, t_max] and a free pad
        for ``min(full_s, t_max - start)`` seconds, at least ``min_s``; None
        if there is none."""
        d = min(full_s, t_max - t_from)
        if t_from > t_max + EPS_S or d < min_s - EPS_S or d <= EPS_S:
            return None  # later starts are shorter still
        cap = self._cap(si)
        slots = self._after(si, t_from)
        if cap == 1:  # as in ``earliest``, for a window shrinking towards ``t_max``
            t = t_from
            uid, from_s = ign if ign is not None else ("", float("inf"))
            from_s -= EPS_S
            for s, e, u in slots:
                if e <= t + EPS_S or (u == uid and s >= from_s):
                    continue
                if s >= t + min(full_s, t_max - t) - EPS_S:
                    break
                t = e
            if t > t_max + EPS_S:
                return None
            d = min(full_s, t_max - t)
            if d < min_s - EPS_S or d <= EPS_S:
                return None
            return t, d
        busy = _busy(slots, t_from, ign)
        if len(busy) < cap or self._fits(busy, cap, t_from, t_from + d):
            return t_from, d
        for start in sorted({e for _, e in busy}):
            if start > t_max + EPS_S:
                return None
            d = min(full_s, t_max - start)
            if d < min_s - EPS_S or d <= EPS_S:
                return None
            if self._fits(busy, cap, start, start + d):
                return start, d
        return None

    def free_for_good(self, si: int, t: float, keep: int, ign: Ignore) -> bool:
        """Whether a pad of station ``si`` is free from ``t`` on for good with
        ``keep`` more left free beside it."""
        cap = self._cap(si) - keep
        busy = _busy(self._after(si, t), t, ign)
        return cap >= 1 and self._fits(busy, cap, t, float("inf"))

    def remove_uav(self, uav_id: str, from_s: float, until_s: float = float("inf")) -> None:
        """Drop ``uav_id``'s reservations starting in [from_s, until_s)."""
        mine = self.by_uav.get(uav_id)
        if not mine:
            return
        i = bisect_left(mine, (from_s - EPS_S,))
        j = bisect_left(mine, (until_s - EPS_S,))
        for start, end, si in mine[i:j]:
            gone = (start, end, uav_id)
            self.slots[si] = [r for r in self.slots[si] if r != gone]
        del mine[i:j]

    def merge(self, merged: int, joined: int) -> None:
        """Move resource ``merged``'s reservations to ``joined`` (hold points
        that a new point linked into one group)."""
        moved = self.slots.pop(merged, None)
        if not moved:
            return
        self.slots[joined] = sorted([*self.slots.get(joined, _NONE), *moved])
        self.longest[joined] = max(self.longest.get(joined, 0.0), self.longest.pop(merged))
        for uid in {u for _, _, u in moved}:
            self.by_uav[uid] = sorted(
                (s, e, joined if si == merged else si) for s, e, si in self.by_uav[uid]
            )

    def add(self, si: int, start_s: float, end_s: float, uav_id: str) -> None:
        lst = list(self.slots.get(si, _NONE))  # a new list: copies share the old one
        insort(lst, (start_s, end_s, uav_id))
        self.slots[si] = lst
        self.longest[si] = max(self.longest.get(si, 0.0), end_s - start_s)
        insort(self.by_uav.setdefault(uav_id, []), (start_s, end_s, si))

    def book(self, bookings: Iterable[Booking], uav_id: str) -> None:
        """Add ``uav_id``'s ``bookings``."""
        for b in bookings:
            self.add(b.resource, b.start_s, b.end_s, uav_id)


def _busy(slots: list[Reservation], t_from: float, ign: Ignore) -> list[tuple[float, float]]:
    """``(start, end)`` of the reservations ending after ``t_from``, leaving
    out those ``ign`` names."""
    lo = t_from + EPS_S
    if ign is None:
        return [(s, e) for s, e, _ in slots if e > lo]
    uid, from_s = ign
    from_s -= EPS_S
    return [(s, e) for s, e, u in slots if e > lo and not (u == uid and s >= from_s)]
