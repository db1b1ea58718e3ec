"""Each package's public API is its sorted ``__all__``, and every name exists."""

from __future__ import annotations

import importlib

import pytest

PACKAGES = [
    "proto",
    "linecrew_runtime.bus",
    "ground_station.store",
    "ground_station.gateway",
    "ground_station.planner",
    "onboard_agent",
    "onboard_agent.autopilot",
    "sim_fleet",
]


@pytest.mark.parametrize("name", PACKAGES)
def test_all_is_sorted_and_resolvable(name):
    module = importlib.import_module(name)
    exported = module.__all__
    assert exported == sorted(exported, key=lambda n: (not n.isupper(), n))
    for attr in exported:
        assert hasattr(module, attr), attr


def test_proto_does_not_import_zenoh():
    import subprocess
    import sys

    code = "import sys, proto; print('zenoh' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
