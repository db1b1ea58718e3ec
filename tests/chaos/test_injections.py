"""The chaos runner's cancels, edits, motor and GPS faults, read-only store
and clock jumps: the schedule draws them purely from the seed; the store's
disk made read-only on a real fleet refuses new actions with 503 and keeps
every acknowledged one (after the heal and a ground-station restart); a
short seeded run of a mix of them ends with zero violations."""

from __future__ import annotations

import itertools
import time
import types

import httpx
import msgspec
import pytest

from ground_station.gateway.bodies import ModifyBody
from linecrew.chaos import ChaosOptions, ChaosRunner, Checker, make_schedule
from linecrew.chaos.faults import ProcessFaults
from linecrew.chaos.injections import Context, cancel, disk, edit
from linecrew.chaos.report import render
from linecrew.chaos.schedule import Injection
from linecrew.launch.local_run import LocalRun, RunOptions
from linecrew_runtime.clock import OFFSET_ENV, mission_clock
from linecrew_runtime.process import Shutdown
from linecrew_runtime.scenarios import load
from proto import Role
from tests.support.processes import wait_until

PAPER = load("paper")
NEW_KINDS = {"cancel", "edit", "motor", "gps", "disk", "clock_jump"}
# a focused mix (new actions and the new kinds only) and a seed whose 40 s
# schedule has each, its cancel and edit soon after their action's submission
# and its motor fault soon after a submission (a UAV is likely in the air)
FOCUS = {
    "action": 3.0,
    "cancel": 1.2,
    "edit": 1.2,
    "motor": 1.0,
    "gps": 1.0,
    "disk": 0.8,
    "clock_jump": 0.8,
}
RUN_SEED, RUN_DURATION_S = 358, 40.0


def _schedules(duration_s: float = 90.0, seeds: int = 40) -> list[list[Injection]]:
    return [make_schedule(seed, duration_s, PAPER) for seed in range(seeds)]


def test_the_new_kinds_are_drawn_and_a_seed_still_names_one_schedule():
    kinds = {i.kind for s in _schedules() for i in s}
    assert kinds >= NEW_KINDS
    assert make_schedule(RUN_SEED, RUN_DURATION_S, PAPER, mix=FOCUS) == make_schedule(
        RUN_SEED, RUN_DURATION_S, PAPER, mix=FOCUS
    )


def test_cancels_and_edits_name_an_action_scheduled_before_them():
    for schedule in _schedules():
        earlier: set[str] = set()
        for injection in schedule:
            if injection.kind == "action":
                earlier.add(injection.params["action_id"])
            elif injection.kind in {"cancel", "edit"}:
                assert injection.target in earlier, injection
                assert injection.hold_s > 0  # re-read later


def test_edits_are_bodies_the_gateway_takes():
    edits = [i for s in _schedules() for i in s if i.kind == "edit"]
    assert {("action" in i.params["change"]) for i in edits} == {True, False}
    for injection in edits:
        change = msgspec.convert(injection.params["change"], ModifyBody)
        assert change.priority is not None or change.action is not None


def test_one_motor_fault_at_most_and_faults_target_uavs():
    uavs = {u.id for u in PAPER.fleet.uavs}
    for schedule in _schedules(duration_s=300.0):
        assert sum(i.kind == "motor" for i in schedule) <= 1
        for injection in schedule:
            if injection.kind in {"motor", "gps", "clock_jump"}:
                assert injection.target in uavs
            if injection.kind == "gps":
                assert 0 < injection.hold_s <= 3.0
            if injection.kind == "clock_jump":
                assert 2 <= abs(injection.params["offset_s"]) <= 30


def test_the_store_fault_and_clock_jumps_are_disruptions_that_never_overlap():
    for schedule in _schedules():
        disruptive = [i for i in schedule if i.kind in {"disk", "clock_jump", "kill_gs"}]
        for before, after in itertools.pairwise(disruptive):
            assert before.at_s + before.hold_s < after.at_s
        for injection in schedule:
            if injection.kind == "disk":  # its probe is a fresh action of the run
                assert injection.params["action_id"].startswith("chaos-")


def test_the_mission_clock_takes_an_offset_from_the_environment(monkeypatch):
    monkeypatch.setenv(OFFSET_ENV, "-25")
    assert abs(mission_clock(10.0)() - (time.time() * 10.0 - 25)) < 1.0
    monkeypatch.setenv(OFFSET_ENV, "soon")
    with pytest.raises(ValueError, match=OFFSET_ENV):
        mission_clock(1.0)
    monkeypatch.delenv(OFFSET_ENV)
    assert mission_clock(1.0) is time.time


def _inspect(action_id: str) -> dict:
    tower = PAPER.site.towers[0].position
    point = {"x_m": tower.x_m + 3, "y_m": tower.y_m + 3, "z_m": max(4.0, tower.z_m)}
    return {
        "type": "inspect",
        "action_id": action_id,
        "request_id": f"req-{action_id}",
        "waypoints": [{"position": point, "service_s": 2.0}],
    }


def test_a_read_only_store_refuses_new_actions_with_503_and_keeps_every_acknowledged_one(
    tmp_path,
):
    options = RunOptions(speedup=10.0, run_dir=tmp_path / "run", register=False)
    with LocalRun(PAPER, options) as run, run.http(timeout_s=5.0) as http:
        assert http.post("/v1/actions", json=_inspect("kept-1")).status_code == 201
        checker = Checker(PAPER.fleet.reserve_fraction)
        ctx = Context(
            run=run,
            faults=ProcessFaults(run),
            http=http,
            checker=checker,
            speedup=10.0,
            now=time.monotonic,
            submit=lambda body: str(http.post("/v1/actions", json=body).status_code),
        )
        applied = types.SimpleNamespace(note="")
        probe = Injection(at_s=0.0, kind="disk", hold_s=3.0, params=_inspect("probe"))
        heal = disk(probe, ctx, applied)
        if heal is None:
            pytest.skip(f"the store's files cannot be made immutable here: {applied.note}")
        try:
            assert "probe answered 503 store_unavailable, then 503" in applied.note
            refused = http.post("/v1/actions", json=_inspect("late"))
            assert refused.status_code == 503
            assert refused.json()["error"] == "store_unavailable"
            listed = {r["action_id"] for r in http.get("/v1/actions").json()}
            assert listed == {"kept-1"}  # reads go on; nothing refused was kept
            assert http.delete("/v1/actions/kept-1").status_code == 503  # nor a cancel
        finally:
            heal()
        assert "writable again" in applied.note and "FAILED" not in applied.note
        for action_id in ("probe", "late"):  # the same requests, retried, are accepted now
            answer = http.post("/v1/actions", json=_inspect(action_id))
            assert answer.status_code == 201, answer.text
        assert checker.violations == []

        faults = ProcessFaults(run)
        faults.kill("ground-station")
        faults.restart("ground-station")
        key = run.keys.alive(Role.GROUND_STATION, "gs")
        wait_until(lambda: key in run.bus.alive(key, 0.5), 60.0, "the gs back")

        def listed_after_restart() -> set[str] | None:
            response = http.get("/v1/actions")
            return {r["action_id"] for r in response.json()} if response.is_success else None

        wait_until(listed_after_restart, 30.0, "the restarted gs answering", period_s=0.5)
        assert listed_after_restart() == {"kept-1", "probe", "late"}
        names = {c.name for c in run.supervisor.children}
        assert all(faults.child(name).alive() for name in names)  # nothing died of it


def test_a_short_seeded_run_with_every_new_kind_reports_zero_violations(tmp_path):
    schedule = make_schedule(RUN_SEED, RUN_DURATION_S, PAPER, mix=FOCUS)
    assert {i.kind for i in schedule} == NEW_KINDS | {"action"}, schedule
    options = ChaosOptions(
        seed=RUN_SEED,
        duration_s=RUN_DURATION_S,
        drain_s=45.0,
        run_dir=tmp_path / "run",
        scenario_actions=False,
    )
    runner = ChaosRunner(PAPER, options, Shutdown())
    runner.schedule = schedule
    started = time.monotonic()
    result = runner.run()
    report = render(result)
    print(report)
    assert result.ok, report
    notes = {a.injection.kind: a.note for a in result.applied}
    assert "probe answered 503 store_unavailable" in notes["disk"], report
    assert notes["motor"].startswith("HTTP 200"), report  # a UAV in the air fell
    assert "restarted as pid" in notes["clock_jump"], report
    assert time.monotonic() - started < 100.0


def _context(answer) -> tuple[Context, types.SimpleNamespace]:
    """A context whose gateway answers with ``answer(request)`` (one component alone)."""
    checker = Checker(reserve_fraction=0.2)
    checker.accepted("a1", 0.0)
    http = httpx.Client(base_url="http://gw", transport=httpx.MockTransport(answer))
    ctx = Context(
        run=None, faults=None, http=http, checker=checker, speedup=10.0, now=lambda: 1.0,
        submit=lambda body: "accepted",
    )  # fmt: skip
    return ctx, types.SimpleNamespace(note="")


def _record(state: str, **action) -> dict:
    return {"action_id": "a1", "state": state, "action": {"type": "inspect", **action}}


def test_a_cancel_answered_404_or_not_kept_is_a_violation():
    ctx, applied = _context(lambda r: httpx.Response(404, json={"error": "not_found"}))
    assert cancel(Injection(at_s=0, kind="cancel", target="a1"), ctx, applied) is None
    assert [v.invariant for v in ctx.checker.violations] == ["cancel_kept"]
    states = iter(["cancelled", "in_progress"])
    ctx, applied = _context(lambda r: httpx.Response(200, json=_record(next(states))))
    recheck = cancel(Injection(at_s=0, kind="cancel", target="a1"), ctx, applied)
    assert not ctx.checker.violations and recheck is not None
    recheck()
    assert [v.detail for v in ctx.checker.violations] == [
        "a1 re-read in_progress: {'type': 'inspect'}"
    ]


def test_an_edit_is_applied_or_refused_with_a_reason_and_a_later_one_wins():
    edit_to = lambda priority: Injection(  # noqa: E731
        at_s=0, kind="edit", target="a1", params={"change": {"priority": priority}}
    )
    ctx, applied = _context(lambda r: httpx.Response(409, json={"error": "invalid_transition"}))
    assert edit(edit_to(2), ctx, applied) is None and not ctx.checker.violations
    ctx, applied = _context(lambda r: httpx.Response(422, text="no"))
    edit(edit_to(2), ctx, applied)
    assert [v.invariant for v in ctx.checker.violations] == ["edit_kept"]  # no reason given
    priorities = iter([2, 4, 4, 4])  # the two answers, then both re-reads
    ctx, applied = _context(
        lambda r: httpx.Response(200, json=_record("planned", priority=next(priorities)))
    )
    first, second = edit(edit_to(2), ctx, applied), edit(edit_to(4), ctx, applied)
    first()  # reads 4: the later edit, not a lost one
    second()
    assert not ctx.checker.violations
    ctx, applied = _context(lambda r: httpx.Response(200, json=_record("planned", priority=1)))
    edit(edit_to(3), ctx, applied)
    assert [v.invariant for v in ctx.checker.violations] == ["edit_kept"]  # answered unchanged
