"""Settings of one ground station process, built once in ``main``."""

from __future__ import annotations

import dataclasses

from linecrew_runtime.clock import wall_period_s
from linecrew_runtime.settings import EnvSettings


@dataclasses.dataclass(frozen=True, kw_only=True)
class GsConfig(EnvSettings):
    """Ground-station settings (flags override ``LINECREW_GS_*`` variables)."""

    ENV_PREFIX = "LINECREW_GS_"

    scenario: str = "paper"  # shipped scenario name or a scenario file
    db_path: str = "linecrew-gs.db"  # the SQLite store (created if missing)
    gs_id: str = "gs"  # name of this ground station's liveliness token
    store_wait_s: float = 60.0  # wall s to retry a store that cannot write at start
    link_timeout_s: float = 5.0  # silence before a UAV is lost; > the agents' 3 s
    watchdog_period_s: float = 0.1  # how often the watchdog looks
    battery_margin_fraction: float = 0.1  # battery below the plan by this much -> replan
    improve: int = 1  # anytime improvement of the live plan in the background (0: off)
    improve_rounds: int = 200  # local-search rounds per attempt (deterministic)
    improve_margin: float = 0.02  # adopt an improved plan only if better by this fraction
    freeze_horizon_s: float = 30.0  # tasks starting within this (mission s) never change
    improve_attempts: int = 10  # attempts per state at most, while each gains
    session_window_s: float = 10.0  # mission s a planning session serves incremental replans
    improve_delay_s: float = 0.5  # quiet wall seconds after a trigger before improving
    traffic_period_s: float = 0.5  # wall s between two traffic reports (see ``traffic_period``)

    def traffic_period(self, speedup: float) -> float:
        """Wall seconds between traffic reports under ``speedup`` (:func:`wall_period_s`)."""
        return wall_period_s(self.traffic_period_s, speedup)
