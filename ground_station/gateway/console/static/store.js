// What the console knows, one place: the site, the fleet, the plans, the
// actions, the selection, the flown tracks, and the mission clock. Views
// register a render function per part; changes mark parts dirty and one
// requestAnimationFrame renders every dirty part at once.

const TRACK_POINTS = 300; // flown track kept per UAV (client side)
const TRACK_STEP_M = 0.3; // a new track point once the UAV moved this far

export const state = {
  site: null,
  fleet: new Map(), // uav_id -> UavState (telemetry, status)
  plans: new Map(), // uav_id -> Plan
  actions: new Map(), // action_id -> ActionRecord
  tracks: new Map(), // uav_id -> [[x, y], ...]
  workers: new Map(), // worker_id -> WorkerView (tracked pose, else the site's)
  selected: null, // uav_id
};

/** Render cost: frames rendered, longest and total milliseconds (for the bench). */
export const stats = { frames: 0, maxMs: 0, totalMs: 0, parts: {} };

const renderers = new Map(); // part -> fn
const dirty = new Set();
let frame = 0;

export function onRender(part, fn) {
  renderers.set(part, fn);
}

/** Mark parts dirty; they render in the next animation frame. */
export function invalidate(...parts) {
  for (const part of parts) dirty.add(part);
  if (!frame) frame = requestAnimationFrame(flush);
}

function flush() {
  frame = 0;
  const started = performance.now();
  const parts = [...dirty];
  dirty.clear();
  for (const part of parts) {
    const fn = renderers.get(part);
    if (!fn) continue;
    const t0 = performance.now();
    try {
      fn(state);
    } catch (exc) {
      console.error(`render ${part}`, exc);
    }
    stats.parts[part] = Math.max(stats.parts[part] || 0, performance.now() - t0);
  }
  const took = performance.now() - started;
  stats.frames += 1;
  stats.totalMs += took;
  stats.maxMs = Math.max(stats.maxMs, took);
}

/** Ids in natural order (uav-2 before uav-10). */
export function byId(ids) {
  return [...ids].sort((a, b) => a.localeCompare(b, "en", { numeric: true }));
}

export function select(uavId) {
  state.selected = state.selected === uavId ? null : uavId;
  invalidate("map", "gantt", "fleet");
}

// -- mission clock ---------------------------------------------------------------
// Plans are in mission seconds (UNIX seconds times the run's speed-up), which
// the gateway does not state: estimate them from telemetry stamps and the
// rate at which they advance against this page's clock.

const clock = { stamp: null, at: 0, rate: 1, anchor: null, measured: false };

export function observeStamp(stamp) {
  const at = performance.now();
  if (clock.stamp === null) {
    Object.assign(clock, { stamp, at, anchor: { stamp, at } });
    return;
  }
  if (stamp <= clock.stamp) return;
  const wall = (at - clock.anchor.at) / 1000;
  if (wall >= 2) {
    const rate = (stamp - clock.anchor.stamp) / wall;
    if (rate > 0.05 && rate < 10000) {
      clock.rate = clock.measured ? clock.rate * 0.8 + rate * 0.2 : rate;
      clock.measured = true;
    }
    clock.anchor = { stamp, at };
  }
  clock.stamp = stamp;
  clock.at = at;
}

/** Mission seconds now (null before any telemetry). */
export function missionNow() {
  if (clock.stamp === null) return null;
  return clock.stamp + ((performance.now() - clock.at) / 1000) * clock.rate;
}

export function clockRate() {
  return clock.rate;
}

// -- updates from the API ---------------------------------------------------------

export function setSite(site) {
  state.site = site;
  invalidate("map", "forms");
}

let shownUnknown = ""; // the unknown tasks the actions and the Gantt last showed

export function setFleet(uavs) {
  const seen = new Set();
  let latest = null;
  for (const uav of uavs) {
    seen.add(uav.uav_id);
    state.fleet.set(uav.uav_id, uav);
    const t = uav.telemetry;
    if (!t) continue;
    if (latest === null || t.stamp_s > latest) latest = t.stamp_s;
    const track = state.tracks.get(uav.uav_id) || [];
    const p = t.position;
    const end = track[track.length - 1];
    if (!end || Math.hypot(end[0] - p.x_m, end[1] - p.y_m) >= TRACK_STEP_M) {
      track.push([p.x_m, p.y_m]);
      if (track.length > TRACK_POINTS) track.splice(0, track.length - TRACK_POINTS);
    }
    state.tracks.set(uav.uav_id, track);
  }
  for (const id of [...state.fleet.keys()]) if (!seen.has(id)) state.fleet.delete(id);
  if (latest !== null) observeStamp(latest);
  invalidate("map", "fleet", "alerts-fleet", "sim");
  const unknown = uavs.flatMap((u) => u.unknown_tasks || []).join(" ");
  if (unknown !== shownUnknown) {
    shownUnknown = unknown;
    invalidate("actions", "gantt");
  }
}

export function setWorkers(workers) {
  state.workers = new Map(workers.map((w) => [w.worker_id, w]));
  invalidate("map");
}

export function setPlans(plans) {
  state.plans = new Map(plans.map((p) => [p.uav_id, p]));
  invalidate("map", "gantt", "fleet");
}

export function setActions(records) {
  state.actions = new Map(records.map((r) => [r.action_id, r]));
  invalidate("actions", "map");
}

export function upsertAction(record) {
  state.actions.set(record.action_id, record);
  invalidate("actions", "map");
}

// -- derived --------------------------------------------------------------------

/** Where a worker is now: tracked, else where the site puts them. */
export function workerPosition(id) {
  const live = state.workers.get(id);
  if (live) return live.position;
  const w = state.site && state.site.workers.find((x) => x.id === id);
  return w ? w.position : null;
}

/** Where a task flies the UAV, in order ([] for a wait). */
export function taskTargets(task) {
  switch (task.type) {
    case "inspect":
      return task.waypoints.map((w) => w.position);
    case "monitor":
    case "deliver": {
      const p = workerPosition(task.worker_id);
      return p ? [p] : [];
    }
    case "pick":
    case "recharge":
    case "home":
      return [task.position];
    default:
      return [];
  }
}

/** Tasks whose fate is unknown while their UAV is silent: task id -> its UavState. */
export function unknownTasks() {
  const out = new Map();
  for (const uav of state.fleet.values()) for (const id of uav.unknown_tasks || []) out.set(id, uav);
  return out;
}

/** The task a UAV is flying: its agent's task id, else its plan's first. */
export function currentTask(uavId) {
  const uav = state.fleet.get(uavId);
  const plan = state.plans.get(uavId);
  const taskId = uav && uav.status && uav.status.task_id;
  if (plan && taskId) {
    const task = plan.tasks.find((t) => t.task_id === taskId);
    if (task) return task;
  }
  return taskId ? { task_id: taskId, type: taskId.split(".").pop() } : null;
}
