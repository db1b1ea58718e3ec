// The fleet table: one row per UAV, kept by id, cells updated in place;
// its control cell takes a UAV out of the plan (hold, return, land) and
// gives it back (resume); "hold all" above the table is a fleet stop.

import { api } from "./api.js";
import { attr, el, Keyed, pct, text, timeOfDay, toggle } from "./dom.js";
import { byId, currentTask, onRender, select, setFleet } from "./store.js";

const COLUMNS = ["uav", "state", "flight", "battery", "alt", "heading", "task", "epoch", "control"];
const COMMANDS = { hold: "H", return: "R", land: "L", resume: "\u25b6" }; // label: see the header

let rows;

export function initFleet(table) {
  const body = table.tBodies[0];
  rows = new Keyed(body, (id) => {
    const tr = el("tr", { "data-uav": id });
    const cells = {};
    for (const name of COLUMNS) cells[name] = el("td", { class: `c-${name}` }, tr);
    for (const [command, label] of Object.entries(COMMANDS)) {
      const attrs = { type: "button", "data-command": command, title: command, text: label };
      el("button", attrs, cells.control);
    }
    return { node: tr, cells };
  });
  body.addEventListener("click", (event) => {
    const button = event.target.closest("button[data-command]");
    const tr = event.target.closest("tr[data-uav]");
    if (button && tr) command(`v1/uavs/${encodeURIComponent(tr.dataset.uav)}/control`, button);
    else if (tr) select(tr.dataset.uav);
  });
  const all = document.getElementById("hold-all");
  if (all) all.addEventListener("click", () => command("v1/fleet/control", all, "hold"));
  onRender("fleet", render);
}

async function command(path, button, name = button.dataset.command) {
  const said = document.getElementById("control-result");
  try {
    setFleet(await api("POST", path, { command: name }));
    if (said) text(said, `${name}: sent`);
  } catch (exc) {
    if (said) text(said, `${name} refused: ${exc.code}: ${exc.message}`);
  }
}

/** "silent since HH:MM:SS, N s" (mission clock) for a silent UAV, else "". */
export function silenceText(uav) {
  if (!uav.silent_s) return "";
  const since = uav.silent_since_s != null ? ` since ${timeOfDay(uav.silent_since_s)},` : "";
  return `silent${since} ${Math.round(uav.silent_s)} s`;
}

/** The UAV's state, with what keeps it waiting: silence, another UAV at its next point. */
export function stateText(uav) {
  const silence = silenceText(uav);
  let said = silence ? `${uav.state} (${silence})` : uav.state;
  const other = uav.status && uav.status.holding_for;
  if (other) said += ` · holding off for ${other}`;
  return said;
}

function render(s) {
  const ids = byId(s.fleet.keys());
  for (const id of ids) {
    const uav = s.fleet.get(id);
    const t = uav.telemetry;
    const row = rows.get(id);
    const c = row.cells;
    const task = currentTask(id);
    const plan = s.plans.get(id);
    text(c.uav, id);
    text(c.state, stateText(uav));
    row.node.dataset.state = uav.state;
    text(c.flight, t ? `${t.flight_state}${t.mode ? ` ${t.mode}` : ""}` : "-");
    text(c.battery, t ? pct(t.battery_fraction) : "-");
    toggle(c.battery, "low", t && t.battery_fraction < 0.2);
    text(c.alt, t ? t.position.z_m.toFixed(1) : "-");
    text(c.heading, t ? `${Math.round(t.heading_deg)}°` : "-");
    const progress = uav.status && uav.status.task_id ? ` ${pct(uav.status.progress)}` : "";
    const unknown = uav.unknown_tasks && uav.unknown_tasks.length ? uav.unknown_tasks : null;
    text(c.task, unknown ? `${unknown[0]} unknown` : task ? `${task.task_id}${progress}` : "-");
    toggle(c.task, "unknown", unknown);
    row.node.dataset.silent = uav.silent_s ? "yes" : "";
    text(c.epoch, plan ? plan.epoch : uav.status ? uav.status.epoch : "-");
    for (const button of c.control.querySelectorAll("button")) {
      attr(button, "aria-pressed", String(button.dataset.command === uav.control));
    }
    row.node.dataset.control = uav.control || "";
    toggle(row.node, "selected", s.selected === id);
  }
  rows.prune(new Set(ids));
  rows.order(ids);
}
