"""``GET /metrics`` in the Prometheus text format: the ground station's
numbers (over RPC) and the gateway's own request counts."""

from __future__ import annotations

import collections
import re


class GatewayCounters:
    """HTTP responses by status code."""

    def __init__(self) -> None:
        self.by_status: collections.Counter[int] = collections.Counter()

    def count(self, status: int) -> None:
        """One response with ``status``."""
        self.by_status[status] += 1


def prometheus_text(gs_values: dict[str, float] | None, counters: GatewayCounters) -> str:
    """The exposition text; ``gs_values`` is ``None`` when the ground station is down."""
    lines = ["# TYPE linecrew_gateway_responses_total counter"]
    lines += [
        f'linecrew_gateway_responses_total{{status="{status}"}} {count}'
        for status, count in sorted(counters.by_status.items())
    ]
    lines += [
        "# TYPE linecrew_ground_station_up gauge",
        f"linecrew_ground_station_up {0 if gs_values is None else 1}",
    ]
    for name, value in sorted((gs_values or {}).items()):
        metric = "linecrew_gs_" + re.sub(r"[^a-zA-Z0-9_]", "_", name)
        lines += [f"# TYPE {metric} gauge", f"{metric} {value:g}"]
    return "\n".join(lines) + "\n"
