"""AgentConfig: defaults, LINECREW_AGENT_* variables, flags."""

from __future__ import annotations

import pytest

from onboard_agent import AgentConfig


def test_defaults_follow_the_design():
    config = AgentConfig.from_env({})
    assert config.tick_hz == 10.0
    assert config.agent_link_timeout_s == 3.0
    assert config.battery_full_fraction == 0.95


def test_environment_then_overrides():
    env = {"LINECREW_AGENT_TICK_HZ": "5", "LINECREW_AGENT_COMMAND_RETRIES": "1"}
    config = AgentConfig.from_env(env, tick_hz=20.0, agent_link_timeout_s=None)
    assert config.tick_hz == 20.0
    assert config.command_retries == 1
    assert config.agent_link_timeout_s == 3.0


@pytest.mark.parametrize(
    "env",
    [
        {"LINECREW_AGENT_TICK_HZ": "fast"},
        {"LINECREW_AGENT_TICK_HZ": "0"},
        {"LINECREW_AGENT_BATTERY_FULL_FRACTION": "1.5"},
    ],
)
def test_bad_values_are_refused(env):
    with pytest.raises(ValueError):
        AgentConfig.from_env(env)


@pytest.mark.parametrize(("speedup", "hz"), [(1.0, 5.0), (2.0, 10.0), (10.0, 20.0), (0.5, 5.0)])
def test_telemetry_keeps_its_rate_in_mission_time_up_to_20_hz(speedup, hz):
    """Others steer clear of where a UAV's telemetry says it is: at x10 a
    5 Hz report would be 2 mission seconds (4 m of flight) old."""
    assert AgentConfig().at_speedup(speedup).telemetry_hz == pytest.approx(hz)
