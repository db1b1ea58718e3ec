"""Key expressions of the linecrew key space, built and parsed in one place.

::

    linecrew/{site}/uav/{uav}/telemetry|status|outcome|plan|spot
    linecrew/{site}/human/{worker}/pose
    linecrew/{site}/station/{station}/spots
    linecrew/{site}/gs/rpc/{op}
    linecrew/{site}/gs/events
    linecrew/{site}/gs/traffic
    linecrew/{site}/alive/{role}/{id}
    linecrew/{site}/sim/{topic}

Every id is one chunk of ``[A-Za-z0-9._-]`` not starting with ``@``;
anything else raises :class:`InvalidKey`.
"""

from __future__ import annotations

import enum
import re

import msgspec

from proto.base import ID_PATTERN
from proto.errors import InvalidKey

ROOT = "linecrew"
_ID = re.compile(ID_PATTERN)


class UavTopic(enum.StrEnum):
    """Per-UAV topics."""

    TELEMETRY = "telemetry"
    STATUS = "status"
    OUTCOME = "outcome"
    PLAN = "plan"
    SPOT = "spot"


class Role(enum.StrEnum):
    """Who declares a liveliness token."""

    GROUND_STATION = "gs"
    AGENT = "agent"
    GATEWAY = "gateway"
    SIM = "sim"
    ROUTER = "router"


def check_id(value: str, what: str = "id") -> str:
    """Return ``value`` if it is a valid key chunk, else raise :class:`InvalidKey`."""
    if not isinstance(value, str) or not _ID.match(value):
        raise InvalidKey(f"invalid {what} {value!r}: use 1-64 characters of [A-Za-z0-9._-]")
    return value


class ParsedKey(msgspec.Struct, frozen=True):
    """A key split into its parts: ``kind`` is ``uav``, ``human``,
    ``station``, ``rpc``, ``events``, ``traffic``, ``alive`` or ``sim``; ``ident`` the UAV /
    worker / station / op / id; ``topic`` the per-UAV topic, the liveliness
    role, or the sim topic."""

    site: str
    kind: str
    ident: str | None = None
    topic: str | None = None


class KeySpace:
    """Builds and parses the keys of one site."""

    def __init__(self, site: str = "default") -> None:
        self.site = check_id(site, "site")
        self.prefix = f"{ROOT}/{self.site}"

    def uav(self, uav_id: str, topic: UavTopic) -> str:
        """``uav/{uav_id}/{topic}``."""
        return f"{self.prefix}/uav/{check_id(uav_id, 'uav id')}/{UavTopic(topic)}"

    def telemetry(self, uav_id: str) -> str:
        """Where ``uav_id`` publishes telemetry."""
        return self.uav(uav_id, UavTopic.TELEMETRY)

    def status(self, uav_id: str) -> str:
        """Where ``uav_id`` publishes its status."""
        return self.uav(uav_id, UavTopic.STATUS)

    def outcome(self, uav_id: str) -> str:
        """Where ``uav_id`` publishes task outcomes."""
        return self.uav(uav_id, UavTopic.OUTCOME)

    def plan(self, uav_id: str) -> str:
        """Where ``uav_id``'s plan is published (and queried)."""
        return self.uav(uav_id, UavTopic.PLAN)

    def all_uavs(self, topic: UavTopic) -> str:
        """Wildcard for one topic of every UAV."""
        return f"{self.prefix}/uav/*/{UavTopic(topic)}"

    def human_pose(self, worker_id: str) -> str:
        """Where the tracker publishes ``worker_id``'s pose."""
        return f"{self.prefix}/human/{check_id(worker_id, 'worker id')}/pose"

    def all_human_poses(self) -> str:
        """Wildcard for every worker's pose."""
        return f"{self.prefix}/human/*/pose"

    def station_spots(self, station_id: str) -> str:
        """``station/{station_id}/spots``."""
        return f"{self.prefix}/station/{check_id(station_id, 'station id')}/spots"

    def all_station_spots(self) -> str:
        """``station/*/spots``."""
        return f"{self.prefix}/station/*/spots"

    def rpc(self, op: str) -> str:
        """The ground-station queryable for request ``op``."""
        return f"{self.prefix}/gs/rpc/{check_id(op, 'rpc op')}"

    def events(self) -> str:
        """The ground-station event stream."""
        return f"{self.prefix}/gs/events"

    def traffic(self) -> str:
        """Where the ground station last heard each UAV (for keeping clear)."""
        return f"{self.prefix}/gs/traffic"

    def alive(self, role: Role, ident: str) -> str:
        """The liveliness token of ``ident`` in ``role``."""
        return f"{self.prefix}/alive/{Role(role)}/{check_id(ident)}"

    def all_alive(self, role: Role) -> str:
        """Wildcard for every liveliness token of ``role``."""
        return f"{self.prefix}/alive/{Role(role)}/*"

    def sim(self, topic: str) -> str:
        """Simulator control topic (e.g. ``fault``)."""
        return f"{self.prefix}/sim/{check_id(topic, 'sim topic')}"

    def owns(self, key: str, kind: str, ident: str) -> bool:
        """Whether ``key`` is a key of ``kind`` ``ident`` (``uav/uav-1/...``,
        ``station/C1/...``): a sample is trusted only as far as the key it
        came on. A key outside the key space belongs to nobody."""
        try:
            parsed = self.parse(key)
        except InvalidKey:
            return False
        return parsed.kind == kind and parsed.ident == ident

    def parse(self, key: str) -> ParsedKey:
        """Split a concrete key of this site; raise :class:`InvalidKey` otherwise."""
        parts = str(key).split("/")
        if len(parts) < 3 or parts[0] != ROOT or parts[1] != self.site:
            raise InvalidKey(f"{key!r} is not a key of site {self.site!r}")
        shape = parts[2:]
        match shape:
            case ["uav", uav_id, topic] if topic in set(UavTopic):
                return ParsedKey(self.site, "uav", check_id(uav_id, "uav id"), topic)
            case ["human", worker_id, "pose"]:
                return ParsedKey(self.site, "human", check_id(worker_id, "worker id"), "pose")
            case ["station", station_id, "spots"]:
                return ParsedKey(self.site, "station", check_id(station_id, "station id"), "spots")
            case ["gs", "rpc", op]:
                return ParsedKey(self.site, "rpc", check_id(op, "rpc op"))
            case ["gs", "events"]:
                return ParsedKey(self.site, "events")
            case ["gs", "traffic"]:
                return ParsedKey(self.site, "traffic")
            case ["alive", role, ident] if role in set(Role):
                return ParsedKey(self.site, "alive", check_id(ident), role)
            case ["sim", topic]:
                return ParsedKey(self.site, "sim", None, check_id(topic, "sim topic"))
        raise InvalidKey(f"{key!r} is not a linecrew key")
