"""The console's pure pieces, run in the browser from the served modules:
the SSE frame parser, the waypoint syntax of the inspect form, and the
fault bodies of the simulation panel (which must decode as the proto's
``SimFault``, kind for kind with ``linecrew fault``)."""

from __future__ import annotations

import msgspec
import pytest

from linecrew_runtime.fault_kinds import FAULT_KINDS
from proto.sim import SimFault
from tests.fakes.fleet import TOKEN, big_site, fake_app, serving


@pytest.fixture(scope="module")
def url():
    app, _client = fake_app(uavs=2)
    with serving(app) as base:
        yield base


@pytest.fixture
def page(new_page, url):
    page, log = new_page()
    page.goto(f"{url}/#token={TOKEN}")
    page.locator("body[data-ready=yes]").wait_for()
    yield page
    assert not log.errors, log.errors


def test_sse_frames_are_parsed_across_chunks(page):
    frames, rest = page.evaluate(
        """async () => {
          const { parseFrames } = await import('/console/api.js');
          const got = [];
          const push = (f) => got.push(f);
          let buffer = parseFrames(': connected\\n\\nid: 3\\nevent: fault\\ndata: {"seq"', push);
          buffer = parseFrames(buffer + ': 3}\\n\\nid: 4\\ndata: a\\ndata: b\\n\\nid: 5', push);
          return [got, buffer];
        }"""
    )
    assert frames == [
        {"id": "3", "event": "fault", "data": ['{"seq": 3}']},
        {"id": "4", "event": "message", "data": ["a", "b"]},
    ]
    assert rest == "id: 5"


def test_waypoints_are_typed_as_x_y_z_with_an_optional_service_time(page):
    parsed = page.evaluate(
        """async () => {
          const { parseWaypoints } = await import('/console/actions.js');
          const bad = [];
          for (const text of ['', '1,2', '1,2,x', '1,2,3,4,5']) {
            try { parseWaypoints(text); bad.push(null); } catch (e) { bad.push(e.message); }
          }
          return { ok: parseWaypoints(' -5,15,3 ; 7,7,3,5;'), bad };
        }"""
    )
    assert parsed["ok"] == [
        {"position": {"x_m": -5, "y_m": 15, "z_m": 3}, "service_s": 0},
        {"position": {"x_m": 7, "y_m": 7, "z_m": 3}, "service_s": 5},
    ]
    assert all(parsed["bad"]), parsed["bad"]


def test_every_fault_of_the_panel_is_a_sim_fault_of_the_cli(page):
    bodies = page.evaluate(
        """async () => {
          const { FAULTS } = await import('/console/sim.js');
          return Object.fromEntries(Object.entries(FAULTS).map(([kind, [, fields, build]]) => [
            kind,
            build(kind === 'move-worker' ? 'W1' : 'uav-1',
                  Object.fromEntries(fields.map(([name, , value]) => [name, value]))),
          ]));
        }"""
    )
    assert set(bodies) == set(FAULT_KINDS)
    for kind, body in bodies.items():
        fault = msgspec.convert(body, SimFault)
        cli = FAULT_KINDS[kind][2](
            "W1" if kind == "move-worker" else "uav-1",
            [str(v) for v in _values(body)],
        )
        assert fault == cli, kind


def _values(body: dict) -> list[float]:
    """The CLI's positional values for a panel body, in the CLI's order."""
    if "position" in body:
        return [body["position"][k] for k in ("x_m", "y_m", "z_m")]
    return [body[k] for k in ("fraction", "multiplier", "duration_s") if k in body]


def test_workers_are_drawn_where_tracked_and_a_uav_holding_off_says_for_whom(page):
    site = big_site()
    first, second = site.workers[:2]
    page.locator(f"#map .worker[data-id='{first.id}']:not(.untracked)").wait_for()
    where = page.eval_on_selector_all(
        "#map .worker",
        "els => Object.fromEntries(els.map(e => [e.dataset.id, [+e.dataset.x, +e.dataset.y]]))",
    )
    assert where[first.id] == [first.position.x_m + 3.0, first.position.y_m]  # the tracked pose
    assert where[second.id] == [second.position.x_m, second.position.y_m]  # the site's, faded
    assert page.locator(f"#map .worker.untracked[data-id='{second.id}']").count() == 1
    title = page.text_content(f"#map .worker[data-id='{first.id}'] title")
    assert "tracked" in title and "not tracked" not in title
    page.locator("#map .uav.holding[data-uav='uav-2']").wait_for()
    assert page.locator("#map .uav.holding").count() == 1
    state = page.text_content("#fleet tr[data-uav='uav-2'] .c-state")
    assert state == "busy · holding off for uav-1"
