"""Shared helpers for the planner tests."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from ground_station.planner import Problem, problem_from_obj

FIXTURES = Path(__file__).parent / "fixtures"
EXAMPLES = Path(__file__).parents[3] / "ground_station" / "planner" / "examples"


def load_yaml(path: Path) -> Problem:
    return problem_from_obj(yaml.safe_load(path.read_text()))


@pytest.fixture
def fig6() -> Problem:
    return load_yaml(FIXTURES / "fig6.yaml")


@pytest.fixture
def paper() -> Problem:
    return load_yaml(EXAMPLES / "paper.yaml")
