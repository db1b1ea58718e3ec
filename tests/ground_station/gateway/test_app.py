"""The gateway app in-process over a stand-in ground station
(:mod:`tests.fakes.fleet`): every refusal is its error-tree class's HTTP
status, in the one JSON shape, and the request it refused names its field."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from proto.errors import (
    InvalidAction,
    InvalidTransition,
    RequestTimeout,
    StoreUnavailable,
    ToolOutOfStock,
)
from proto.rpc import CancelAction, SubmitAction
from tests.fakes.fleet import TOKEN, fake_app

INSPECT = {"type": "inspect", "waypoints": [{"position": {"x_m": 0, "y_m": 0, "z_m": 12}}]}


@pytest.fixture
def stand_in():
    app, client = fake_app(uavs=3)
    with TestClient(app, headers={"Authorization": f"Bearer {TOKEN}"}) as http:
        yield http, client


def refused(response, status: int, code: str, field: str | None = None) -> dict:
    body = response.json()
    assert (response.status_code, body["error"], body["field"]) == (status, code, field), body
    assert body["message"]
    return body


def test_an_accepted_action_is_201_and_reaches_the_ground_station(stand_in):
    http, client = stand_in
    response = http.post("/v1/actions", json=INSPECT, headers={"Idempotency-Key": "req-1"})
    assert response.status_code == 201 and response.json()["state"] == "accepted"
    [sent] = client.requests
    assert isinstance(sent, SubmitAction) and sent.request_id == "req-1"


@pytest.mark.parametrize(
    ("refusal", "status"),
    [
        (InvalidAction("no capable UAV", field="action.waypoints"), 422),
        (ToolOutOfStock("every wrench is taken", field="action.tool"), 422),
        (StoreUnavailable("disk full"), 503),
    ],
)
def test_a_ground_station_refusal_keeps_its_code_field_and_status(stand_in, refusal, status):
    http, client = stand_in
    client.refusal = refusal
    refused(http.post("/v1/actions", json=INSPECT), status, refusal.code, refusal.field)


def test_a_cancel_of_an_ended_action_is_409(stand_in):
    http, client = stand_in
    client.refusal = InvalidTransition("action a1 is completed", field="action_id")
    refused(http.delete("/v1/actions/a1"), 409, "invalid_transition", "action_id")
    assert isinstance(client.requests[-1], CancelAction)


def test_a_timed_out_submit_is_503_and_says_which_request_id_to_resend(stand_in):
    http, client = stand_in
    client.refusal = RequestTimeout("no answer in 1.0 s")
    response = http.post("/v1/actions", json=INSPECT, headers={"Idempotency-Key": "req-7"})
    body = refused(response, 503, "request_timeout")
    assert body["request_id"] == "req-7" and "req" in body["message"]


def test_an_unknown_action_is_404(stand_in):
    http, _client = stand_in
    refused(http.get("/v1/actions/nope"), 404, "not_found", "action_id")


def test_a_body_that_breaks_the_schema_is_422_naming_the_field(stand_in):
    http, client = stand_in
    bad = {"type": "inspect", "waypoints": [{"position": {"x_m": "far", "y_m": 0, "z_m": 12}}]}
    body = refused(
        http.post("/v1/actions", json=bad), 422, "invalid_request", "waypoints[0].position.x_m"
    )
    assert "far" not in body["field"]
    refused(http.post("/v1/actions", content=b"{not json"), 422, "invalid_request")
    assert client.requests == []  # nothing reached the ground station


def test_an_unknown_gesture_is_422_and_lists_the_known_ones(stand_in):
    http, _client = stand_in
    body = refused(
        http.post("/v1/gestures", json={"gesture": "wave", "target": "W1"}),
        422,
        "unknown_gesture",
        "gesture",
    )
    assert body["known"] and "wave" not in body["known"]


def test_bad_query_parameters_are_422_naming_them(stand_in):
    http, _client = stand_in
    refused(http.get("/v1/actions", params={"stat": "accepted"}), 422, "invalid_request", "stat")
    refused(http.get("/v1/actions", params={"state": "lost"}), 422, "invalid_request", "state")


def test_no_token_is_401_too_large_is_413_a_wrong_method_is_405(stand_in):
    http, _client = stand_in
    refused(http.get("/v1/fleet", headers={"Authorization": "Bearer wrong"}), 401, "unauthorized")
    huge = {"type": "inspect", "waypoints": [], "pad": "x" * 70_000}
    refused(http.post("/v1/actions", json=huge), 413, "body_too_large")
    refused(http.put("/v1/fleet"), 405, "method_not_allowed")
