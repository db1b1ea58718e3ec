"""A thin typed layer over Zenoh shared by every linecrew process."""

from linecrew.bus.config import DEFAULT_ROUTER, BusConfig
from linecrew.bus.session import Bus, Declared
from linecrew.bus.stats import BusStats

__all__ = ["DEFAULT_ROUTER", "Bus", "BusConfig", "BusStats", "Declared"]
