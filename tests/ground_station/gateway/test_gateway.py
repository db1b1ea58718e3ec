"""The gateway process against a real ground station over a real router:
the REST contract, auth, bad input, gestures, SSE, metrics, and a 503 when
the ground station is gone."""

from __future__ import annotations

import json
import signal
import subprocess
import threading

import httpx
import pytest

from ground_station.gateway.main import STREAMS_GRACE_S
from linecrew_runtime.bus import Bus
from proto import EventKind, GsEvent, KeySpace
from tests.ground_station.gateway.conftest import TOKEN
from tests.support.processes import wait_until

DELIVER = {"type": "deliver", "tool": "wrench", "tool_station_id": "tp-wrench", "worker_id": "W1"}


def test_auth_is_required_on_the_api_but_not_on_health(gateway):
    base = str(gateway.base_url)
    assert httpx.get(f"{base}/v1/actions").status_code == 401
    wrong = httpx.get(f"{base}/v1/actions", headers={"Authorization": "Bearer nope"})
    assert wrong.status_code == 401 and wrong.json()["error"] == "unauthorized"
    health = httpx.get(f"{base}/healthz")
    assert health.status_code == 200 and health.json()["ground_station"] == "up"


def test_submit_is_idempotent_and_actions_can_be_read_changed_and_cancelled(gateway):
    body = {**DELIVER, "request_id": "op-1"}
    first = gateway.post("/v1/actions", json=body)
    assert first.status_code == 201, first.text
    record = first.json()
    assert record["state"] == "accepted"  # no UAV present in this test to plan it on
    assert record["action"]["tool"] == "wrench"
    again = gateway.post("/v1/actions", json=body)
    assert again.json()["action_id"] == record["action_id"]
    assert [a["action_id"] for a in gateway.get("/v1/actions").json()] == [record["action_id"]]
    one = gateway.get(f"/v1/actions/{record['action_id']}")
    assert one.status_code == 200 and one.json()["request_id"] == "op-1"
    patched = gateway.patch(f"/v1/actions/{record['action_id']}", json={"priority": 7})
    assert patched.status_code == 200 and patched.json()["action"]["priority"] == 7
    cancelled = gateway.delete(f"/v1/actions/{record['action_id']}")
    assert cancelled.json()["state"] == "cancelled"
    assert (
        gateway.get("/v1/actions", params={"state": "cancelled"}).json()[0]["state"] == "cancelled"
    )


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ({"type": "monitor", "worker_id": "W1", "duration_s": "long"}, "duration_s"),
        ({"type": "monitor", "worker_id": "W9", "duration_s": 30}, "action.worker_id"),
        ({"type": "inspect", "waypoints": []}, "action.waypoints"),
        ({"type": "fly-to-mars"}, "type"),
    ],
)
def test_invalid_bodies_are_422_naming_the_field(gateway, body, field):
    response = gateway.post("/v1/actions", json=body)
    assert response.status_code == 422, response.text
    assert response.json()["field"] == field


def test_not_json_unknown_action_and_oversized_bodies(gateway):
    assert gateway.post("/v1/actions", content=b"{nope").status_code == 422
    assert gateway.get("/v1/actions/no-such").status_code == 404
    huge = gateway.post("/v1/actions", content=b"x" * 100_000)
    assert huge.status_code == 413


def test_gestures_map_to_actions_and_unknown_ones_list_the_vocabulary(gateway):
    made = gateway.post("/v1/gestures", json={"gesture": "bring-wrench", "target": "W1"})
    assert made.status_code == 201 and made.json()["action"]["type"] == "deliver"
    tower = gateway.post("/v1/gestures", json={"gesture": "inspect-tower", "target": "T2"})
    assert len(tower.json()["action"]["waypoints"]) == 4
    unknown = gateway.post("/v1/gestures", json={"gesture": "moonwalk", "target": "W1"})
    assert unknown.status_code == 422 and "bring-wrench" in unknown.json()["known"]
    nowhere = gateway.post("/v1/gestures", json={"gesture": "watch-me", "target": "W9"})
    assert nowhere.status_code == 422 and nowhere.json()["field"] == "target"


def test_fleet_plan_metrics_and_openapi(gateway):
    gateway.post("/v1/actions", json=DELIVER)
    fleet = gateway.get("/v1/fleet").json()
    assert sorted(u["uav_id"] for u in fleet) == ["uav-1", "uav-2", "uav-3"]
    assert all(u["state"] == "lost" for u in fleet)  # no agents in this test
    assert gateway.get("/v1/plan").status_code == 200
    quality = gateway.get("/v1/plan/quality").json()
    assert set(quality) == {"objective_s", "improved_ago_s", "gap_to_best"}
    assert quality["improved_ago_s"] is None  # nothing improved with no UAV up
    metrics = gateway.get("/metrics").text
    assert "linecrew_ground_station_up 1" in metrics and "linecrew_gs_replans" in metrics
    spec = gateway.get("/openapi.json").json()
    assert "/v1/actions" in spec["paths"] and "DeliverAction" in spec["components"]["schemas"]


def test_events_stream_replays_history_then_follows(gateway):
    gateway.post("/v1/actions", json=DELIVER)
    seen: list[dict] = []
    with gateway.stream("GET", "/v1/events", params={"after_seq": 0}) as stream:
        for line in stream.iter_lines():
            if line.startswith("data: "):
                seen.append(json.loads(line[6:]))
            if any(e["kind"] == "action_accepted" for e in seen):
                break
    assert seen[0]["seq"] == 1


def test_a_forged_event_on_the_bus_neither_reaches_the_stream_nor_hides_real_ones(
    gateway, bus_config
):
    """Live frames are read from the ground station's log: a sample on the
    events key with a huge ``seq`` is only a wake-up."""
    forged = GsEvent(seq=2**52, stamp_s=0.0, kind=EventKind.ACTION_ACCEPTED, detail="forged")
    stream_client = httpx.Client(
        base_url=gateway.base_url, headers=gateway.headers, timeout=10.0
    )  # a read timeout (no keep-alive within 10 s) fails the test rather than hanging it
    seen: list[dict] = []
    with Bus.open(bus_config) as bus, stream_client.stream("GET", "/v1/events") as stream:
        lines = stream.iter_lines()
        assert next(line for line in lines if line.startswith(":")) == ": connected"
        bus.publish(KeySpace().events(), forged)
        assert gateway.post("/v1/actions", json=DELIVER).status_code == 201
        for line in lines:
            if line.startswith("data: "):
                seen.append(json.loads(line[6:]))
            if any(e["kind"] == "action_accepted" for e in seen):
                break
    assert all(e["detail"] != "forged" and e["seq"] < 100 for e in seen), seen


def test_fault_without_a_simulator_is_503_not_a_hang(gateway):
    response = gateway.post("/v1/sim/faults", json={"type": "motor", "uav_id": "uav-1"})
    assert response.status_code == 503 and "no reply" in response.json()["message"]


def test_ground_station_down_gives_503_with_a_clear_message(gateway, gs):
    gs.stop()
    response = gateway.get("/v1/actions")
    assert response.status_code == 503
    assert response.json()["error"] == "request_timeout"
    wait_until(lambda: gateway.get("/healthz").json()["ground_station"] == "down", 10, "down")
    point = {"position": {"x_m": 0, "y_m": 7, "z_m": 3}}
    refused = gateway.post("/v1/actions", json={"type": "inspect", "waypoints": [point]})
    body = refused.json()
    assert refused.status_code == 503 and body["error"] == "request_timeout"
    assert body["request_id"] and "with this request_id" in body["message"]  # how to find out


def test_a_list_larger_than_a_bus_message_is_served_whole_or_by_page(gateway):
    """24 inspections of 900 waypoints are over 1 MiB on the bus: the list
    still answers (fetched page by page), and by page with a cursor."""
    points = [
        {"position": {"x_m": -20 + (i % 40), "y_m": i // 40, "z_m": 5}, "service_s": 1}
        for i in range(900)
    ]
    ids = []
    for _ in range(24):
        reply = gateway.post("/v1/actions", json={"type": "inspect", "waypoints": points})
        assert reply.status_code == 201, reply.text
        ids.append(reply.json()["action_id"])
    whole = gateway.get("/v1/actions")
    assert whole.status_code == 200 and [a["action_id"] for a in whole.json()] == ids
    seen, cursor = [], None
    while True:
        params = {"limit": 5, **({"cursor": cursor} if cursor else {})}
        page = gateway.get("/v1/actions", params=params)
        assert page.status_code == 200 and 0 < len(page.json()) <= 5
        seen += [a["action_id"] for a in page.json()]
        cursor = page.headers.get("Next-Cursor")
        if cursor is None:
            break
    assert seen == ids
    bogus = gateway.get("/v1/actions", params={"state": "bogus"})
    assert bogus.status_code == 422 and bogus.json()["field"] == "state"
    unknown = gateway.get("/v1/actions", params={"cursor": "act-nope"})
    assert unknown.status_code == 422 and unknown.json()["field"] == "cursor"


@pytest.mark.parametrize(
    ("method", "path", "params", "status", "error", "field"),
    [
        ("GET", "/v1/nowhere", {}, 404, "not_found", None),
        ("PUT", "/v1/actions", {}, 405, "method_not_allowed", None),
        ("GET", "/v1/actions", {"limit": "many"}, 422, "invalid_request", "limit"),
    ],
)
def test_the_framework_s_own_errors_come_in_the_documented_shape(
    gateway, method, path, params, status, error, field
):
    response = gateway.request(method, path, params=params)
    body = response.json()
    assert response.status_code == status and set(body) >= {"error", "message", "field"}, body
    assert (body["error"], body["field"]) == (error, field) and "detail" not in body


def test_an_open_event_stream_does_not_keep_the_gateway_from_stopping(gateway_process):
    """An event stream never ends by itself: on SIGTERM the gateway cuts it
    after its grace and exits (it waited for it forever, so a killed
    ``linecrew up`` left its gateway running)."""
    proc, base = gateway_process
    opened, ended = threading.Event(), threading.Event()

    def follow() -> None:
        headers = {"Authorization": f"Bearer {TOKEN}"}
        try:
            with httpx.stream("GET", f"{base}/v1/events", headers=headers, timeout=None) as r:
                opened.set()
                for _line in r.iter_lines():
                    pass
        except httpx.HTTPError:
            pass
        ended.set()

    threading.Thread(target=follow, daemon=True).start()
    wait_until(opened.is_set, 10, "the stream open")
    proc.popen.send_signal(signal.SIGTERM)
    try:
        proc.popen.wait(STREAMS_GRACE_S + 15)
    except subprocess.TimeoutExpired:
        raise AssertionError("the gateway still runs with a stream open") from None
    wait_until(ended.is_set, 10, "the stream cut")
