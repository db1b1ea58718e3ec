"""The ground station: the mission manager (actions in, per-UAV plans out),
the planner (``ground_station.planner``, a pure library), the fleet monitor,
the durable SQLite store and the operator REST gateway
(``ground_station.gateway``). The Zenoh router process is
``linecrew_runtime.bus.router``."""
