// Boot: token, views, polling and the live event stream.
//
// The fleet and the workers' poses are polled (default every 500 ms;
// #poll=MS in the URL changes it), plans and actions are fetched on the events that change them and
// polled slowly as a fallback. Every update only marks views dirty; they
// render together in the next animation frame.

import { api, askToken, followEvents, on, readFragment, token } from "./api.js";
import { initActions } from "./actions.js";
import { initAlerts, onEvent } from "./alerts.js";
import { text, timeOfDay } from "./dom.js";
import { initFleet } from "./fleet.js";
import { initGantt } from "./gantt.js";
import { initMap } from "./map.js";
import { initSim } from "./sim.js";
import {
  clockRate,
  invalidate,
  missionNow,
  setActions,
  setFleet,
  setPlans,
  setSite,
  setWorkers,
  state,
  stats,
} from "./store.js";

const $ = (id) => document.getElementById(id);
const params = readFragment();
const POLL_MS = Math.min(Math.max(Number(params.get("poll")) || 500, 100), 10000);
const PLAN_EVENTS = new Set(["plan_changed", "replan", "uav_lost", "uav_back", "uav_crashed"]);
const ACTION_EVENTS = new Set(["action_accepted", "action_changed", "action_cancelled", "action_state", "action_failed", "handover"]);

let generation = 0; // bumped on every (re)start: old loops stop
let unauthorized = false;
let stream = null;

function banner(message) {
  const node = $("error");
  if (!message) {
    node.hidden = true;
    node.textContent = "";
    return;
  }
  node.textContent = message;
  node.hidden = false;
}

function pill(id, value) {
  $(id).dataset.state = value;
  $(id).title = `${id === "api-status" ? "REST API" : "event stream"}: ${value}`;
}

on("auth", (error) => {
  unauthorized = true;
  pill("api-status", "unauthorized");
  banner(
    `Unauthorized (401): the gateway refused the bearer token (${error.message}). ` +
      `Open the console as /#token=YOUR_TOKEN, or press "Change token".`,
  );
  document.body.dataset.auth = "refused";
});

on("status", (ok, error) => {
  if (unauthorized) return;
  pill("api-status", ok ? "ok" : "down");
  if (ok && $("error").dataset.kind === "status") {
    banner("");
    delete $("error").dataset.kind;
  } else if (!ok) {
    banner(`Gateway or ground station not answering: ${error.message}`);
    $("error").dataset.kind = "status";
  }
});

function later(fn, ms) {
  let timer = 0;
  return () => {
    if (!timer) {
      timer = setTimeout(() => {
        timer = 0;
        fn();
      }, ms);
    }
  };
}

async function quietly(fn) {
  try {
    await fn();
  } catch (exc) {
    if (!exc.status) console.error(exc);
  }
}

const refreshFleet = () => quietly(async () => setFleet(await api("GET", "v1/fleet")));
const refreshPlans = () =>
  quietly(async () => {
    setPlans(await api("GET", "v1/plan"));
    setQuality(await api("GET", "v1/plan/quality"));
  });

/** The live plan's objective and improvement age beside the epoch. */
function setQuality(q) {
  const el = document.getElementById("plan-quality");
  if (!el || q.objective_s == null) return;
  const ago = q.improved_ago_s == null ? "not improved yet" : `improved ${Math.round(q.improved_ago_s)} s ago`;
  el.textContent = `objective ${q.objective_s.toFixed(1)} s, ${ago}`;
  el.dataset.objective = String(q.objective_s);
}
const refreshWorkers = () => quietly(async () => setWorkers((await api("GET", "v1/workers")).workers));
const refreshActions = () => quietly(async () => setActions(await api("GET", "v1/actions")));
const plansSoon = later(refreshPlans, 100);
const actionsSoon = later(refreshActions, 100);

/** Run fn every ms (one at a time) until the next restart or a 401. */
async function every(ms, fn, gen) {
  while (gen === generation && !unauthorized) {
    const started = performance.now();
    await fn();
    const wait = Math.max(ms - (performance.now() - started), 20);
    await new Promise((r) => setTimeout(r, wait));
  }
}

async function start() {
  generation += 1;
  const gen = generation;
  unauthorized = false;
  banner("");
  delete document.body.dataset.auth;
  if (stream) stream.stop();
  try {
    const site = await api("GET", "v1/site");
    setSite(site);
    text($("site-id"), `site ${site.id}`);
  } catch (exc) {
    if (!exc.status || exc.status !== 401) banner(`Cannot read the site: ${exc.message}`);
    return;
  }
  document.body.dataset.ready = "yes";
  every(POLL_MS, refreshFleet, gen);
  every(POLL_MS, refreshWorkers, gen);
  every(3000, refreshPlans, gen);
  every(2000, refreshActions, gen);
  stream = followEvents(
    0,
    (event) => {
      onEvent(event);
      if (PLAN_EVENTS.has(event.kind)) plansSoon();
      if (ACTION_EVENTS.has(event.kind)) actionsSoon();
    },
    (value) => pill("stream-status", value),
  );
}

function tick() {
  const now = missionNow();
  const shown = now === null ? "waiting for telemetry" : `${timeOfDay(now)} ×${clockRate().toFixed(1)}`;
  text($("clock"), `mission clock ${shown}`);
  invalidate("gantt");
}

function boot() {
  initMap($("map"));
  initGantt($("gantt"), $("gantt-legend"));
  initFleet($("fleet"));
  initActions(
    $("actions"),
    { inspect: $("form-inspect"), monitor: $("form-monitor"), deliver: $("form-deliver") },
    $("form-result"),
  );
  initAlerts($("alerts"), $("alerts-acked"), $("ack-all"));
  initSim($("sim-panel"), $("form-fault"), $("fault-values"), $("fault-result"));
  $("change-token").addEventListener("click", () => {
    if (askToken()) start();
  });
  window.addEventListener("resize", () => invalidate("gantt"));
  setInterval(tick, 500);
  window.linecrewConsole = { state, stats, pollMs: POLL_MS };
  if (!token() && !askToken()) {
    banner('No bearer token: open the console as /#token=YOUR_TOKEN, or press "Change token".');
    document.body.dataset.auth = "missing";
    return;
  }
  start();
}

boot();
