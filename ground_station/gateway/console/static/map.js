// The site map: SVG in local ENU metres (x east, y north: drawn as -y so
// north is up), auto-fitted to the site and the UAVs. Static features are
// drawn once per fit; UAVs, workers (where the tracker sees them), routes,
// tracks and waypoints are kept by id and updated in place.

import { attr, el, Keyed, pct, text, toggle } from "./dom.js";
import { currentTask, onRender, select, state, taskTargets, workerPosition } from "./store.js";

let svg;
let layers;
let view = null; // {x, y, w, h} in SVG units
let unit = 1; // marker size in metres
let staticKey = "";

const pt = (p) => `${round(p.x_m)},${round(-p.y_m)}`;
const round = (v) => Math.round(v * 100) / 100;

export function initMap(node) {
  svg = node;
  svg.setAttribute("preserveAspectRatio", "xMidYMid meet");
  const names = ["lines", "stations", "tools", "towers", "workers", "waypoints", "tracks"];
  layers = {};
  for (const name of [...names, "routes", "uavs"]) {
    layers[name] = el("svg:g", { class: `layer-${name}` }, svg);
  }
  layers.uavItems = new Keyed(layers.uavs, makeUav);
  layers.trackItems = new Keyed(layers.tracks, (id) =>
    el("svg:polyline", { class: "track", "data-uav": id }),
  );
  layers.routeItems = new Keyed(layers.routes, (id) =>
    el("svg:polyline", { class: "route", "data-uav": id }),
  );
  layers.workerItems = new Keyed(layers.workers, makeWorker);
  layers.wpItems = new Keyed(layers.waypoints, () => {
    const node = el("svg:circle", { class: "wp" });
    el("svg:title", {}, node);
    return node;
  });
  svg.addEventListener("click", (event) => {
    const target = event.target.closest("[data-uav]");
    if (target) select(target.dataset.uav);
  });
  onRender("map", render);
}

function makeUav(id) {
  const node = el("svg:g", { class: "uav", "data-uav": id });
  el("svg:circle", { class: "uav-halo", r: 2.2 }, node);
  const body = el("svg:path", { class: "uav-body", d: "M0,-1.4 L1,1 L0,0.5 L-1,1 Z" }, node);
  const label = el("svg:text", { class: "uav-label", x: 1.6, y: -0.2 }, node);
  const sub = el("svg:text", { class: "uav-sub", x: 1.6, y: 1.1 }, node);
  const title = el("svg:title", {}, node);
  return { node, body, label, sub, title };
}

function makeWorker(id) {
  const node = el("svg:g", { class: "worker", "data-id": id });
  el("svg:circle", { r: 0.8 }, node);
  el("svg:text", { x: 1.1, y: 0.4, text: id }, node);
  const title = el("svg:title", {}, node);
  return { node, title };
}

function render(s) {
  if (!s.site) return;
  fit(s);
  drawStatic(s);
  drawWorkers(s);
  drawWaypoints(s);
  drawUavs(s);
}

// -- fit -------------------------------------------------------------------------

function bounds(s) {
  const xs = [];
  const ys = [];
  const add = (p) => {
    xs.push(p.x_m);
    ys.push(-p.y_m);
  };
  const site = s.site;
  for (const f of [...site.towers, ...site.stations, ...site.tool_stations]) add(f.position);
  for (const w of site.workers) add(workerPosition(w.id));
  for (const uav of s.fleet.values()) if (uav.telemetry) add(uav.telemetry.position);
  if (!xs.length) return { x: -10, y: -10, w: 20, h: 20 };
  const x0 = Math.min(...xs);
  const y0 = Math.min(...ys);
  const w = Math.max(Math.max(...xs) - x0, 10);
  const h = Math.max(Math.max(...ys) - y0, 10);
  const pad = Math.max(w, h) * 0.08 + 2;
  return { x: x0 - pad, y: y0 - pad, w: w + 2 * pad, h: h + 2 * pad };
}

function fit(s) {
  const want = bounds(s);
  const inside =
    view &&
    want.x >= view.x &&
    want.y >= view.y &&
    want.x + want.w <= view.x + view.w &&
    want.y + want.h <= view.y + view.h;
  if (inside && view.w * view.h <= 1.6 * want.w * want.h) return; // close enough: keep still
  view = want;
  unit = Math.max(view.w, view.h) / 80;
  attr(svg, "viewBox", `${round(view.x)} ${round(view.y)} ${round(view.w)} ${round(view.h)}`);
}

// -- static features ---------------------------------------------------------------

function drawStatic(s) {
  const site = s.site;
  const stock = toolStock(s);
  const key = `${unit}|${JSON.stringify([...stock])}`;
  if (key === staticKey) return;
  staticKey = key;
  for (const name of ["lines", "stations", "tools", "towers"]) {
    layers[name].replaceChildren();
  }
  const towers = new Map(site.towers.map((t) => [t.id, t]));
  for (const line of site.lines) {
    const points = line.tower_ids.filter((id) => towers.has(id)).map((id) => towers.get(id));
    const node = el("svg:polyline", { class: "line", points: points.map((t) => pt(t.position)).join(" ") }, layers.lines);
    el("svg:title", { text: `line ${line.id}: ${line.tower_ids.join(" - ")}` }, node);
  }
  for (const t of site.towers) {
    const g = group(layers.towers, t.position, "tower", t.id);
    el("svg:rect", { x: -0.7, y: -0.7, width: 1.4, height: 1.4 }, g);
    el("svg:text", { x: 1, y: -0.9, text: `${t.id} ${round(t.position.z_m)} m` }, g);
    el("svg:title", { text: `tower ${t.id} top at ${round(t.position.z_m)} m` }, g);
  }
  for (const c of site.stations) {
    const g = group(layers.stations, c.position, "station", c.id);
    el("svg:circle", { r: 1.6 }, g);
    for (let i = 0; i < c.pads; i++) {
      const a = (2 * Math.PI * i) / Math.max(c.pads, 1);
      el("svg:circle", { class: "pad", r: 0.45, cx: round(Math.cos(a) * 0.8), cy: round(Math.sin(a) * 0.8) }, g);
    }
    const how = c.recharge.type === "swap" ? `swap ${c.recharge.swap_s} s` : `charge ${c.recharge.full_charge_s} s`;
    el("svg:text", { x: 2, y: 0.4, text: `${c.id} · ${c.pads} pads` }, g);
    el("svg:title", { text: `charging station ${c.id}: ${c.pads} pads, ${how}` }, g);
  }
  for (const ts of site.tool_stations) {
    const g = group(layers.tools, ts.position, "toolstation", ts.id);
    el("svg:rect", { x: -0.45, y: -0.45, width: 0.9, height: 0.9, transform: "rotate(45)" }, g);
    const tools = ts.tools.map((t) => `${t.name} ${stock.get(`${ts.id}/${t.name}`)}/${t.count}`);
    el("svg:text", { x: 0.6, y: -0.6, transform: "rotate(-60)", text: tools.join(", ") }, g);
    el("svg:title", { text: `tool station ${ts.id}: ${tools.join(", ")} (left/total)` }, g);
  }
}

// -- workers ---------------------------------------------------------------------------

function drawWorkers(s) {
  const keep = new Set();
  for (const w of s.site.workers) {
    keep.add(w.id);
    const item = layers.workerItems.get(w.id);
    const live = s.workers.get(w.id);
    const p = live ? live.position : w.position;
    attr(item.node, "transform", `translate(${pt(p)}) scale(${round(unit)})`);
    attr(item.node, "data-x", p.x_m);
    attr(item.node, "data-y", p.y_m);
    toggle(item.node, "untracked", !(live && live.tracked));
    const seen = live && live.tracked ? `tracked ${live.age_s.toFixed(1)} s ago` : "not tracked: site position";
    text(item.title, `worker ${w.id} at ${round(p.x_m)}, ${round(p.y_m)}, z ${round(p.z_m)} m (${seen})`);
  }
  layers.workerItems.prune(keep);
}

function group(parent, p, cls, id) {
  const transform = `translate(${pt(p)}) scale(${round(unit)})`;
  return el("svg:g", { class: cls, "data-id": id, transform }, parent);
}

/** Copies left per station/tool: the site's stock minus live or done deliveries. */
function toolStock(s) {
  const left = new Map();
  for (const ts of s.site.tool_stations) {
    for (const t of ts.tools) left.set(`${ts.id}/${t.name}`, t.count);
  }
  for (const r of s.actions.values()) {
    const a = r.action;
    if (a.type !== "deliver" || r.state === "failed" || r.state === "cancelled") continue;
    const key = `${a.tool_station_id}/${a.tool}`;
    if (left.has(key)) left.set(key, left.get(key) - 1);
  }
  return left;
}

// -- inspection waypoints ------------------------------------------------------------

function drawWaypoints(s) {
  const keep = new Set();
  for (const r of s.actions.values()) {
    if (r.action.type !== "inspect") continue;
    const done = new Set(r.waypoints_done || []);
    r.action.waypoints.forEach((w, i) => {
      const key = `${r.action_id}:${i}`;
      keep.add(key);
      const node = layers.wpItems.get(key);
      const status =
        done.has(i) || r.state === "completed"
          ? "done"
          : r.state === "failed" || r.state === "cancelled"
            ? "void"
            : "pending";
      attr(node, "class", `wp wp-${status}`);
      attr(node, "data-action", r.action_id);
      attr(node, "cx", w.position.x_m);
      attr(node, "cy", -w.position.y_m);
      attr(node, "r", unit * 0.6);
      text(node.firstChild, `${r.action_id} waypoint ${i} (${pt(w.position)}, z ${w.position.z_m}) ${status}`);
    });
  }
  layers.wpItems.prune(keep);
}

// -- UAVs, routes, tracks --------------------------------------------------------------

function drawUavs(s) {
  const keep = new Set();
  for (const [id, uav] of s.fleet) {
    const t = uav.telemetry;
    if (!t) continue;
    keep.add(id);
    const item = layers.uavItems.get(id);
    const p = t.position;
    attr(item.node, "transform", `translate(${round(p.x_m)},${round(-p.y_m)}) scale(${round(unit)})`);
    attr(item.node, "data-x", p.x_m);
    attr(item.node, "data-y", p.y_m);
    attr(item.node, "class", `uav state-${uav.state}${s.selected === id ? " selected" : ""}`);
    toggle(item.node, "low", t.battery_fraction < 0.2);
    attr(item.body, "transform", `rotate(${Math.round(t.heading_deg)})`);
    const task = currentTask(id);
    text(item.label, id);
    const holding = uav.status && uav.status.holding_for;
    toggle(item.node, "holding", holding);
    text(item.sub, `${p.z_m.toFixed(1)} m · ${pct(t.battery_fraction)} · ${holding ? `holding off for ${holding}` : uav.state}`);
    text(
      item.title,
      `${id}: ${uav.state} (${t.flight_state}, ${t.mode})\n` +
        `heading ${Math.round(t.heading_deg)}°, altitude ${p.z_m.toFixed(1)} m\n` +
        `battery ${pct(t.battery_fraction)} (${t.battery_wh.toFixed(1)} Wh)` +
        (t.tool ? `, carrying ${t.tool}` : "") +
        `\ntask ${task ? task.task_id : "none"}`,
    );
    const track = s.tracks.get(id) || [];
    const line = layers.trackItems.get(id);
    attr(line, "points", track.map(([x, y]) => `${round(x)},${round(-y)}`).join(" "));
    toggle(line, "selected", s.selected === id);
    const route = layers.routeItems.get(id);
    attr(route, "points", routePoints(s, id, p));
    toggle(route, "selected", s.selected === id);
  }
  layers.uavItems.prune(keep);
  layers.trackItems.prune(keep);
  layers.routeItems.prune(keep);
}

/** The planned route ahead: the UAV, then each remaining task's targets. */
function routePoints(s, id, here) {
  const plan = s.plans.get(id);
  if (!plan || !plan.tasks.length) return "";
  const current = currentTask(id);
  let from = current ? plan.tasks.findIndex((t) => t.task_id === current.task_id) : 0;
  if (from < 0) from = 0;
  const points = [pt(here)];
  for (const task of plan.tasks.slice(from)) for (const p of taskTargets(task)) points.push(pt(p));
  return points.length > 1 ? points.join(" ") : "";
}
