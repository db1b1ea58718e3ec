"""The running fleet does what the paper promises, proven by the simulator's
ground truth: k-UAV monitoring, hand-over without a gap, tools delivered
as named (and refused when none is left), physically absurd requests
refused, a UAV killed mid-monitor replaced. Every process is real; x10."""

from __future__ import annotations

import itertools
import math

import msgspec
import pytest

from linecrew.chaos.faults import ProcessFaults
from linecrew.client.gateway import GatewayError
from linecrew.launch.local_run import LocalRun, RunOptions
from linecrew_runtime.scenarios import load
from proto import EventKind
from proto.spots import spot_positions
from tests.e2e.truth import TruthLog

SPEEDUP = 10.0
PAPER = msgspec.structs.replace(load("paper"), actions=[])
SAFETY = PAPER.site.safety
W1, W2 = PAPER.site.worker("W1").position, PAPER.site.worker("W2").position
UNSAFE = ("ground_contact", "people_proximity", "off_pad_landing")


@pytest.fixture
def truth(tmp_path):
    with LocalRun(PAPER, RunOptions(speedup=SPEEDUP, run_dir=tmp_path / "run")) as run:
        yield TruthLog(run)


def monitor(worker: str, k: int, duration_s: float, standoff_m: float = 4.0) -> dict:
    return {
        "type": "monitor",
        "worker_id": worker,
        "uavs": k,
        "standoff_m": standoff_m,
        "duration_s": duration_s,
    }


def flown_together(truth: TruthLog, worker: str, k: int, duration_s: float) -> float:
    """Submit a k-UAV monitor, wait for its end; the seconds the simulator saw
    k UAVs on the ring around the worker at once."""
    truth.samples.clear()
    action_id = truth.submit(monitor(worker, k, duration_s))["action_id"]
    truth.until(f"the k = {k} monitor ends", lambda: truth.finished(action_id), 150)
    assert truth.action(action_id)["state"] == "completed", truth.action(action_id)
    where = PAPER.site.worker(worker).position
    covered, _gap = truth.coverage(where, 4.0, SAFETY.monitor_height_m, k)
    return covered


def test_k2_then_k3_monitoring_starts_together_and_covers_the_whole_duration(truth):
    assert flown_together(truth, "W2", 2, 120) >= 0.95 * 120
    assert flown_together(truth, "W1", 3, 90) >= 0.95 * 90
    assert not truth.violations(*UNSAFE)
    epochs = [e for e in truth.events() if e.kind == EventKind.PLAN_CHANGED]
    assert len(epochs) < 40, f"{len(epochs)} plan changes for two monitors: thrashing"


def test_a_monitor_longer_than_one_battery_is_handed_over_and_recorded_as_flown(truth):
    """1,500 s of W2 with hand-overs: no gap, and the seconds the ground
    station records as monitored are those the simulator saw (within 2 %)."""
    duration = 1500.0
    long = truth.submit(monitor("W2", 1, duration))["action_id"]
    truth.until("the long monitor ends", lambda: truth.finished(long), 420)
    record = truth.action(long)
    assert record["state"] == "completed", record
    covered, gap = truth.coverage(W2, 4.0, SAFETY.monitor_height_m, 1)
    assert covered >= 0.97 * duration, (covered, gap)
    # what was recorded was flown, and what was flown for the action (the
    # ring may stay held a little past its end) was recorded
    assert abs(record["monitored_s"] - min(covered, duration)) <= 0.02 * duration, (
        record,
        covered,
    )
    assert gap <= 5.0, f"{gap:.1f} s without a UAV watching W2"
    assert len(truth.watchers(W2, 4.0, SAFETY.monitor_height_m)) >= 2
    handovers = [e for e in truth.events() if e.kind == EventKind.HANDOVER]
    assert len(handovers) >= 2, "hand-over events name who relieved whom"
    assert not truth.violations(*UNSAFE)


def test_tools_arrive_as_named_and_an_exhausted_tool_or_an_underground_point_is_refused(truth):
    wrench = truth.submit(
        {"type": "deliver", "tool": "wrench", "tool_station_id": "tp-wrench", "worker_id": "W1"}
    )["action_id"]
    hammer = truth.submit(
        {"type": "deliver", "tool": "hammer", "tool_station_id": "tp-hammer", "worker_id": "W3"}
    )["action_id"]
    with pytest.raises(GatewayError) as refused:
        truth.submit(
            {"type": "deliver", "tool": "wrench", "tool_station_id": "tp-wrench", "worker_id": "W2"}
        )
    assert refused.value.status == 422 and refused.value.body["error"] == "tool_out_of_stock"
    assert refused.value.body["field"] == "action.tool"
    with pytest.raises(GatewayError) as underground:
        truth.submit(
            {"type": "inspect", "waypoints": [{"position": {"x_m": 0, "y_m": 7, "z_m": -3}}]}
        )
    assert underground.value.status == 422
    assert underground.value.body["field"] == "action.waypoints[0].position.z_m"

    truth.until("both deliveries end", lambda: truth.finished(wrench, hammer), 150)
    assert truth.action(wrench)["state"] == truth.action(hammer)["state"] == "completed"
    delivered = {(d.tool, d.worker_id) for d in truth.samples[-1].state.deliveries}
    assert delivered == {("wrench", "W1"), ("hammer", "W3")}
    assert not truth.violations(*UNSAFE)
    # a pick's replan changes no plan: one made before telemetry showed the
    # tool held planned the pick again, which the agent "completed" at once,
    # and so on (at least one changed plan per pick, up to 61)
    picks = [
        e.detail
        for e in truth.events()
        if e.kind == EventKind.REPLAN and ".pick completed" in e.detail
    ]
    assert sum(d.count(".pick completed") for d in picks) <= 1, picks


def test_a_uav_killed_mid_monitor_is_declared_lost_and_another_takes_the_slot(truth):
    watch = truth.submit(monitor("W2", 1, 240))["action_id"]

    def on_station() -> set[str]:
        return truth.watching(truth.samples[-1], W2, 4.0, SAFETY.monitor_height_m)

    [victim] = truth.until("a UAV watches W2", on_station, 60)
    truth.gateway.call("POST", "/v1/sim/faults", json={"type": "kill", "uav_id": victim})
    killed_at = truth.samples[-1].sim_s
    truth.until("the monitor ends", lambda: truth.finished(watch), 200)
    assert truth.action(watch)["state"] == "completed", truth.action(watch)
    lost = [e for e in truth.events() if e.uav_id == victim]
    assert any(e.kind in (EventKind.UAV_LOST, EventKind.UAV_CRASHED) for e in lost), lost
    after = [s for s in truth.samples if s.sim_s > killed_at]
    others = set().union(*(truth.watching(s, W2, 4.0, SAFETY.monitor_height_m) for s in after))
    assert others - {victim}, "another UAV took the slot after the kill"


def test_a_k2_watcher_that_falls_leaves_the_other_on_its_slot_and_its_seconds_counted(truth):
    """Motors fail on one of two UAVs watching W2 (the other has deliveries
    to make after it): the other goes on watching
    from where it is (never flown across the ring to the fallen one's slot),
    a newcomer takes the free slot, and the survivor's seconds stay
    counted: the action's progress falls back by at most the fallen UAV's
    share (a UAV's seconds count when its segment ends, and a loss voids
    them), and it ends about when what was left of it is flown."""
    duration_s = 180.0
    watch = truth.submit(monitor("W2", 2, duration_s))["action_id"]
    for tool, station, worker in (("wrench", "tp-wrench", "W1"), ("hammer", "tp-hammer", "W3")):
        body = {"tool": tool, "tool_station_id": station, "worker_id": worker}
        truth.submit({"type": "deliver", **body})  # for uav-1, the one with a gripper
    progress: list[float] = []

    def watched_for(seconds: float) -> bool:
        progress.append(truth.action(watch)["progress"])
        return progress[-1] * duration_s >= seconds

    truth.until("both watch W2 for 60 s", lambda: watched_for(60.0), 120)
    sample = truth.samples[-1]
    pair = sorted(truth.watching(sample, W2, 4.0, SAFETY.monitor_height_m))
    assert len(pair) == 2, pair
    survivor = "uav-1" if "uav-1" in pair else pair[0]  # the one with deliveries to come
    [victim] = set(pair) - {survivor}
    kept = _xyz(_at(sample, survivor))
    truth.gateway.call("POST", "/v1/sim/faults", json={"type": "motor", "uav_id": victim})
    fell_at, at_fall = sample.sim_s, progress[-1]
    left_s = (1.0 - at_fall) * duration_s
    truth.until("the monitor ends", lambda: watched_for(duration_s) or truth.finished(watch), 150)
    assert truth.action(watch)["state"] == "completed", truth.action(watch)
    fall_back = max((a - b for a, b in itertools.pairwise(progress)), default=0.0)
    assert fall_back <= at_fall / 2 + 0.02, progress  # at most the fallen UAV's share
    ended_at = truth.samples[-1].sim_s
    assert ended_at - fell_at <= left_s + 120.0, (fell_at, left_s, ended_at)
    on_ring = [
        s
        for s in truth.samples
        if s.sim_s > fell_at and survivor in truth.watching(s, W2, 4.0, SAFETY.monitor_height_m)
    ]
    assert on_ring, "the survivor went on watching"
    moved = max(math.dist(_xyz(_at(s, survivor)), kept) for s in on_ring)
    assert moved < 1.5, f"{survivor} moved {moved:.1f} m along the ring"
    assert not truth.violations(*UNSAFE)


def test_work_asked_while_the_autopilots_warm_up_waits_for_them_then_flies(tmp_path):
    """Agents report not ready (not failed) while their autopilots warm up;
    the ground station gives them no work until they are ready, then they
    fly it: no vehicle arms before the warm-up ends, nothing fails."""
    warmup_s = 200.0  # 20 s of wall time at x10: well past the start-up
    options = RunOptions(speedup=SPEEDUP, run_dir=tmp_path / "run", warmup_s=warmup_s)
    with LocalRun(PAPER, options) as run:
        truth = TruthLog(run)
        assert truth.sample().sim_time_s < warmup_s
        point = {"position": {"x_m": -5, "y_m": 10, "z_m": 8}}
        action_id = truth.submit({"type": "inspect", "waypoints": [point]})["action_id"]
        truth.until("the inspection done", lambda: truth.finished(action_id), 240)
        assert truth.action(action_id)["state"] == "completed"
        armed = [s.sim_s for s in truth.samples if any(v.armed for v in s.state.vehicles)]
        assert armed and min(armed) >= warmup_s
        kinds = [(e.kind, e.uav_id) for e in truth.events()]
        for uav in (u.id for u in PAPER.fleet.uavs):
            assert (EventKind.UAV_STATE, uav) in kinds  # said not ready, not lost or failed
            assert (EventKind.UAV_LOST, uav) not in kinds
            not_ready = kinds.index((EventKind.UAV_STATE, uav))
            assert (EventKind.UAV_BACK, uav) in kinds[not_ready:]  # ready: it got work again


def test_two_monitors_of_one_worker_are_flown_on_opposite_sides(truth):
    """Two k = 1 monitoring actions of W2 at once: the simulator sees their
    UAVs hold opposite points of the ring, never one point (each action has
    its own bearing)."""
    first = truth.submit(monitor("W2", 1, 90))["action_id"]
    second = truth.submit(monitor("W2", 1, 90))["action_id"]
    truth.until("both monitors end", lambda: truth.finished(first, second), 150)
    assert truth.action(first)["state"] == truth.action(second)["state"] == "completed"
    height = W2.z_m + SAFETY.monitor_height_m
    slots = [(W2.x_m + 4.0, W2.y_m, height), (W2.x_m - 4.0, W2.y_m, height)]  # 0 and 180 deg
    both_held, shared = 0, 0
    for sample in truth.samples:
        at = [
            [v.uav_id for v in sample.state.vehicles if math.dist(_xyz(v.position), slot) < 1.5]
            for slot in slots
        ]
        both_held += all(at)
        shared += any(len(held) > 1 for held in at)
    assert both_held > 20, "the two slots were hardly held together"
    assert shared == 0, f"two UAVs at one slot in {shared} samples"
    assert not truth.violations(*UNSAFE)


def _xyz(p) -> tuple[float, float, float]:
    return (p.x_m, p.y_m, p.z_m)


def test_a_hung_agent_s_replacement_is_not_sent_to_where_it_hovers(truth):
    """SIGSTOP the agent of the UAV watching W2: its autopilot hovers on at
    the slot. The ground station declares it lost and moves the slot: the
    replacement watches from the other side of W2, never at the hung UAV."""
    watch = truth.submit(monitor("W2", 1, 240))["action_id"]

    def on_station() -> set[str]:
        """UAVs hovering at W2's ring for the watch: there in the last two
        samples, 2 s or more apart, within 1 m of where they were (another
        may only be flying past: a relief sent to the far side of W2 crosses
        the ring on its way)."""
        last = truth.samples[-1]
        before = [s for s in truth.samples if s.sim_s <= last.sim_s - 2.0]
        if not before:
            return set()
        ring = truth.watching(last, W2, 4.0, SAFETY.monitor_height_m)
        ring &= truth.watching(before[-1], W2, 4.0, SAFETY.monitor_height_m)
        ring = {u for u in ring if math.dist(_xyz(_at(last, u)), _xyz(_at(before[-1], u))) < 1.0}
        return ring & truth.working_on(watch) if ring else ring

    [victim] = truth.until("a UAV watches W2", on_station, 60)
    faults = ProcessFaults(truth.run)
    faults.cut(f"agent-{victim}")  # on loopback: SIGSTOP
    try:
        [relief] = truth.until("another UAV watches W2", lambda: on_station() - {victim}, 90)
        since = truth.samples[-1].sim_s
        truth.until("it holds there 10 s", lambda: truth.samples[-1].sim_s > since + 10, 30)
    finally:
        faults.heal_all()
    holding = [s for s in truth.samples if s.sim_s > since + 5]
    apart = [math.dist(_xyz(_at(s, victim)), _xyz(_at(s, relief))) for s in holding]
    assert all(relief in truth.watching(s, W2, 4.0, SAFETY.monitor_height_m) for s in holding)
    assert min(apart) > 6.0, f"the relief holds {min(apart):.1f} m from the hung UAV"
    truth.until("the monitor ends", lambda: truth.finished(watch), 200)
    assert truth.action(watch)["state"] == "completed", truth.action(watch)
    assert not truth.violations("separation", *UNSAFE)


def test_a_ground_station_frozen_4_s_mid_monitor_ends_with_the_monitor_completed(truth):
    """SIGSTOP the ground station for 4 s (40 mission s) while a UAV watches
    W2: the agents see it gone, the ground station sees them silent; once it
    runs again they agree and the monitor is flown to the end."""
    watch = truth.submit(monitor("W2", 1, 200))["action_id"]

    def on_station() -> set[str]:
        return truth.watching(truth.samples[-1], W2, 4.0, SAFETY.monitor_height_m)

    truth.until("a UAV watches W2", on_station, 60)
    faults = ProcessFaults(truth.run)
    faults.cut("ground-station")  # on loopback: SIGSTOP
    try:
        frozen_at = truth.samples[-1].sim_s
        truth.until("4 s frozen", lambda: truth.samples[-1].sim_s > frozen_at + 40, 30)
    finally:
        faults.heal_all()
    truth.until("the monitor ends", lambda: truth.finished(watch), 300)
    record = truth.action(watch)
    assert record["state"] == "completed", record
    covered, _gap = truth.coverage(W2, 4.0, SAFETY.monitor_height_m, 1)
    assert covered >= record["monitored_s"] - 0.02 * 200, (covered, record)
    assert not truth.violations(*UNSAFE)


def _at(sample, uav_id: str):
    return next(v.position for v in sample.state.vehicles if v.uav_id == uav_id)


def test_emergency_landings_never_put_two_uavs_on_one_spot(truth):
    """Three UAVs watch W3, beside C2 (uav-2's home spot, 2 shared pads):
    kill -9 the ground station. Each agent's emergency lands it at the
    nearest station with a spot granted to it: uav-2 on its own, the others
    on C2's shared spots; never two on one spot, never one on top of
    another, never on another UAV's home spot."""
    truth.submit(monitor("W3", 3, 200))
    w3 = PAPER.site.worker("W3").position
    truth.until(
        "three UAVs watch W3",
        lambda: len(truth.watching(truth.samples[-1], w3, 4.0, SAFETY.monitor_height_m)) == 3,
        90,
    )
    ProcessFaults(truth.run).kill("ground-station")
    truth.until(
        "all three landed",
        lambda: all(v.state == "landed" for v in truth.samples[-1].state.vehicles),
        120,
    )
    spots = {s.id: spot_positions(s, PAPER.fleet) for s in PAPER.site.stations}
    where = {}
    for v in truth.samples[-1].state.vehicles:
        station, spot = min(
            ((sid, i) for sid, points in spots.items() for i in range(len(points))),
            key=lambda k: math.dist(_xyz(v.position), _xyz(spots[k[0]][k[1]])),
        )
        assert math.dist(_xyz(v.position), _xyz(spots[station][spot])) < 1.0, v
        where[v.uav_id] = (station, spot)
    assert len(set(where.values())) == 3, where
    assert where["uav-2"] == ("C2", 0), where
    assert {where["uav-1"], where["uav-3"]} == {("C2", 1), ("C2", 2)}, where
    assert not truth.violations("separation", "off_pad_landing", *UNSAFE)


def test_an_operator_holds_a_watching_uav_sends_it_home_and_gives_it_back(truth):
    """Hold the UAV watching W2: it hovers where it is while another takes
    over W2 on another side; return: it lands on a spot at home; resume:
    the planner has it again. The monitor is flown to the end."""
    watch = truth.submit(monitor("W2", 1, 200))["action_id"]

    def on_station() -> set[str]:
        return truth.watching(truth.samples[-1], W2, 4.0, SAFETY.monitor_height_m)

    [held] = truth.until("a UAV watches W2", on_station, 60)
    fleet = truth.gateway.call("POST", f"/v1/uavs/{held}/control", json={"command": "hold"})
    assert {u["uav_id"]: u["control"] for u in fleet}[held] == "hold"
    since = truth.samples[-1].sim_s
    [relief] = truth.until("another UAV watches W2", lambda: on_station() - {held}, 90)
    arrived = truth.samples[-1].sim_s
    truth.until("it holds there 10 s", lambda: truth.samples[-1].sim_s > arrived + 10, 30)
    there = _xyz(_at(truth.samples[-1], held))
    later = [s for s in truth.samples if s.sim_s > since + 3]
    assert all(math.dist(_xyz(_at(s, held)), there) < 1.0 for s in later), "the held UAV moved"
    holding = [s for s in truth.samples if s.sim_s > arrived + 5]
    assert min(math.dist(there, _xyz(_at(s, relief))) for s in holding) > 3.0
    truth.gateway.call("POST", f"/v1/uavs/{held}/control", json={"command": "return"})
    home = PAPER.site.station(next(u.home_station for u in PAPER.fleet.uavs if u.id == held))
    spots = [_xyz(p) for p in spot_positions(home, PAPER.fleet)]

    def landed_home() -> bool:
        v = next(v for v in truth.samples[-1].state.vehicles if v.uav_id == held)
        return v.state == "landed" and min(math.dist(_xyz(v.position), p) for p in spots) < 1.0

    truth.until("the held UAV landed at home", landed_home, 90)
    fleet = truth.gateway.call("POST", f"/v1/uavs/{held}/control", json={"command": "resume"})
    assert {u["uav_id"]: u["control"] for u in fleet}[held] is None
    truth.until("the monitor ends", lambda: truth.finished(watch), 200)
    assert truth.action(watch)["state"] == "completed", truth.action(watch)
    controls = [e.detail for e in truth.events() if e.kind == EventKind.UAV_CONTROL]
    assert controls == ["operator: hold", "operator: return", "operator: resume"]
    assert not truth.violations("separation", *UNSAFE)
