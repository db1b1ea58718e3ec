"""Tool stock: how many of each tool a tool station still has to give.

A station starts with the counts of its scenario (``Tool.count``). Every
delivery in force or completed holds one of its station's tool (it was
reserved when the action was accepted); a failed or cancelled delivery gives
its reservation back. Delivered tools stay with the worker: returns are not
modelled, so a tool whose stock is used up is refused until the mission ends.
"""

from __future__ import annotations

from collections.abc import Iterable

from proto.errors import ToolOutOfStock
from proto.mission import ActionRecord, ActionState, DeliverAction
from proto.site import Site

RELEASED = frozenset({ActionState.FAILED, ActionState.CANCELLED})


def stock_left(site: Site, records: Iterable[ActionRecord], station_id: str, tool: str) -> int:
    """Copies of ``tool`` at ``station_id`` neither delivered nor reserved."""
    station = site.tool_station(station_id)
    total = station.stock(tool) if station is not None else 0
    held = sum(
        1
        for r in records
        if isinstance(r.action, DeliverAction)
        and r.action.tool_station_id == station_id
        and r.action.tool == tool
        and r.state not in RELEASED
    )
    return total - held


def reserve(site: Site, records: Iterable[ActionRecord], action: DeliverAction) -> None:
    """Raise :class:`ToolOutOfStock` if ``action`` would take a tool that is not there."""
    if stock_left(site, records, action.tool_station_id, action.tool) <= 0:
        station = site.tool_station(action.tool_station_id)
        total = station.stock(action.tool) if station is not None else 0
        raise ToolOutOfStock(
            f"no {action.tool} left at {action.tool_station_id}: all {total} delivered or "
            "reserved by other deliveries",
            field="action.tool",
        )
