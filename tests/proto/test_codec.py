"""Every message survives the codec; every kind of bad input gives DecodeError."""

from __future__ import annotations

import contextlib
import typing

import msgspec
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import proto
from proto import codec
from proto.errors import DecodeError, EncodeError
from tests.support.strategies import for_type

MESSAGE_TYPES = [
    proto.Telemetry,
    proto.AgentStatus,
    proto.TaskOutcome,
    proto.HumanPose,
    proto.SpotClaim,
    proto.StationSpots,
    proto.Plan,
    proto.GsEvent,
    proto.Site,
    proto.Fleet,
    proto.ErrorReply,
    *typing.get_args(proto.Request),
    *typing.get_args(proto.Reply),
    *typing.get_args(proto.SimFault),
]
UNIONS = [proto.Request, proto.Reply, proto.SimFault]


@pytest.mark.parametrize("message_type", MESSAGE_TYPES, ids=lambda t: t.__name__)
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_every_message_round_trips(message_type, data):
    message = data.draw(for_type(message_type))
    assert codec.decode(codec.encode(message), message_type) == message


@pytest.mark.parametrize("union", UNIONS, ids=["Request", "Reply", "SimFault"])
@settings(max_examples=25, deadline=None)
@given(data=st.data())
def test_tagged_unions_dispatch_to_the_right_type(union, data):
    message = data.draw(for_type(union))
    decoded = codec.decode(codec.encode(message), union)
    assert type(decoded) is type(message)
    assert decoded == message


def test_every_top_level_message_carries_the_schema_version():
    for message_type in MESSAGE_TYPES:
        assert issubclass(message_type, proto.Message), message_type
    raw = msgspec.msgpack.decode(codec.encode(proto.GetFleet()))
    assert raw["schema_version"] == proto.SCHEMA_VERSION


def _plan() -> proto.Plan:
    task = proto.WaitTask(task_id="t1", until_s=12.5)
    return proto.Plan(uav_id="uav-1", epoch=4, tasks=[task])


def test_truncated_bytes_raise_decode_error():
    data = codec.encode(_plan())
    for cut in range(len(data)):
        with pytest.raises(DecodeError):
            codec.decode(data[:cut], proto.Plan)


def test_oversized_payload_is_rejected_before_decoding():
    with pytest.raises(DecodeError, match="over the"):
        codec.decode(b"\x00" * (codec.MAX_MESSAGE_BYTES + 1), proto.Plan)


def test_oversized_message_cannot_be_encoded():
    big = proto.ErrorReply(code="x", message="y" * codec.MAX_MESSAGE_BYTES)
    with pytest.raises(EncodeError):
        codec.encode(big)


def test_wrong_schema_version_is_named():
    future = msgspec.structs.replace(_plan(), schema_version=proto.SCHEMA_VERSION + 1)
    with pytest.raises(DecodeError, match="unsupported schema version"):
        codec.decode(msgspec.msgpack.encode(future), proto.Plan)


def test_wrong_schema_version_with_a_changed_shape_is_named():
    payload = msgspec.msgpack.encode({"schema_version": 99, "uav_id": 7})
    with pytest.raises(DecodeError, match="unsupported schema version 99"):
        codec.decode(payload, proto.Plan)


def test_wrong_type_names_the_field():
    payload = msgspec.msgpack.encode({"schema_version": 1, "uav_id": "u1", "epoch": -1})
    with pytest.raises(DecodeError, match=r"\$\.epoch"):
        codec.decode(payload, proto.Plan)


def test_id_outside_the_key_space_is_rejected():
    payload = msgspec.msgpack.encode({"schema_version": 1, "uav_id": "a/b", "epoch": 1})
    with pytest.raises(DecodeError, match=r"\$\.uav_id"):
        codec.decode(payload, proto.Plan)


def test_fraction_out_of_range_is_rejected():
    status = proto.AgentStatus(uav_id="u1", stamp_s=1.0, state=proto.AgentState.IDLE)
    raw = msgspec.to_builtins(status)
    raw["progress"] = 1.5
    with pytest.raises(DecodeError, match=r"\$\.progress"):
        codec.decode(msgspec.msgpack.encode(raw), proto.AgentStatus)


def test_deep_nesting_is_a_decode_error_not_a_crash():
    with pytest.raises(DecodeError):
        codec.decode(b"\x91" * 100_000 + b"\x01", proto.Plan)


@settings(max_examples=300, deadline=None)
@given(payload=st.binary(max_size=300), target=st.sampled_from(MESSAGE_TYPES + UNIONS))
def test_random_bytes_only_ever_raise_decode_error(payload, target):
    with contextlib.suppress(DecodeError):
        codec.decode(payload, target)


@settings(max_examples=100, deadline=None)
@given(data=st.data())
def test_mutated_messages_only_ever_raise_decode_error(data):
    encoded = bytearray(codec.encode(data.draw(for_type(proto.Plan))))
    index = data.draw(st.integers(0, len(encoded) - 1))
    encoded[index] = data.draw(st.integers(0, 255))
    with contextlib.suppress(DecodeError):
        codec.decode(bytes(encoded), proto.Plan)


def test_decoders_are_built_once_even_when_threads_race_for_them():
    import threading

    class Fresh(proto.Message, frozen=True, kw_only=True):  # a type nobody decoded yet
        plan: proto.Plan
        status: proto.AgentStatus | None = None

    barrier = threading.Barrier(16)
    built: list[object] = []

    def first_use() -> None:
        barrier.wait()
        built.append(codec._decoder(Fresh))

    threads = [threading.Thread(target=first_use) for _ in range(16)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(built) == 16 and all(d is built[0] for d in built)
    message = Fresh(plan=_plan())
    assert codec.decode(codec.encode(message), Fresh) == message


def _telemetry(**changes) -> proto.Telemetry:
    fields = dict(
        uav_id="uav-1",
        stamp_s=1.0,
        position=proto.Point(x_m=1, y_m=2, z_m=3),
        geo=proto.GeoPoint(lat_deg=45, lon_deg=7, alt_m=300),
        battery_wh=100,
        battery_fraction=0.5,
    )
    return proto.Telemetry(**(fields | changes))


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf"), 1e308])
def test_a_non_finite_or_absurd_float_is_refused(bad):
    for message in (
        _telemetry(position=proto.Point(x_m=bad, y_m=0)),
        _telemetry(stamp_s=bad),
        _telemetry(battery_wh=abs(bad)),
        proto.HumanPose(
            worker_id="w1", stamp_s=1, position=proto.Point(x_m=0, y_m=bad), geo=proto.GeoPoint()
        ),
    ):
        with pytest.raises(DecodeError, match="Expected `float`"):
            codec.decode(codec.encode(message), type(message))


def test_strings_on_the_wire_have_length_limits():
    status = dict(uav_id="uav-1", stamp_s=1.0, state=proto.AgentState.IDLE)
    codec.decode(codec.encode(proto.AgentStatus(**status, reason="r" * 4096)), proto.AgentStatus)
    for too_long in (
        proto.AgentStatus(**status, reason="r" * 4097),
        proto.AgentStatus(**status, active_path=["node"] * 65),
        proto.CancelAction(request_id="q" * 129, action_id="a1"),
        proto.CancelAction(request_id="", action_id="a1"),
    ):
        with pytest.raises(DecodeError, match="length"):
            codec.decode(codec.encode(too_long), type(too_long))
