"""A thin typed layer over Zenoh shared by every linecrew process."""

from linecrew_runtime.bus.config import DEFAULT_ROUTER, BusConfig
from linecrew_runtime.bus.session import Bus, Declared
from linecrew_runtime.bus.stats import BusStats

__all__ = ["DEFAULT_ROUTER", "Bus", "BusConfig", "BusStats", "Declared"]
