"""The tick loop's wake-up: a plan that arrives between ticks is ticked at
once, not up to a tick period later."""

from __future__ import annotations

import asyncio

from onboard_agent.runtime import Wakeup


def test_a_wakeup_ends_the_sleep_at_once_and_only_the_current_one():
    async def scenario() -> tuple[float, float]:
        loop = asyncio.get_running_loop()
        wakeup = Wakeup()
        wakeup.set()  # nobody sleeps: nothing to end, nothing remembered
        started = loop.time()
        await wakeup.sleep(0.05)
        slept = loop.time() - started
        loop.call_soon(wakeup.set)
        started = loop.time()
        await wakeup.sleep(60.0)
        return slept, loop.time() - started

    slept, woken = asyncio.run(asyncio.wait_for(scenario(), 90))
    assert slept >= 0.05
    assert woken < 30  # ended by set(), not by its 60 s
