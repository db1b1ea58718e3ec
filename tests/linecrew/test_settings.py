"""Every process reads its settings one way (linecrew_runtime.settings): the same
variable names, conversions, precedence and error message."""

from __future__ import annotations

import argparse
import dataclasses

import pytest

from ground_station.config import GsConfig
from ground_station.gateway.settings import GatewaySettings
from linecrew_runtime.bus import BusConfig
from linecrew_runtime.process import DEFAULT_SITE, RunSettings, common_parser, site_id, start
from linecrew_runtime.settings import EnvSettings, variable
from onboard_agent.config import AgentConfig

CONFIGS = [AgentConfig, GsConfig, GatewaySettings, BusConfig, RunSettings]
SAMPLES = {"float": ("0.5", 0.5), "int": ("2.0", 2), "bool": ("off", False), "str": ("x", "x")}


def read_fields(cls: type[EnvSettings]) -> list[tuple[str, str]]:
    """(field, variable) of each field of ``cls`` that a variable sets."""
    fields = [(f.name, variable(cls, f)) for f in dataclasses.fields(cls)]
    return [(name, var) for name, var in fields if var is not None]


@pytest.mark.parametrize("cls", CONFIGS)
def test_every_process_config_uses_the_one_loader(cls):
    assert issubclass(cls, EnvSettings)
    assert "from_env" not in vars(cls)
    assert all(var.startswith("LINECREW_") for _, var in read_fields(cls))


@pytest.mark.parametrize("cls", CONFIGS)
def test_the_same_text_converts_the_same_way_in_every_config(cls):
    kinds = {f.name: f.type for f in dataclasses.fields(cls)}  # "float", "int", ...
    env = {}
    expected = {}
    for name, var in read_fields(cls):
        if kinds[name] in SAMPLES:
            env[var], expected[name] = SAMPLES[kinds[name]]
    assert expected
    config = cls.from_env(env)
    assert {name: getattr(config, name) for name in expected} == expected


@pytest.mark.parametrize(
    ("cls", "var", "kind"),
    [
        (AgentConfig, "LINECREW_AGENT_TICK_HZ", "float"),
        (GsConfig, "LINECREW_GS_IMPROVE_ROUNDS", "int"),
        (GatewaySettings, "LINECREW_GATEWAY_PORT", "int"),
        (BusConfig, "LINECREW_ZENOH_LEASE_MS", "int"),
        (RunSettings, "LINECREW_SPEEDUP", "float"),
    ],
)
def test_a_bad_value_names_its_variable_the_same_way_everywhere(cls, var, kind):
    with pytest.raises(ValueError, match=rf"^{var}='fast': Expected `{kind}`"):
        cls.from_env({var: "fast"})


def test_overrides_beat_the_environment_and_none_and_empty_mean_unset():
    env = {"LINECREW_GS_LINK_TIMEOUT_S": "7", "LINECREW_GS_GS_ID": "", "LINECREW_GS_IMPROVE": "0"}
    config = GsConfig.from_env(env, link_timeout_s=9.0, improve=None)
    assert (config.link_timeout_s, config.gs_id, config.improve) == (9.0, "gs", 0)


def test_lists_are_comma_separated_and_a_field_may_name_its_variable():
    env = {"LINECREW_ZENOH_CONNECT": "tcp/a:1, tcp/b:2", "LINECREW_ZENOH_CONFIG": "z.json5"}
    config = BusConfig.from_env(env)
    assert config.connect == ("tcp/a:1", "tcp/b:2") and config.config_file == "z.json5"
    with pytest.raises(ValueError, match="LINECREW_ZENOH_MODE='hub'"):
        BusConfig.from_env({"LINECREW_ZENOH_MODE": "hub"})


def test_resolved_gateway_values_have_no_variable():
    env = {"LINECREW_GATEWAY_TOKEN": "t", "LINECREW_GATEWAY_SITE": "s"}
    settings = GatewaySettings.from_env(env)
    assert (settings.token, settings.site) == ("", "default")


def started(monkeypatch: pytest.MonkeyPatch, **env: str) -> argparse.Namespace:
    """The flags of a process started without any, under ``env``."""
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    monkeypatch.setattr("linecrew_runtime.process.configure_logging", lambda *_: None)
    args = common_parser("test", "").parse_args([])
    start(args, "test")
    return args


def test_every_process_takes_the_site_and_speedup_the_same_way(monkeypatch):
    args = started(monkeypatch, LINECREW_SITE="plant-7", LINECREW_SPEEDUP="4")
    assert (args.site, args.speedup) == ("plant-7", 4.0)
    assert site_id() == "plant-7" and site_id("other") == "other"
    monkeypatch.delenv("LINECREW_SITE")
    assert site_id() == DEFAULT_SITE


def test_a_bad_run_variable_stops_the_process_with_status_2(monkeypatch):
    with pytest.raises(SystemExit) as stopped:
        started(monkeypatch, LINECREW_SPEEDUP="fast")
    assert stopped.value.code == 2
