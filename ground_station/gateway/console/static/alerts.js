// Alerts: from ground-station events (UAV silent / heard again / lost / crashed / back, action
// failed with its reason, faults such as a battery below plan) and from the
// console itself (a fault it injected, a battery below the reserve seen in
// telemetry). Each stays in the list until the operator acknowledges it;
// acknowledgements live in sessionStorage keyed by the event's seq (local
// alerts by their own key), so a reload keeps them.

import { el, text } from "./dom.js";
import { invalidate, onRender } from "./store.js";

const ACKED_KEY = "linecrew.console.acked";
const LOCAL_KEY = "linecrew.console.local-alerts";
const EPISODES_KEY = "linecrew.console.battery-episodes";
export const BATTERY_LOW = 0.2; // below the usual reserve fraction
const BATTERY_OK = 0.35; // a new episode only after recovering above this
const RANK = { critical: 0, error: 1, warning: 2, info: 3 };

const alerts = new Map(); // key -> alert, in arrival order
const lost = new Set(); // UAVs seen lost or crashed (so uav_back is "link back")
const silent = new Set(); // UAVs seen silent and neither heard again nor lost since
const acked = new Set(load(ACKED_KEY, []));
const episodes = load(EPISODES_KEY, {});
const nodes = new Map(); // key -> li

let list;
let ackedList;

function load(key, fallback) {
  try {
    return JSON.parse(sessionStorage.getItem(key)) ?? fallback;
  } catch {
    return fallback;
  }
}

function save(key, value) {
  sessionStorage.setItem(key, JSON.stringify(value));
}

export function initAlerts(listNode, ackedNode, ackAll) {
  list = listNode;
  ackedList = ackedNode;
  for (const alert of load(LOCAL_KEY, [])) alerts.set(alert.key, alert);
  const onClick = (event) => {
    const button = event.target.closest("button[data-role=ack]");
    if (button) acknowledge(button.closest("li").dataset.key);
  };
  list.addEventListener("click", onClick);
  ackAll.addEventListener("click", () => {
    for (const key of alerts.keys()) acked.add(key);
    save(ACKED_KEY, [...acked]);
    invalidate("alerts");
  });
  onRender("alerts", render);
  onRender("alerts-fleet", watchBatteries);
  invalidate("alerts");
}

export function acknowledge(key) {
  acked.add(key);
  save(ACKED_KEY, [...acked]);
  invalidate("alerts");
}

/** The alert a ground-station event raises, if any. */
function fromEvent(e) {
  const uav = e.uav_id ? `${e.uav_id}: ` : "";
  const action = e.action_id ? `${e.action_id}: ` : "";
  switch (e.kind) {
    case "uav_silent":
      silent.add(e.uav_id);
      return { severity: "warning", title: "UAV silent", detail: `${uav}${e.detail}` };
    case "uav_heard":
      if (!silent.delete(e.uav_id)) return null;
      return { severity: "info", title: "UAV heard again", detail: `${uav}${e.detail}` };
    case "uav_lost":
      silent.delete(e.uav_id);
      lost.add(e.uav_id);
      return { severity: "critical", title: "UAV lost", detail: `${uav}${e.detail}` };
    case "uav_crashed":
      lost.add(e.uav_id);
      return { severity: "critical", title: "UAV crashed", detail: `${uav}${e.detail}` };
    case "uav_back":
      if (!lost.delete(e.uav_id)) return null; // first contact at start-up: no alert
      return { severity: "info", title: "Link back", detail: `${uav}${e.detail}` };
    case "uav_state":
      return { severity: "info", title: "UAV not ready", detail: `${uav}${e.detail}` };
    case "action_failed":
      return { severity: "error", title: "Action failed", detail: `${action}${e.detail || "no reason given"}` };
    case "fault":
      if (/^battery/.test(e.detail)) {
        return { severity: "warning", title: "Battery low", detail: `${uav}${e.detail}` };
      }
      return { severity: "warning", title: "Fault", detail: `${uav}${action}${e.detail}` };
    default:
      return null;
  }
}

export function onEvent(e) {
  const alert = fromEvent(e);
  if (!alert) return;
  const key = String(e.seq);
  if (alerts.has(key)) return;
  alerts.set(key, { ...alert, key, seq: e.seq, uav: e.uav_id, at: Date.now(), source: e.kind });
  invalidate("alerts");
}

/** An alert raised by the console itself (kept in sessionStorage). */
export function raiseLocal(key, severity, title, detail, uav = null) {
  if (alerts.has(key)) return;
  alerts.set(key, { key, severity, title, detail, uav, at: Date.now(), source: "console" });
  save(LOCAL_KEY, [...alerts.values()].filter((a) => a.source === "console"));
  invalidate("alerts");
}

function watchBatteries(s) {
  let changed = false;
  for (const [id, uav] of s.fleet) {
    const t = uav.telemetry;
    if (!t) continue;
    if (t.battery_fraction < BATTERY_LOW && !episodes[id]) {
      episodes[id] = `battery:${id}:${Date.now()}`;
      raiseLocal(episodes[id], "warning", "Battery low", `${id}: battery at ${Math.round(t.battery_fraction * 100)}% (${t.battery_wh.toFixed(1)} Wh), below ${BATTERY_LOW * 100}%`, id);
      changed = true;
    } else if (t.battery_fraction > BATTERY_OK && episodes[id]) {
      delete episodes[id];
      changed = true;
    }
  }
  if (changed) save(EPISODES_KEY, episodes);
}

function makeNode(alert) {
  const li = el("li", { class: `alert sev-${alert.severity}`, "data-key": alert.key, "data-severity": alert.severity });
  el("span", { class: "sev", text: alert.severity }, li);
  el("strong", { class: "title", text: alert.title }, li);
  el("span", { class: "detail", text: alert.detail }, li);
  const when = new Date(alert.at).toLocaleTimeString();
  el("span", { class: "when muted", text: alert.seq !== undefined ? `${when} · seq ${alert.seq}` : when }, li);
  el("button", { type: "button", class: "small", "data-role": "ack", text: "acknowledge" }, li);
  return li;
}

function render() {
  const open = [];
  const done = [];
  for (const alert of alerts.values()) (acked.has(alert.key) ? done : open).push(alert);
  // unacknowledged: most severe first, newest first within a severity
  open.sort((a, b) => RANK[a.severity] - RANK[b.severity] || b.at - a.at || (b.seq ?? 0) - (a.seq ?? 0));
  done.reverse();
  place(list, open, false);
  place(ackedList, done, true);
  const count = document.getElementById("alert-count");
  text(count, `${open.length} alert${open.length === 1 ? "" : "s"}`);
  count.dataset.count = String(open.length);
  count.dataset.severity = open.length ? open[0].severity : "";
  text(document.getElementById("acked-count"), done.length);
}

function place(parent, items, isAcked) {
  let expected = parent.firstChild;
  for (const alert of items) {
    let li = nodes.get(alert.key);
    if (!li) {
      li = makeNode(alert);
      nodes.set(alert.key, li);
    }
    li.classList.toggle("acked", isAcked);
    li.querySelector("button").hidden = isAcked;
    if (li !== expected) parent.insertBefore(li, expected);
    else expected = expected.nextSibling;
  }
}
