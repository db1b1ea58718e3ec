// The fleet table: one row per UAV, kept by id, cells updated in place.

import { el, Keyed, pct, text, toggle } from "./dom.js";
import { byId, currentTask, onRender, select } from "./store.js";

const COLUMNS = ["uav", "state", "flight", "battery", "alt", "heading", "task", "epoch"];

let rows;

export function initFleet(table) {
  const body = table.tBodies[0];
  rows = new Keyed(body, (id) => {
    const tr = el("tr", { "data-uav": id });
    const cells = {};
    for (const name of COLUMNS) cells[name] = el("td", { class: `c-${name}` }, tr);
    return { node: tr, cells };
  });
  body.addEventListener("click", (event) => {
    const tr = event.target.closest("tr[data-uav]");
    if (tr) select(tr.dataset.uav);
  });
  onRender("fleet", render);
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
    text(c.state, uav.state);
    row.node.dataset.state = uav.state;
    text(c.flight, t ? `${t.flight_state}${t.mode ? ` ${t.mode}` : ""}` : "-");
    text(c.battery, t ? pct(t.battery_fraction) : "-");
    toggle(c.battery, "low", t && t.battery_fraction < 0.2);
    text(c.alt, t ? t.position.z_m.toFixed(1) : "-");
    text(c.heading, t ? `${Math.round(t.heading_deg)}°` : "-");
    const progress = uav.status && uav.status.task_id ? ` ${pct(uav.status.progress)}` : "";
    text(c.task, task ? `${task.task_id}${progress}` : "-");
    text(c.epoch, plan ? plan.epoch : uav.status ? uav.status.epoch : "-");
    toggle(row.node, "selected", s.selected === id);
  }
  rows.prune(new Set(ids));
  rows.order(ids);
}
