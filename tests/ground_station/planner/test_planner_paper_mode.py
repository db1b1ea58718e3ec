"""``Options(mode="paper")`` is the baseline: never an invalid plan (issue 16, item 7)."""

from __future__ import annotations

import pytest

from ground_station.planner import Options, plan, validate
from linecrew.planner_tools.generator import generate

SIZES = ((2, 3), (3, 4), (3, 8), (4, 12), (5, 20), (6, 30), (10, 60))


@pytest.mark.parametrize(("n_uavs", "n_actions"), SIZES)
def test_paper_mode_plans_validate_on_generated_instances(n_uavs: int, n_actions: int) -> None:
    for seed in range(10):
        problem = generate(n_uavs, n_actions, seed)
        result = plan(problem, Options(mode="paper"))
        assert validate(problem, result) == [], (n_uavs, n_actions, seed)
        assert result.unplaced == (), (n_uavs, n_actions, seed)
