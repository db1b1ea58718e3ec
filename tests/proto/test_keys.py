"""Key expressions: build/parse round trip and rejection of ids that would
break the key space."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from proto.base import ID_PATTERN
from proto.errors import InvalidKey
from proto.keys import KeySpace, ParsedKey, Role, UavTopic

ids = st.from_regex(ID_PATTERN, fullmatch=True)
BAD_IDS = ["", "a/b", "*", "**", "$*", "a*", "@uav", "x?y", "x#y", "a b", "é", "x" * 65]


@given(site=ids, uav=ids, topic=st.sampled_from(list(UavTopic)))
def test_uav_keys_round_trip(site, uav, topic):
    keys = KeySpace(site)
    parsed = keys.parse(keys.uav(uav, topic))
    assert (parsed.site, parsed.kind, parsed.ident, parsed.topic) == (site, "uav", uav, topic)


@given(ident=ids, role=st.sampled_from(list(Role)))
def test_liveliness_keys_round_trip(ident, role):
    keys = KeySpace()
    parsed = keys.parse(keys.alive(role, ident))
    assert (parsed.kind, parsed.ident, parsed.topic) == ("alive", ident, role)


def test_other_keys_round_trip():
    keys = KeySpace("s1")
    assert keys.parse(keys.human_pose("W1")) == ParsedKey("s1", "human", "W1", "pose")
    assert keys.parse(keys.rpc("submit")).ident == "submit"
    assert keys.parse(keys.events()).kind == "events"
    assert keys.parse(keys.sim("fault")).topic == "fault"


def test_keys_have_the_documented_shape():
    keys = KeySpace("site-a")
    assert keys.telemetry("uav-1") == "linecrew/site-a/uav/uav-1/telemetry"
    assert keys.plan("uav-1") == "linecrew/site-a/uav/uav-1/plan"
    assert keys.all_uavs(UavTopic.STATUS) == "linecrew/site-a/uav/*/status"
    assert keys.alive(Role.AGENT, "uav-1") == "linecrew/site-a/alive/agent/uav-1"
    assert keys.rpc("submit") == "linecrew/site-a/gs/rpc/submit"


@pytest.mark.parametrize("bad", BAD_IDS)
def test_ids_that_break_the_key_space_are_rejected(bad):
    keys = KeySpace()
    for build in (keys.telemetry, keys.human_pose, keys.rpc, keys.sim):
        with pytest.raises(InvalidKey):
            build(bad)
    with pytest.raises(InvalidKey):
        KeySpace(bad)


@pytest.mark.parametrize(
    "key",
    [
        "linecrew/other/uav/u1/telemetry",
        "linecrew/default/uav/u1/bogus",
        "linecrew/default/uav/*/telemetry",
        "linecrew/default",
        "zenoh/default/uav/u1/plan",
        "linecrew/default/alive/nobody/u1",
    ],
)
def test_foreign_or_wildcard_keys_do_not_parse(key):
    with pytest.raises(InvalidKey):
        KeySpace().parse(key)


def test_a_key_is_owned_only_by_the_kind_and_id_it_names():
    keys = KeySpace("s1")
    assert keys.owns(keys.telemetry("uav-1"), "uav", "uav-1")
    assert not keys.owns(keys.telemetry("uav-2"), "uav", "uav-1")
    assert keys.owns(keys.station_spots("C1"), "station", "C1")
    assert not keys.owns(keys.station_spots("C1"), "uav", "C1")
    assert not keys.owns("linecrew/s1/uav/*/telemetry", "uav", "*")  # a wildcard: nobody's
    assert not keys.owns("elsewhere/uav-1", "uav", "uav-1")
