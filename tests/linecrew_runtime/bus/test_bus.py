"""The bus over a real router process: pub/sub, asyncio hand-off, queries
with replies, error replies and timeouts, liveliness, malformed samples."""

from __future__ import annotations

import asyncio
import sys
import threading
import time

import pytest
import zenoh

from linecrew_runtime.bus import Bus, BusConfig
from proto import (
    AgentState,
    AgentStatus,
    EventKind,
    GetFleet,
    GetHistory,
    GsEvent,
    HistoryReply,
    KeySpace,
    RequestError,
    RequestTimeout,
    Role,
    Unavailable,
)
from tests.support.processes import free_port, running_alive, wait_until

KEYS = KeySpace()


def status(uav: str, progress: float = 0.0) -> AgentStatus:
    return AgentStatus(uav_id=uav, stamp_s=1.0, state=AgentState.BUSY, progress=progress)


@pytest.fixture
def two_buses(bus_config):
    with Bus.open(bus_config) as a, Bus.open(bus_config) as b:
        yield a, b


@pytest.fixture
def peer(router):
    args = [sys.executable, "-m", "tests.support.peer", "--connect", router, "--name", "p1"]
    token = KEYS.alive(Role.SIM, "p1")
    with running_alive(args, "peer", BusConfig(connect=(router,)), token) as proc:
        yield proc


def test_typed_publish_reaches_a_typed_subscriber(two_buses):
    sender, receiver = two_buses
    got: list[tuple[str, AgentStatus]] = []
    receiver.subscribe(KEYS.all_uavs("status"), AgentStatus, lambda k, m: got.append((k, m)))
    message = status("uav-1", 0.5)
    wait_until(lambda: sender.publish(KEYS.status("uav-1"), message) or got, 10, "delivery")
    assert got[0] == (KEYS.status("uav-1"), message)
    assert receiver.stats.received >= 1


def test_malformed_samples_are_counted_and_dropped_and_delivery_goes_on(two_buses):
    sender, receiver = two_buses
    got: list[AgentStatus] = []
    receiver.subscribe(KEYS.status("uav-1"), AgentStatus, lambda _k, m: got.append(m))
    raw = sender.session.declare_publisher(KEYS.status("uav-1"))
    wait_until(lambda: raw.put(b"\xc1garbage") or receiver.stats.malformed, 10, "garbage seen")
    raw.put(b"")
    sender.publish(KEYS.status("uav-1"), status("uav-1", 0.25))
    wait_until(lambda: got, 10, "a valid message after garbage")
    assert got == [status("uav-1", 0.25)]
    assert receiver.stats.malformed[KEYS.status("uav-1")] >= 2


def test_a_failing_callback_does_not_stop_the_subscriber(two_buses):
    sender, receiver = two_buses
    seen: list[float] = []

    def callback(_key: str, message: AgentStatus) -> None:
        seen.append(message.progress)
        if message.progress == 0.0:
            raise ValueError("boom")

    receiver.subscribe(KEYS.status("u"), AgentStatus, callback)
    wait_until(lambda: sender.publish(KEYS.status("u"), status("u")) or seen, 10, "first")
    sender.publish(KEYS.status("u"), status("u", 1.0))
    wait_until(lambda: 1.0 in seen, 10, "delivery after a failing callback")


def test_async_subscription_hands_samples_to_the_loop(two_buses):
    sender, receiver = two_buses

    async def scenario() -> tuple[str, AgentStatus, int]:
        loop_thread = threading.get_ident()
        async with receiver.subscribe_async(KEYS.status("u2"), AgentStatus) as sub:
            stop = threading.Event()

            def publish_until_stopped() -> None:
                while not stop.wait(0.05):
                    sender.publish(KEYS.status("u2"), status("u2"))

            thread = threading.Thread(target=publish_until_stopped)
            thread.start()
            try:
                key, message = await asyncio.wait_for(sub.get(), 10)
            finally:
                stop.set()
                thread.join()
            return key, message, loop_thread

    key, message, loop_thread = asyncio.run(scenario())
    assert key == KEYS.status("u2") and message == status("u2")
    assert loop_thread == threading.main_thread().ident


def test_query_gets_the_typed_reply_from_another_process(bus_config, peer):
    with Bus.open(bus_config) as bus:
        reply = bus.query(KEYS.rpc("echo"), GetHistory(after_seq=41), HistoryReply, 5.0)
    assert [event.seq for event in reply.events] == [41]


def test_query_gets_a_typed_error_reply(bus_config, peer):
    with Bus.open(bus_config) as bus, pytest.raises(RequestError) as caught:
        bus.query(KEYS.rpc("echo"), GetHistory(limit=13), HistoryReply, 5.0)
    assert (caught.value.code, caught.value.field) == ("unlucky", "limit")
    assert "unlucky" in str(caught.value)


def test_undecodable_request_gets_a_decode_error_reply_and_the_server_keeps_serving(
    bus_config, peer
):
    with Bus.open(bus_config) as bus:
        replies = list(bus.session.get(KEYS.rpc("echo"), payload=b"\x92junk", timeout=5.0))
        assert len(replies) == 1 and replies[0].err is not None
        with pytest.raises(RequestError) as caught:
            bus.query(KEYS.rpc("echo"), GetFleet(), HistoryReply, 5.0)
        assert caught.value.code == "decode_error"
        reply = bus.query(KEYS.rpc("echo"), GetHistory(after_seq=7), HistoryReply, 5.0)
    assert reply.events[0].seq == 7


def test_query_without_a_server_times_out_with_a_clear_error(bus_config):
    with Bus.open(bus_config) as bus, pytest.raises(RequestTimeout, match="no reply"):
        bus.query(KEYS.rpc("nobody"), GetHistory(), HistoryReply, 0.5)


def test_queryable_served_by_asyncio_in_process(two_buses):
    server, client = two_buses

    async def handler(request: GetHistory) -> HistoryReply:
        await asyncio.sleep(0)
        return HistoryReply(events=[])

    async def scenario() -> HistoryReply:
        with server.serve(KEYS.rpc("local"), GetHistory, handler):
            request = GetHistory()
            for _ in range(100):
                try:
                    return await client.query_async(KEYS.rpc("local"), request, HistoryReply, 2.0)
                except RequestTimeout:
                    await asyncio.sleep(0.05)  # the queryable may not be routed yet
        raise AssertionError("queryable never answered")

    assert asyncio.run(scenario()) == HistoryReply(events=[])


def test_a_reply_too_large_for_the_bus_is_an_error_reply_not_silence(two_buses):
    server, client = two_buses
    huge = GsEvent(seq=1, stamp_s=0.0, kind=EventKind.FAULT, detail="x" * (2 << 20))

    async def handler(_request: GetHistory) -> HistoryReply:
        return HistoryReply(events=[huge])

    async def scenario() -> RequestError:
        with server.serve(KEYS.rpc("huge"), GetHistory, handler):
            for _ in range(100):
                try:
                    await client.query_async(KEYS.rpc("huge"), GetHistory(), HistoryReply, 2.0)
                except RequestTimeout:
                    await asyncio.sleep(0.05)  # the queryable may not be routed yet
                except RequestError as exc:
                    return exc
        raise AssertionError("no error reply")

    error = asyncio.run(scenario())
    assert error.code == "encode_error" and "cannot be sent" in error.message


def test_liveliness_sees_a_killed_peer_disappear(bus_config, peer):
    token = KEYS.alive(Role.SIM, "p1")
    changes: list[tuple[str, bool]] = []
    with Bus.open(bus_config) as bus:
        bus.watch_liveliness(KEYS.all_alive(Role.SIM), lambda k, a: changes.append((k, a)))
        wait_until(lambda: (token, True) in changes, 10, "token seen alive")
        started = time.monotonic()
        peer.kill()
        wait_until(lambda: (token, False) in changes, 10, "token seen gone")
        assert time.monotonic() - started < 5.0
        assert token not in bus.alive(KEYS.all_alive(Role.SIM))


def test_closing_a_token_is_seen_by_watchers(two_buses):
    owner, watcher = two_buses
    key = KEYS.alive(Role.AGENT, "uav-9")
    changes: list[tuple[str, bool]] = []
    watcher.watch_liveliness(KEYS.all_alive(Role.AGENT), lambda k, a: changes.append((k, a)))
    token = owner.declare_token(key)
    wait_until(lambda: (key, True) in changes, 10, "token up")
    token.close()
    wait_until(lambda: (key, False) in changes, 10, "token down")


def test_open_without_a_router_gives_up_with_unavailable():
    config = BusConfig(connect=(f"tcp/127.0.0.1:{free_port()}",), connect_attempt_ms=200)
    with pytest.raises(Unavailable, match="no zenoh router"):
        Bus.open(config, wait_s=0.5)


def test_client_waits_for_a_router_that_starts_later():
    port = free_port()
    config = BusConfig(connect=(f"tcp/127.0.0.1:{port}",), connect_attempt_ms=200)
    router_config = BusConfig(mode="router", listen=(f"tcp/127.0.0.1:{port}",))
    opened: list[Bus] = []
    thread = threading.Thread(target=lambda: opened.append(Bus.open(config, wait_s=20)))
    thread.start()
    try:
        with Bus.open(router_config):
            thread.join(20)
            assert opened, "client never connected"
            opened[0].close()
    finally:
        thread.join()


def test_zenoh_config_disables_multicast_and_sets_the_lease():
    config = BusConfig(connect=("tcp/127.0.0.1:1",), lease_ms=500).to_zenoh()
    assert config.get_json("scouting/multicast/enabled") == "false"
    assert config.get_json("transport/link/tx/lease") == "500"
    assert isinstance(config, zenoh.Config)


def test_an_error_reply_from_the_network_is_a_timeout_not_a_server_failure(two_buses):
    """Zenoh answers ``Timeout`` for a query it gave up on (across a cut,
    chaos seed 13): a retryable RequestTimeout (503 at the gateway), not a
    RequestError with no code (500, and the cancel it carried counted lost)."""
    server, client = two_buses
    queryable = server.session.declare_queryable(KEYS.rpc("cut"), lambda q: q.reply_err(b"Timeout"))
    try:
        for _ in range(100):
            with pytest.raises(RequestTimeout) as caught:
                client.query(KEYS.rpc("cut"), GetHistory(), HistoryReply, 2.0)
            if "network" in str(caught.value):
                break  # routed (before that: nobody answered)
        assert "the network answered" in str(caught.value) and "Timeout" in str(caught.value)
        assert caught.value.code == "request_timeout"
    finally:
        queryable.undeclare()
