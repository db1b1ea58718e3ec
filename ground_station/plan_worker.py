"""The ground station's single planning worker.

Requests and agents' reports never plan: they make their change durable and
``trigger`` a replan with a reason. The worker runs one replan at a time;
triggers that arrive while one runs are merged into the next (coalesced,
never dropped). A replan is taken in three steps: its inputs on the loop
(``prepare``), the planning itself on a thread (``compute``), its result on
the loop (``commit``); a result the mission outran meanwhile (a task
finished, an action cancelled, a UAV lost) is dropped and the replan run
again. When no trigger has come for ``improve_delay_s``, the worker tries to
improve the live plan (bounded rounds, on the same thread; a trigger
interrupts it and the attempt is dropped), and stops trying for a state once
an attempt is not adopted: a steady mission plans nothing. A result the
store cannot take is not adopted: its reason waits, and the replan is run
again every ``STORE_RETRY_S`` until the store writes.

``settle()`` does the same synchronously (tests, and any caller that must
see the plan follow at once).
"""

from __future__ import annotations

import asyncio
import dataclasses
import logging
from typing import Protocol

from ground_station.replan_jobs import Computed, ReplanJob
from ground_station.replanner import Replanner
from ground_station.store import StoreUnavailable
from proto.plan import Plan

log = logging.getLogger(__name__)

STORE_RETRY_S = 1.0
"""Wall seconds between attempts to commit a plan while the store fails."""


@dataclasses.dataclass
class WorkerStats:
    """Triggers and the replans they became."""

    triggers: int = 0
    runs: int = 0  # replans run (each serves every trigger merged into it)
    coalesced: int = 0  # triggers merged into a replan with others
    max_batch: int = 0


class Planned(Protocol):
    """What the worker plans for (the mission manager): a replan's or an
    improvement's inputs taken on the loop, its result committed there."""

    replanner: Replanner

    def prepare_replan(self, reason: str) -> ReplanJob: ...

    def prepare_improvement(self) -> ReplanJob: ...

    def finish_replan(self, computed: Computed) -> list[Plan] | None: ...

    def finish_improvement(self, computed: Computed | None, interrupted: bool = False) -> None: ...


class PlanWorker:
    """Coalescing trigger + one planning worker for a mission manager."""

    def __init__(
        self, manager: Planned, *, improve: bool = True, improve_delay_s: float = 0.5
    ) -> None:
        self.manager = manager
        self.improve = improve
        self.improve_delay_s = improve_delay_s  # quiet (wall) time before improving
        self.stats = WorkerStats()
        self._reasons: list[str] = []
        self._wake: asyncio.Event | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self.busy = False

    # -- triggers ------------------------------------------------------------------

    def trigger(self, reason: str) -> None:
        """Ask for a replan (on the loop; returns at once)."""
        self._reasons.append(reason)
        self.stats.triggers += 1
        if self._wake is not None:
            self._wake.set()

    def _stop(self) -> bool:
        return bool(self._reasons)  # read from the planning thread: a trigger waits

    @property
    def pending(self) -> bool:
        """Whether a trigger waits for a replan."""
        return bool(self._reasons)

    @property
    def settled(self) -> bool:
        """Whether the plan is final for now: no trigger waiting, nothing
        planning, and no improvement due."""
        due = self.improve and self.manager.replanner.wants_improvement()
        return not (self._reasons or self.busy or due)

    def _take(self) -> str:
        reasons, self._reasons = self._reasons, []
        self.stats.runs += 1
        self.stats.coalesced += len(reasons) - 1
        self.stats.max_batch = max(self.stats.max_batch, len(reasons))
        unique = list(dict.fromkeys(reasons))
        text = "; ".join(unique[:3])
        return text + (f" (+{len(unique) - 3} more)" if len(unique) > 3 else "")

    # -- synchronous -----------------------------------------------------------------

    def settle(self, improve: bool = False, max_improvements: int = 10) -> None:
        """Run the pending replans now (and, if ``improve``, the improvement
        attempts due), on the caller's thread."""
        manager = self.manager
        self._replan_pending()
        if not (improve and self.improve):
            return
        for _ in range(max_improvements):
            if not manager.replanner.wants_improvement():
                return
            job = manager.prepare_improvement()
            manager.finish_improvement(manager.replanner.improve(job))
            self._replan_pending()  # an adopted plan may trigger nothing, but be safe

    def _replan_pending(self) -> None:
        manager = self.manager
        while self._reasons:
            reason = self._take()
            self._finish(reason, manager.replanner.compute(manager.prepare_replan(reason)))

    def _finish(self, reason: str, computed: Computed) -> None:
        """Commit ``computed``; its reason waits for the next replan if the
        mission outran it, or the store could not take it (raised)."""
        try:
            finished = self.manager.finish_replan(computed)
        except StoreUnavailable:
            self._reasons.insert(0, reason)
            raise
        if finished is None:
            self._reasons.insert(0, reason)

    # -- the worker task ---------------------------------------------------------------

    async def run(self) -> None:
        """Serve triggers until cancelled (one asyncio task on the loop)."""
        self._loop = asyncio.get_running_loop()
        self._wake = asyncio.Event()
        manager = self.manager
        while True:
            try:
                if self._reasons:
                    await self._replan_once()
                elif self.improve and manager.replanner.wants_improvement():
                    if await self._quiet(self.improve_delay_s):
                        await self._improve_once()
                else:
                    self._wake.clear()
                    if not self._reasons:
                        await self._wake.wait()
            except asyncio.CancelledError:
                raise
            except StoreUnavailable as exc:
                log.error("planning waits for the store: %s", exc)
                await asyncio.sleep(STORE_RETRY_S)
            except Exception:
                log.exception("planning worker step failed")
                await asyncio.sleep(0.05)

    async def _quiet(self, seconds: float) -> bool:
        """Wait up to ``seconds`` for a trigger; True if none came (a burst of
        triggers is served before any improvement competes with it)."""
        assert self._wake is not None
        self._wake.clear()
        if self._reasons:
            return False
        try:
            await asyncio.wait_for(self._wake.wait(), seconds)
        except TimeoutError:
            return not self._reasons
        return False

    async def _replan_once(self) -> None:
        manager = self.manager
        reason = self._take()
        job = manager.prepare_replan(reason)
        self.busy = True
        try:
            computed = await asyncio.to_thread(manager.replanner.compute, job)
        finally:
            self.busy = False
        self._finish(reason, computed)

    async def _improve_once(self) -> None:
        manager = self.manager
        job = manager.prepare_improvement()
        self.busy = True
        try:
            computed = await asyncio.to_thread(manager.replanner.improve, job, self._stop)
        finally:
            self.busy = False
        manager.finish_improvement(computed, interrupted=computed is None and self.pending)
