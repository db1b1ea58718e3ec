"""The planner's offline tools, above the engine (:mod:`ground_station.planner`):
the ``linecrew plan`` / ``linecrew bench planner`` front ends, Gantt text
rendering, the instance generator and the reference solvers (OR-Tools)."""
