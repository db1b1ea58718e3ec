"""The operator console in a real browser against a real local fleet (every
process of ``linecrew up``, the paper's site, x10): it loads with the token,
shows the site and the UAVs moving, submits actions through its forms and
follows them on the Gantt and in the table to completion, changes a
priority and cancels, raises alerts for an injected battery fault and a
lost UAV that stay acknowledged across a reload, and says clearly when the
token is wrong. Screenshots go to each test's tmp_path (one to
/tmp/console.png)."""

from __future__ import annotations

import math
import shutil
import time
from urllib.parse import urlsplit

import msgspec
import pytest

from linecrew.launch.local_run import LocalRun, RunOptions
from linecrew_runtime.scenarios import load
from tests.support.processes import wait_until

SPEEDUP = 10.0
PAPER = msgspec.structs.replace(load("paper"), actions=[])
UAVS = [u.id for u in PAPER.fleet.uavs]
TERMINAL = ("completed", "failed", "cancelled")


@pytest.fixture(scope="module")
def run(tmp_path_factory, browser):
    options = RunOptions(speedup=SPEEDUP, run_dir=tmp_path_factory.mktemp("console") / "run")
    with LocalRun(PAPER, options) as fleet:
        yield fleet


@pytest.fixture
def gateway(run):
    return run.gateway()


def open_console(new_page, run, fragment: str | None = None):
    page, log = new_page()
    page.goto(f"{run.url}/#{fragment if fragment is not None else f'token={run.token}'}")
    return page, log


def wait_loaded(page) -> None:
    page.locator("body[data-ready=yes]").wait_for()
    page.locator(f"#map .uav[data-uav='{UAVS[-1]}']").wait_for()


def markers(page) -> dict[str, tuple[float, float]]:
    return page.eval_on_selector_all(
        "#map .uav",
        "els => Object.fromEntries(els.map(e => [e.dataset.uav, [+e.dataset.x, +e.dataset.y]]))",
    )


def row_state(page, action_id: str) -> str | None:
    row = page.locator(f"#actions tr[data-action='{action_id}']")
    return row.get_attribute("data-state") if row.count() else None


def shoot(page, artefacts, name: str, keep: bool = False) -> None:
    path = artefacts / f"{name}.png"
    page.screenshot(path=str(path), full_page=True)
    if keep:
        shutil.copy(path, "/tmp/console.png")


def test_a_wrong_or_missing_token_is_said_clearly(run, new_page, artefacts):
    page, _log = open_console(new_page, run, "token=not-the-token")
    banner = page.locator("#error")
    banner.wait_for()
    assert "Unauthorized (401)" in banner.inner_text()
    assert "#token=" in banner.inner_text()
    assert page.locator("body[data-auth=refused]").count() == 1
    assert page.get_attribute("#api-status", "data-state") == "unauthorized"
    assert page.locator("#map .uav").count() == 0
    shoot(page, artefacts, "bad-token")

    page, _log = open_console(new_page, run, "")  # no token; the prompt is dismissed
    page.locator("#error").wait_for()
    assert "No bearer token" in page.inner_text("#error")


def test_the_console_loads_with_the_token_and_shows_the_site_and_the_fleet(
    run, new_page, artefacts
):
    page, log = open_console(new_page, run)
    wait_loaded(page)
    assert "token" not in page.url  # taken out of the address bar...
    stored = page.evaluate("() => sessionStorage.getItem('linecrew.console.token')")
    assert stored == run.token  # ...and kept for this tab only
    assert page.locator("#map .tower").count() == len(PAPER.site.towers)
    assert page.locator("#map .line").count() == len(PAPER.site.lines)
    assert page.locator("#map .station").count() == len(PAPER.site.stations)
    assert page.locator("#map .station .pad").count() == sum(s.pads for s in PAPER.site.stations)
    assert page.locator("#map .toolstation").count() == len(PAPER.site.tool_stations)
    assert page.locator("#map .worker").count() == len(PAPER.site.workers)
    assert sorted(markers(page)) == UAVS
    page.locator(f"#fleet tbody tr[data-uav='{UAVS[-1]}']").wait_for()
    assert page.locator("#fleet tbody tr").count() == len(UAVS)
    page.locator("#stream-status[data-state=live]").wait_for()

    page.click(f"#map .uav[data-uav='{UAVS[1]}']")  # select: map, fleet table, Gantt row
    page.locator(f"#map .uav.selected[data-uav='{UAVS[1]}']").wait_for()
    page.locator(f"#fleet tr.selected[data-uav='{UAVS[1]}']").wait_for()
    page.locator(f"#gantt .gantt-row.selected[data-uav='{UAVS[1]}']").wait_for()
    shoot(page, artefacts, "loaded")

    origin = urlsplit(run.url).netloc
    assert {urlsplit(r.url).netloc for r in log.requests if r.url.startswith("http")} == {origin}
    api_calls = [r for r in log.requests if urlsplit(r.url).path.startswith("/v1/")]
    assert api_calls and all(
        r.headers.get("authorization") == f"Bearer {run.token}" for r in api_calls
    )
    assert not log.errors, log.errors

    page.goto(run.url + "/")  # a reload without the fragment keeps the session's token
    wait_loaded(page)


def test_actions_from_the_forms_are_planned_flown_and_completed(run, new_page, gateway, artefacts):
    page, log = open_console(new_page, run)
    wait_loaded(page)

    def submit(form: str, fill: dict[str, str], selects: dict[str, str] | None = None) -> str:
        for name, value in fill.items():
            page.fill(f"#form-{form} [name={name}]", value)
        for name, value in (selects or {}).items():
            page.select_option(f"#form-{form} [name={name}]", value)
        previous = page.get_attribute("#form-result", "data-action") or ""
        page.click(f"#form-{form} button[type=submit]")
        page.wait_for_function(
            "prev => (document.querySelector('#form-result').dataset.action || '') !== prev",
            arg=previous,
        )
        assert "accepted" in page.inner_text("#form-result")
        return page.get_attribute("#form-result", "data-action")

    inspect = submit("inspect", {"waypoints": "0,7,5,5; 7,7,5,5; 7,14,5,5"})
    deliver = submit("deliver", {}, {"tool": "tp-hammer/hammer", "worker": "W3"})
    watch = submit("monitor", {"duration": "60", "k": "1"}, {"worker": "W1"})
    for action_id in (inspect, deliver, watch):
        page.locator(f"#actions tr[data-action='{action_id}']").wait_for()

    # the Gantt shows their bars, coloured by kind, labelled with the action
    page.locator(f"#gantt .bar.kind-inspect[data-action='{inspect}']").first.wait_for()
    page.locator(f"#gantt .bar.kind-monitor[data-action='{watch}']").first.wait_for()
    assert page.locator("#gantt .gantt-now").count() == 1
    assert page.inner_text("#gantt-epoch").startswith("latest epoch")
    page.wait_for_function("() => document.getElementById('plan-quality').dataset.objective")
    assert page.inner_text("#plan-quality").startswith("objective ")
    bar_title = page.locator(f"#gantt .bar[data-action='{watch}'] title").first.text_content()
    assert watch in bar_title and "monitor" in bar_title

    # the markers move, with a planned route ahead
    first = markers(page)

    def moved() -> set[str]:
        now = markers(page)
        return {u for u in UAVS if math.dist(first[u], now[u]) > 0.3}

    wait_until(moved, 30, "a UAV marker moves", period_s=0.2)
    assert page.locator("#map .route[points*=' ']").count() >= 1
    assert page.locator(f"#map .wp[data-action='{inspect}']").count() == 3
    shoot(page, artefacts, "flying", keep=True)

    def all_completed() -> bool:
        return all(row_state(page, a) in TERMINAL for a in (inspect, deliver, watch))

    wait_until(all_completed, 150, "the three actions end", period_s=0.5)
    assert [row_state(page, a) for a in (inspect, deliver, watch)] == ["completed"] * 3
    page.locator(f"#map .wp.wp-done[data-action='{inspect}']").nth(2).wait_for()
    progress = gateway.call("GET", f"/v1/actions/{watch}")["progress"]
    shown = page.locator(f"#actions tr[data-action='{watch}'] .c-progress").inner_text().strip()
    assert shown == f"{round(progress * 100)}%"  # a monitor ends within a small tail
    assert page.locator("#map .track[points*=' ']").count() >= 1  # flown tracks kept
    shoot(page, artefacts, "completed")
    assert not log.errors, log.errors


def test_a_priority_is_changed_and_an_action_cancelled_from_the_table(
    run, new_page, gateway, artefacts
):
    page, log = open_console(new_page, run)
    wait_loaded(page)
    body = {"type": "monitor", "worker_id": "W2", "uavs": 1, "duration_s": 900}
    action_id = gateway.call("POST", "/v1/actions", json=body)["action_id"]
    row = page.locator(f"#actions tr[data-action='{action_id}']")
    row.wait_for()
    row.locator("input[data-role=priority]").fill("4")
    row.locator("button[data-role=set-priority]").click()
    wait_until(
        lambda: gateway.call("GET", f"/v1/actions/{action_id}")["action"]["priority"] == 4.0,
        10,
        "the priority changes",
    )
    page.locator("#form-result", has_text=f"{action_id} priority 4").wait_for()
    assert row.locator("input[data-role=priority]").input_value() == "4"
    row.locator("button[data-role=cancel]").click()
    page.locator(f"#actions tr[data-action='{action_id}'][data-state=cancelled]").wait_for()
    assert gateway.call("GET", f"/v1/actions/{action_id}")["state"] == "cancelled"
    assert row.locator("button[data-role=cancel]").is_hidden()
    shoot(page, artefacts, "cancelled")
    assert not log.errors, log.errors


def test_an_operator_holds_a_uav_and_gives_it_back_from_the_fleet_table(
    run, new_page, gateway, artefacts
):
    page, log = open_console(new_page, run)
    wait_loaded(page)
    uav = UAVS[0]
    row = page.locator(f"#fleet tr[data-uav='{uav}']")
    row.locator("button[data-command=hold]").click()
    page.locator(f"#fleet tr[data-uav='{uav}'][data-control=hold]").wait_for()
    assert row.locator("button[data-command=hold]").get_attribute("aria-pressed") == "true"
    fleet = {u["uav_id"]: u for u in gateway.call("GET", "/v1/fleet")}
    assert fleet[uav]["control"] == "hold"
    shoot(page, artefacts, "held")
    row.locator("button[data-command=resume]").click()
    page.locator(f"#fleet tr[data-uav='{uav}'][data-control='']").wait_for()
    assert {u["uav_id"]: u for u in gateway.call("GET", "/v1/fleet")}[uav]["control"] is None
    assert not log.errors, log.errors


def flying_with(gateway, action_id: str) -> str | None:
    """The UAV flying a task of ``action_id``, if any."""
    for uav in gateway.call("GET", "/v1/fleet"):
        task = (uav.get("status") or {}).get("task_id") or ""
        telemetry = uav.get("telemetry") or {}
        if task.startswith(action_id) and telemetry.get("flight_state") == "flying":
            return uav["uav_id"]
    return None


def alert_keys(page, where: str, title: str, uav: str | None = None) -> list[str]:
    return page.eval_on_selector_all(
        f"{where} li.alert",
        "(els, [title, uav]) => els.filter(e => e.querySelector('.title').textContent === title"
        " && (!uav || e.querySelector('.detail').textContent.startsWith(uav + ':')))"
        ".map(e => e.dataset.key)",
        [title, uav],
    )


def test_a_battery_fault_raises_an_alert_that_stays_acknowledged(run, new_page, gateway, artefacts):
    page, log = open_console(new_page, run)
    wait_loaded(page)
    body = {"type": "monitor", "worker_id": "W3", "uavs": 1, "duration_s": 300}
    action_id = gateway.call("POST", "/v1/actions", json=body)["action_id"]
    victim: list = [None]

    def found() -> str | None:
        victim[0] = flying_with(gateway, action_id)
        return victim[0]

    wait_until(found, 60, "a UAV flies the monitor", period_s=0.2)
    uav = victim[0]

    page.locator("#sim-panel").wait_for()  # the gateway offers /v1/sim/faults
    page.select_option("#form-fault [name=kind]", "battery")
    page.select_option("#form-fault [name=target]", uav)
    page.fill("#form-fault [name=fraction]", "0.12")
    page.click("#form-fault button[type=submit]")
    page.locator("#fault-result[data-ok=yes]").wait_for()
    assert "battery set to 12%" in page.inner_text("#fault-result")

    page.wait_for_function(
        "uav => [...document.querySelectorAll('#alerts li.alert')].some(e =>"
        " e.querySelector('.title').textContent === 'Battery low'"
        " && e.querySelector('.detail').textContent.startsWith(uav + ':'))",
        arg=uav,
    )
    [battery] = alert_keys(page, "#alerts", "Battery low", uav)[:1]
    assert alert_keys(page, "#alerts", "Fault injected", uav)
    alert = page.locator(f"#alerts li[data-key='{battery}']")
    assert alert.get_attribute("data-severity") == "warning"
    shoot(page, artefacts, "battery-alert")

    alert.locator("button[data-role=ack]").click()
    page.locator(f"#alerts-acked li[data-key='{battery}']").wait_for(state="attached")
    assert page.locator(f"#alerts li[data-key='{battery}']").count() == 0
    counted, listed = page.evaluate(
        "() => [+document.querySelector('#alert-count').dataset.count,"
        " document.querySelectorAll('#alerts li.alert').length]"
    )
    assert counted == listed  # the header counts what is still to acknowledge

    page.reload()
    wait_loaded(page)
    page.locator(f"#alerts-acked li[data-key='{battery}']").wait_for(state="attached")
    time.sleep(1.5)  # fleet polls and the event replay have run again: still acknowledged
    assert page.locator(f"#alerts li[data-key='{battery}']").count() == 0
    assert alert_keys(page, "#alerts", "Fault injected", uav), "other alerts stay until acked"
    gateway.call("DELETE", f"/v1/actions/{action_id}")
    assert not log.errors, log.errors


def test_a_lost_uav_raises_a_critical_alert_keyed_by_its_event(run, new_page, gateway, artefacts):
    page, log = open_console(new_page, run)
    wait_loaded(page)
    uav = UAVS[0]
    gateway.call("POST", "/v1/sim/faults", json={"type": "kill", "uav_id": uav})
    page.wait_for_function(
        "uav => [...document.querySelectorAll('#alerts li.sev-critical')].some(e =>"
        " e.querySelector('.detail').textContent.startsWith(uav + ':'))",
        arg=uav,
        timeout=30_000,
    )
    keys = alert_keys(page, "#alerts", "UAV lost", uav) + alert_keys(
        page, "#alerts", "UAV crashed", uav
    )
    assert keys and all(k.isdigit() for k in keys)  # the event's seq
    shoot(page, artefacts, "lost")
    for key in keys:
        page.click(f"#alerts li[data-key='{key}'] button[data-role=ack]")
    page.reload()
    wait_loaded(page)
    for key in keys:  # replayed from the event history, still acknowledged
        page.locator(f"#alerts-acked li[data-key='{key}']").wait_for(state="attached")
        assert page.locator(f"#alerts li[data-key='{key}']").count() == 0
    page.locator(
        f"#fleet tr[data-uav='{uav}'][data-state=lost], "
        f"#fleet tr[data-uav='{uav}'][data-state=failed]"
    ).first.wait_for()
    assert not log.errors, log.errors


def test_a_worker_who_moves_is_drawn_where_the_tracker_sees_them(run, new_page, gateway, artefacts):
    page, log = open_console(new_page, run)
    wait_loaded(page)
    worker = PAPER.site.workers[0]
    start = worker.position
    page.locator(f"#map .worker[data-id='{worker.id}']:not(.untracked)").wait_for()
    there = {"x_m": start.x_m + 6.0, "y_m": start.y_m - 4.0, "z_m": start.z_m}
    body = {"type": "move_worker", "worker_id": worker.id, "position": there}
    gateway.call("POST", "/v1/sim/faults", json=body)
    try:
        page.wait_for_function(
            "([id, x, y]) => { const e = document.querySelector(`#map .worker[data-id='${id}']`);"
            " return e && Math.hypot(+e.dataset.x - x, +e.dataset.y - y) < 0.01; }",
            arg=[worker.id, there["x_m"], there["y_m"]],
        )
        [view] = [
            w for w in gateway.call("GET", "/v1/workers")["workers"] if w["worker_id"] == worker.id
        ]
        assert view["tracked"] and view["position"]["x_m"] == there["x_m"]
        shoot(page, artefacts, "worker-moved")
    finally:
        back = {"x_m": start.x_m, "y_m": start.y_m, "z_m": start.z_m}
        gateway.call("POST", "/v1/sim/faults", json={**body, "position": back})
    assert not log.errors, log.errors


def test_the_api_docs_render_from_the_gateway_alone(run, new_page, artefacts):
    page, log = new_page()
    origin = urlsplit(run.url).netloc
    page.route(  # a control room without internet: nothing but the gateway answers
        "**/*",
        lambda route: (
            route.continue_() if urlsplit(route.request.url).netloc == origin else route.abort()
        ),
    )
    page.goto(f"{run.url}/docs")
    page.locator(".swagger-ui .info .title").wait_for()
    assert "linecrew gateway" in page.inner_text(".swagger-ui .info .title")
    page.locator(".opblock-summary-path[data-path='/v1/actions']").first.wait_for()
    assert page.locator(".auth-wrapper .authorize").count() == 1  # the bearer scheme
    assert {urlsplit(r.url).netloc for r in log.requests} == {origin}
    assert not log.errors, log.errors
    shoot(page, artefacts, "docs")
