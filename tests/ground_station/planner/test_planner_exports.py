"""The package root re-exports its API with a sorted ``__all__``."""

from __future__ import annotations

import ground_station.planner as planner


def test_all_is_sorted_and_resolvable() -> None:
    assert planner.__all__ == sorted(planner.__all__)
    for name in planner.__all__:
        assert hasattr(planner, name), name


def test_core_api_is_exported() -> None:
    for name in ("plan", "validate", "Session", "Problem", "Solution", "PlanningProblemError"):
        assert name in planner.__all__
