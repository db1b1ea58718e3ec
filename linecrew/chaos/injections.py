"""The chaos runner's operator- and fault-side injections, one applier per
kind of :data:`APPLIERS`: each does the thing, says what happened in
``applied.note`` and returns what heals (or re-checks) it after the
injection's ``hold_s``, if anything.

What each must leave true, checked here (the invariants named in the
report's violations):

- ``cancel_kept``: a cancel the ground station acknowledged answers
  ``cancelled`` and is still ``cancelled`` when looked at again; a refused
  one says why with a 409 (it had already ended), never a 404;
- ``edit_kept``: an edit is applied (the reply, and a later read, carry the
  new priority or duration) or refused with a 4xx that says why; the action
  is never lost;
- ``store_refusal``: while the store's files cannot be written, a new
  action is refused with 503 (then retried by the runner with the same
  ``request_id`` until accepted), never acknowledged.

The store's disk is made read-only by ``chattr +i`` on the SQLite file and
its write-ahead log: the ground station's open descriptors then fail every
write (``disk I/O error``) as on a read-only disk, while reads go on. A full
disk would not do: SQLite reuses the log's frames once checkpointed, so a
store whose log has grown keeps committing on a full disk. The shared-memory
index stays writable (SQLite maps it: a write fault there is a SIGBUS).

Motor and GPS faults go through the gateway's simulator route; a motor
failure hits a UAV in the air and excuses its fall (its work must go to the
others). A clock
jump restarts one agent with ``LINECREW_CLOCK_OFFSET_S`` set (its mission
clock that far off), then again on the true clock after ``hold_s``.
"""

from __future__ import annotations

import dataclasses
import pathlib
import subprocess
from collections.abc import Callable
from typing import Any, Protocol

import httpx

from linecrew.chaos.faults import ProcessFaults
from linecrew.chaos.invariants import Checker, Violation
from linecrew.chaos.netns_run import NetnsRun
from linecrew.chaos.schedule import Injection
from linecrew.launch.local_run import LocalRun
from linecrew_runtime.clock import OFFSET_ENV
from proto import GetSimState, SimState
from proto.errors import LinecrewError

Heal = Callable[[], None]
STORE_FILES = ("gs.db", "gs.db-wal")  # in the run directory
AIRBORNE = frozenset({"taking_off", "flying", "landing"})  # the simulator's flight states


class Noted(Protocol):
    """What the report says of one applied injection."""

    note: str


@dataclasses.dataclass(kw_only=True)
class Context:
    """What the appliers act on, shared by every injection of one run."""

    run: LocalRun | NetnsRun
    faults: ProcessFaults
    http: httpx.Client
    checker: Checker
    speedup: float
    now: Callable[[], float]  # wall seconds since the chaos phase started
    submit: Callable[[dict[str, Any]], str]  # the runner's POST (retried until answered)
    edits: dict[str, dict[str, Any]] = dataclasses.field(default_factory=dict)

    def violate(self, invariant: str, detail: str) -> None:
        """Record a broken invariant."""
        self.checker.violations.append(Violation(self.now(), invariant, detail))


def cancel(injection: Injection, ctx: Context, applied: Noted) -> Heal | None:
    """``DELETE`` an accepted chaos action; re-read it after ``hold_s``."""
    action_id = injection.target
    response = _call(ctx, applied, "DELETE", action_id)
    if response is None:
        return None
    ctx.checker.checks["cancel_kept"] += 1
    if response.status_code >= 300:
        applied.note = f"refused ({response.status_code} {_error(response)})"
        if response.status_code != 409:
            ctx.violate("cancel_kept", f"cancel of {action_id}: {applied.note}")
        return None
    state = response.json()["state"]
    applied.note = f"answered {state}"
    if state != "cancelled":
        ctx.violate("cancel_kept", f"cancel of {action_id} answered {state}")
    return lambda: _recheck(ctx, applied, action_id, "cancel_kept", _cancelled)


def edit(injection: Injection, ctx: Context, applied: Noted) -> Heal | None:
    """``PATCH`` an accepted chaos action's priority or duration; re-read it
    after ``hold_s``."""
    action_id = injection.target
    change: dict[str, Any] = injection.params["change"]
    ctx.edits.pop(action_id, None)  # an unanswered edit may or may not be applied
    response = _call(ctx, applied, "PATCH", action_id, change)
    if response is None:
        return None
    ctx.checker.checks["edit_kept"] += 1
    if response.status_code >= 300:
        applied.note = f"refused ({response.status_code} {_error(response)})"
        if response.status_code in (404, 500) or not _error(response):  # lost, or no reason
            ctx.violate("edit_kept", f"edit of {action_id}: {applied.note}")
        return None
    record = response.json()
    applied.note = "applied"
    if not _edited(change)(record):
        ctx.violate("edit_kept", f"edit of {action_id} answered without it: {record['action']}")
    ctx.edits[action_id] = change

    def still_edited(record: dict[str, Any]) -> bool:
        return ctx.edits.get(action_id) is not change or _edited(change)(record)

    return lambda: _recheck(ctx, applied, action_id, "edit_kept", still_edited)


def motor(injection: Injection, ctx: Context, applied: Noted) -> Heal | None:
    """The motors of a flying UAV fail: it falls; its crash is excused, its
    work is the others'. The schedule's UAV if it flies, else the first that
    does; none if none flies (on the ground it would be another fault)."""
    flying = _flying(ctx)
    target = injection.target if injection.target in flying else min(flying, default="")
    if not target:
        applied.note = "skipped: no UAV in the air"
        return None
    ctx.checker.excuse(target, "motors failed")
    _sim_fault(ctx, applied, {"type": "motor", "uav_id": target})
    applied.note += "" if target == injection.target else f" (on {target}: it flies)"
    return None


def gps(injection: Injection, ctx: Context, applied: Noted) -> Heal | None:
    """The UAV reports a frozen position for ``hold_s`` wall seconds (the
    simulator ends it by itself)."""
    seconds = injection.hold_s * ctx.speedup
    _sim_fault(ctx, applied, {"type": "gps", "uav_id": injection.target, "duration_s": seconds})
    return None


def disk(injection: Injection, ctx: Context, applied: Noted) -> Heal | None:
    """Make the store read-only, submit the probe action (it must get 503,
    then is retried until accepted), make it writable after ``hold_s``."""
    body = dict(injection.params)
    files = [ctx.run.run_dir / name for name in STORE_FILES]
    failed = set_immutable(files, True)
    if failed:
        applied.note = f"not applied ({failed}); probe {ctx.submit(body)}"
        return None
    ctx.checker.checks["store_refusal"] += 1
    try:
        response = ctx.http.post("/v1/actions", json=body)
        answer = f"{response.status_code} {_error(response)}"
        if response.status_code < 300:
            ctx.violate("store_refusal", f"{body['action_id']} acknowledged on a read-only store")
    except httpx.HTTPError as exc:
        answer = type(exc).__name__
    applied.note = f"probe answered {answer}, then {ctx.submit(body)}"

    def heal() -> None:
        failed = set_immutable(files, False)
        applied.note += f"; writable again{f' FAILED: {failed}' if failed else ''}"

    return heal


def clock_jump(injection: Injection, ctx: Context, applied: Noted) -> Heal | None:
    """Restart the UAV's agent with its mission clock ``offset_s`` off; after
    ``hold_s`` restart it on the true clock."""
    name, offset = f"agent-{injection.target}", injection.params["offset_s"]
    ctx.faults.kill(name)
    ctx.checker.excuse(injection.target, f"agent restarted {offset:+g} s off")
    child = ctx.faults.restart(name, env={OFFSET_ENV: str(offset)})
    applied.note = f"restarted as pid {child.popen.pid}"

    def heal() -> None:
        ctx.faults.kill(name)
        child = ctx.faults.restart(name)
        applied.note += f"; on the true clock as pid {child.popen.pid}"

    return heal


APPLIERS: dict[str, Callable[[Injection, Context, Noted], Heal | None]] = {
    "cancel": cancel,
    "edit": edit,
    "motor": motor,
    "gps": gps,
    "disk": disk,
    "clock_jump": clock_jump,
}


def set_immutable(files: list[pathlib.Path], on: bool) -> str:
    """``chattr +i`` (or ``-i``) ``files``; why not, or "" once done."""
    try:
        done = subprocess.run(
            ["chattr", "+i" if on else "-i", *map(str, files)],
            capture_output=True,
            text=True,
            timeout=10,
        )
    except (OSError, subprocess.TimeoutExpired) as exc:
        return str(exc)
    if done.returncode:
        return done.stderr.strip() or f"chattr exit {done.returncode}"
    return ""


# -- helpers -----------------------------------------------------------------


def _call(
    ctx: Context, applied: Noted, method: str, action_id: str, body: Any = None
) -> httpx.Response | None:
    """``method`` on the accepted action ``action_id``; None (and a note) when
    it was never accepted or the ground station did not answer."""
    if action_id not in ctx.checker.accepted_at:
        applied.note = "skipped: not accepted (yet)"
        return None
    try:
        response = ctx.http.request(method, f"/v1/actions/{action_id}", json=body)
    except httpx.HTTPError as exc:
        applied.note = f"unanswered ({type(exc).__name__})"
        return None
    if response.status_code in (502, 503, 504):
        applied.note = f"unanswered ({response.status_code} {_error(response)})"
        return None
    return response


def _recheck(
    ctx: Context,
    applied: Noted,
    action_id: str,
    invariant: str,
    holds: Callable[[dict[str, Any]], bool],
) -> None:
    """Read the action again: it must be listed and ``holds`` must be true."""
    try:
        response = ctx.http.get(f"/v1/actions/{action_id}")
    except httpx.HTTPError as exc:
        applied.note += f"; not re-read ({type(exc).__name__})"
        return
    if response.status_code in (502, 503, 504):
        applied.note += f"; not re-read ({response.status_code})"
    elif response.status_code != 200:
        ctx.violate(invariant, f"{action_id} re-read: {response.status_code} {_error(response)}")
    elif not holds(record := response.json()):
        ctx.violate(invariant, f"{action_id} re-read {record['state']}: {record['action']}")
    else:
        applied.note += f"; re-read {record['state']}"


def _cancelled(record: dict[str, Any]) -> bool:
    return record["state"] == "cancelled"


def _edited(change: dict[str, Any]) -> Callable[[dict[str, Any]], bool]:
    """Whether a record carries ``change``."""
    if "action" in change:
        duration = change["action"]["duration_s"]
        return lambda record: record["action"].get("duration_s") == duration
    return lambda record: record["action"].get("priority") == change["priority"]


def _flying(ctx: Context) -> set[str]:
    """The UAVs the simulator has in the air under power."""
    if ctx.run.bus is None:
        return set()
    try:
        truth = ctx.run.bus.query(ctx.run.keys.sim("state"), GetSimState(), SimState, 2.0)
    except LinecrewError:
        return set()
    return {v.uav_id for v in truth.vehicles if v.state in AIRBORNE}


def _sim_fault(ctx: Context, applied: Noted, body: dict[str, Any]) -> None:
    try:
        response = ctx.http.post("/v1/sim/faults", json=body)
        applied.note = f"HTTP {response.status_code}"
    except httpx.HTTPError as exc:
        applied.note = f"not applied: {exc}"


def _error(response: httpx.Response) -> str:
    """The error code of a JSON error answer ("" if none)."""
    try:
        body = response.json()
    except ValueError:
        return ""
    return str(body.get("error", "")) if isinstance(body, dict) else ""
