"""Durable state of the ground station (SQLite, WAL, versioned schema)."""

from ground_station.store.migrations import MIGRATIONS, migrate
from ground_station.store.sqlite import Store, StoreUnavailable

__all__ = ["MIGRATIONS", "Store", "StoreUnavailable", "migrate"]
