"""The multi-agent host (simulation only): the paper's mission (its
monitoring shortened) flown by three agents in one process, checked against
the simulator's truth; SIGTERM stops them all; an agent that fails leaves
the others flying."""

from __future__ import annotations

import asyncio
import io
import logging
import os
import signal
import subprocess
import sys

import msgspec
import pytest
from rich.console import Console

from linecrew.launch.demo import run_mission
from linecrew.launch.local_run import LocalRun, RunOptions
from linecrew.launch.ports import free_udp_block
from linecrew_runtime.bus import Bus, BusConfig
from linecrew_runtime.process import Shutdown
from linecrew_runtime.scenarios import load
from onboard_agent.config import AgentConfig
from onboard_agent.fleet_host import HOST_NICE, host
from proto import KeySpace, MonitorAction, Role, ScriptedAction
from tests.e2e.truth import TruthLog

SPEEDUP = 10.0
PAPER = load("paper")


def _short(scripted: ScriptedAction) -> ScriptedAction:
    """The paper's actions, the monitoring a minute long instead of ten."""
    if isinstance(scripted.action, MonitorAction):
        action = msgspec.structs.replace(scripted.action, duration_s=60.0)
        return msgspec.structs.replace(scripted, action=action)
    return scripted


SMALL = msgspec.structs.replace(PAPER, actions=[_short(a) for a in PAPER.actions])
UAVS = [u.id for u in PAPER.fleet.uavs]
KEYS = KeySpace(PAPER.site.id)


def test_one_host_flies_the_papers_mission_and_stops_on_sigterm(tmp_path):
    options = RunOptions(speedup=SPEEDUP, run_dir=tmp_path / "run", agents_per_process=3)
    with LocalRun(SMALL, options) as run:
        [agents] = [c for c in run.supervisor.children if c.name.startswith("agent")]
        assert agents.name == "agents-1"
        ground = os.getpriority(os.PRIO_PROCESS, run.supervisor.children[0].popen.pid)
        host = os.getpriority(os.PRIO_PROCESS, agents.popen.pid)
        assert host == ground + HOST_NICE  # the operator's processes come first
        truth = TruthLog(run)
        console = Console(file=io.StringIO())
        records, _ = run_mission(
            run.gateway(), SMALL, SPEEDUP, 300.0, Shutdown(), console, lambda *_: truth.sample()
        )
        final = truth.sample()
        assert {r["action_id"]: r["state"] for r in records} == {
            a.id: "completed" for a in SMALL.actions
        }, run.run_dir
        assert [(d.tool, d.uav_id, d.worker_id) for d in final.deliveries] == [
            ("wrench", "uav-1", "W1")
        ]
        flew = {v.uav_id for s in truth.samples for v in s.state.vehicles if v.state == "flying"}
        assert flew == set(UAVS)  # every agent of the host flew
        assert not any(v.state == "crashed" for s in truth.samples for v in s.state.vehicles)

        os.killpg(agents.popen.pid, signal.SIGTERM)
        assert agents.popen.wait(30) == 0, agents.tail()
        assert not run.bus.alive(KEYS.all_alive(Role.AGENT), 2.0)
        log = agents.log_path.read_text()
        assert "3 agents stopped on SIGTERM" in log
        assert "Traceback" not in log


def test_an_agent_that_fails_leaves_the_others_flying(router, caplog):
    port = free_udp_block(3)
    autopilots = {
        "uav-1": f"udpout:127.0.0.1:{port}",
        "uav-2": "/dev/no-such-autopilot",  # cannot be opened: this agent raises
        "uav-3": f"udpout:127.0.0.1:{port + 2}",
    }
    config = BusConfig(connect=(router,), lease_ms=500)
    healthy = {KEYS.alive(Role.AGENT, u) for u in ("uav-1", "uav-3")}

    async def scenario() -> list[str]:
        stop = asyncio.Event()
        flying = asyncio.create_task(
            host(autopilots, PAPER, config, AgentConfig.from_env(), stop.wait, SPEEDUP)
        )
        with Bus.open(config) as watcher:

            async def others_up() -> bool:
                alive = await asyncio.to_thread(watcher.alive, KEYS.all_alive(Role.AGENT), 0.5)
                return healthy <= alive

            while not await others_up():
                assert not flying.done(), "the host ended"
                await asyncio.sleep(0.1)
            await asyncio.wait_for(_failed_logged(caplog), 20)
            assert await others_up() and not flying.done()  # the failure changed nothing
        stop.set()
        return await asyncio.wait_for(flying, 30)

    with caplog.at_level(logging.ERROR, "onboard_agent.fleet_host"):
        assert asyncio.run(asyncio.wait_for(scenario(), 60)) == ["uav-2"]


async def _failed_logged(caplog: pytest.LogCaptureFixture) -> None:
    while "agent uav-2 failed; the others fly on" not in caplog.text:
        await asyncio.sleep(0.05)


def test_unknown_uavs_are_refused_before_anything_starts():
    flags = ["--uavs", "uav-1,uav-9", "--autopilot-base-port", "14560", "--connect", "tcp/x:9"]
    done = subprocess.run(
        [sys.executable, "-m", "onboard_agent.fleet_host", *flags],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 2
    assert "no UAV uav-9" in done.stderr


def test_secure_runs_keep_one_agent_process_per_uav():
    with pytest.raises(ValueError, match="one agent process per UAV"):
        RunOptions(secure=True, agents_per_process=2)
