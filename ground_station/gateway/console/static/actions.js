// The actions table (state, progress, priority, failure reason; change
// priority, cancel) and the forms that submit inspect, monitor and deliver
// actions, with the same bodies as `linecrew submit`.

import { api } from "./api.js";
import { el, Keyed, pct, text, toggle } from "./dom.js";
import { onRender, state, unknownTasks, upsertAction } from "./store.js";

const TERMINAL = new Set(["completed", "failed", "cancelled"]);
const COLUMNS = ["id", "type", "what", "state", "progress", "priority", "reason", "ops"];

let rows;
let result;

export function initActions(table, forms, resultNode) {
  result = resultNode;
  const body = table.tBodies[0];
  rows = new Keyed(body, makeRow);
  body.addEventListener("click", (event) => {
    const button = event.target.closest("button[data-role]");
    if (!button) return;
    const id = button.closest("tr").dataset.action;
    if (button.dataset.role === "cancel") cancel(id);
    if (button.dataset.role === "set-priority") setPriority(id);
  });
  forms.inspect.addEventListener("submit", (e) => submit(e, inspectBody));
  forms.monitor.addEventListener("submit", (e) => submit(e, monitorBody));
  forms.deliver.addEventListener("submit", (e) => submit(e, deliverBody));
  onRender("actions", render);
  onRender("forms", () => fillForms(forms));
}

function makeRow(id) {
  const tr = el("tr", { "data-action": id });
  const c = {};
  for (const name of COLUMNS) c[name] = el("td", { class: `c-${name}` }, tr);
  const bar = el("progress", { max: 1, value: 0 }, c.progress);
  const share = el("span", {}, c.progress);
  const priority = el("input", { type: "number", min: 0.1, step: 0.1, "data-role": "priority" }, c.priority);
  el("button", { type: "button", class: "small", "data-role": "set-priority", text: "set" }, c.priority);
  const cancelButton = el("button", { type: "button", class: "small danger", "data-role": "cancel", text: "cancel" }, c.ops);
  return { node: tr, c, bar, share, priority, cancelButton };
}

function summary(a) {
  switch (a.type) {
    case "inspect":
      return a.waypoints.map((w) => `${w.position.x_m},${w.position.y_m},${w.position.z_m}`).join("; ");
    case "monitor":
      return `${a.worker_id} · k=${a.uavs} · ${a.duration_s} s · ${a.standoff_m} m`;
    case "deliver":
      return `${a.tool} from ${a.tool_station_id} to ${a.worker_id}`;
    default:
      return "";
  }
}

/** The actions with a task whose UAV is silent (their fate is unknown). */
function unknownActions(s) {
  const unknown = unknownTasks();
  const out = new Set();
  for (const plan of s.plans.values()) {
    for (const t of plan.tasks) if (t.action_id && unknown.has(t.task_id)) out.add(t.action_id);
  }
  return out;
}

function render(s) {
  const records = [...s.actions.values()].sort((a, b) => b.created_s - a.created_s);
  const unknown = unknownActions(s);
  for (const r of records) {
    const row = rows.get(r.action_id);
    const c = row.c;
    text(c.id, r.action_id);
    text(c.type, r.action.type);
    text(c.what, summary(r.action));
    const fate = unknown.has(r.action_id) && !TERMINAL.has(r.state);
    text(c.state, fate ? `${r.state} · unknown` : r.state);
    toggle(c.state, "unknown", fate);
    row.node.dataset.state = r.state;
    row.node.dataset.fate = fate ? "unknown" : "";
    row.bar.value = r.progress;
    text(row.share, ` ${pct(r.progress)}`);
    if (document.activeElement !== row.priority && row.priority.dataset.shown !== String(r.action.priority)) {
      row.priority.value = r.action.priority;
      row.priority.dataset.shown = String(r.action.priority);
    }
    const done = TERMINAL.has(r.state);
    row.priority.disabled = done;
    row.cancelButton.hidden = done;
    text(c.reason, r.reason || "");
    toggle(c.reason, "failure", r.state === "failed");
  }
  rows.prune(new Set(records.map((r) => r.action_id)));
  rows.order(records.map((r) => r.action_id));
}

function say(message, ok) {
  text(result, message);
  result.dataset.ok = ok ? "yes" : "no";
}

function failure(what, exc) {
  const field = exc.field ? ` (field ${exc.field})` : "";
  say(`${what} refused: ${exc.status || ""} ${exc.code}: ${exc.message}${field}`, false);
}

async function cancel(id) {
  try {
    upsertAction(await api("DELETE", `v1/actions/${encodeURIComponent(id)}`));
    say(`${id} cancelled`, true);
  } catch (exc) {
    failure(`cancel ${id}`, exc);
  }
}

async function setPriority(id) {
  const row = rows.get(id);
  const priority = Number(row.priority.value);
  try {
    const record = await api("PATCH", `v1/actions/${encodeURIComponent(id)}`, { priority });
    row.priority.dataset.shown = "";
    upsertAction(record);
    say(`${id} priority ${priority}`, true);
  } catch (exc) {
    failure(`priority of ${id}`, exc);
  }
}

/** "x,y,z; x,y,z[,service]" -> waypoint specs (throws on a bad point). */
export function parseWaypoints(textValue) {
  const parts = textValue.split(";").map((p) => p.trim()).filter(Boolean);
  if (!parts.length) throw new Error("no waypoint given");
  return parts.map((part) => {
    const values = part.split(",").map((v) => Number(v.trim()));
    if ((values.length !== 3 && values.length !== 4) || values.some((v) => !Number.isFinite(v))) {
      throw new Error(`"${part}": expected x,y,z[,service_s]`);
    }
    const [x, y, z, service] = values;
    return { position: { x_m: x, y_m: y, z_m: z }, service_s: service || 0 };
  });
}

function inspectBody(f) {
  return { type: "inspect", priority: Number(f.priority.value), waypoints: parseWaypoints(f.waypoints.value) };
}

function monitorBody(f) {
  return {
    type: "monitor",
    priority: Number(f.priority.value),
    worker_id: f.worker.value,
    uavs: Number(f.k.value),
    duration_s: Number(f.duration.value),
    standoff_m: Number(f.standoff.value),
  };
}

function deliverBody(f) {
  const [station, tool] = f.tool.value.split("/");
  return { type: "deliver", priority: Number(f.priority.value), tool, tool_station_id: station, worker_id: f.worker.value };
}

async function submit(event, build) {
  event.preventDefault();
  const form = event.target;
  let body;
  try {
    body = build(form.elements);
  } catch (exc) {
    say(`not submitted: ${exc.message}`, false);
    return;
  }
  body.request_id = crypto.randomUUID ? crypto.randomUUID() : `console-${Date.now()}-${Math.random()}`;
  const button = form.querySelector("button[type=submit]");
  button.disabled = true;
  try {
    const record = await api("POST", "v1/actions", body);
    upsertAction(record);
    say(`${record.action_id} accepted (${body.type})`, true);
    result.dataset.action = record.action_id;
  } catch (exc) {
    failure(body.type, exc);
  } finally {
    button.disabled = false;
  }
}

function fillForms(forms) {
  const site = state.site;
  if (!site) return;
  const workers = site.workers.map((w) => [w.id, w.id]);
  fill(forms.monitor.elements.worker, workers);
  fill(forms.deliver.elements.worker, workers);
  const tools = [];
  for (const ts of site.tool_stations) {
    for (const t of ts.tools) tools.push([`${ts.id}/${t.name}`, `${t.name} (${ts.id})`]);
  }
  fill(forms.deliver.elements.tool, tools);
}

export function fill(select, options) {
  const keep = select.value;
  select.replaceChildren(...options.map(([value, label]) => el("option", { value, text: label })));
  if (options.some(([value]) => value === keep)) select.value = keep;
}
