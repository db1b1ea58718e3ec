// The simulation panel: inject the faults of `linecrew fault` (see
// linecrew_runtime/fault_kinds.py and proto/sim.py) through POST /v1/sim/faults.
// Shown when the gateway offers that endpoint; a gateway without a
// simulator answers 503, which the panel says.

import { api } from "./api.js";
import { fill } from "./actions.js";
import { raiseLocal } from "./alerts.js";
import { el, text } from "./dom.js";
import { byId, onRender, state } from "./store.js";

// kind -> [help, [[field, label, default]], body builder]
export const FAULTS = {
  battery: ["set the battery to a fraction", [["fraction", "fraction 0..1", 0.15]], (t, v) => ({ type: "battery", uav_id: t, fraction: v.fraction })],
  drain: ["multiply power draw", [["multiplier", "factor", 3]], (t, v) => ({ type: "drain", uav_id: t, multiplier: v.multiplier })],
  motor: ["motors fail (it falls)", [], (t) => ({ type: "motor", uav_id: t })],
  kill: ["silent and falling", [], (t) => ({ type: "kill", uav_id: t })],
  link: ["MAVLink silent for seconds", [["duration_s", "seconds", 10]], (t, v) => ({ type: "link", uav_id: t, duration_s: v.duration_s })],
  gps: ["position frozen for seconds", [["duration_s", "seconds", 10]], (t, v) => ({ type: "gps", uav_id: t, duration_s: v.duration_s })],
  gripper: ["gripper fails", [], (t) => ({ type: "gripper", uav_id: t, failed: true })],
  "gripper-repair": ["gripper works again", [], (t) => ({ type: "gripper", uav_id: t, failed: false })],
  "move-worker": [
    "put a worker at x, y, z",
    [["x", "x m", 0], ["y", "y m", 0], ["z", "z m", 3]],
    (t, v) => ({ type: "move_worker", worker_id: t, position: { x_m: v.x, y_m: v.y, z_m: v.z } }),
  ],
};

let form;
let values;
let result;
let targetsShown = "";

export async function initSim(panel, formNode, valuesNode, resultNode) {
  form = formNode;
  values = valuesNode;
  result = resultNode;
  let spec = null;
  try {
    spec = await (await fetch("openapi.json", { cache: "no-store" })).json();
  } catch {
    spec = null;
  }
  if (!spec || !spec.paths || !spec.paths["/v1/sim/faults"]) return;
  panel.hidden = false;
  fill(form.elements.kind, Object.entries(FAULTS).map(([kind, [help]]) => [kind, `${kind}: ${help}`]));
  form.elements.kind.addEventListener("change", () => {
    showValues();
    targetsShown = "";
    fillTargets(state);
  });
  form.addEventListener("submit", inject);
  showValues();
  onRender("sim", fillTargets);
  fillTargets(state);
}

function showValues() {
  const [, fields] = FAULTS[form.elements.kind.value];
  values.replaceChildren();
  for (const [name, label, value] of fields) {
    const wrap = el("label", { text: `${label} ` }, values);
    el("input", { name, type: "number", step: "any", value }, wrap);
  }
}

function fillTargets(s) {
  const worker = form.elements.kind.value === "move-worker";
  const ids = worker ? (s.site ? s.site.workers.map((w) => w.id) : []) : byId(s.fleet.keys());
  const key = ids.join(",");
  if (key === targetsShown) return;
  targetsShown = key;
  fill(form.elements.target, ids.map((id) => [id, id]));
}

async function inject(event) {
  event.preventDefault();
  const kind = form.elements.kind.value;
  const target = form.elements.target.value;
  const given = {};
  for (const input of values.querySelectorAll("input")) given[input.name] = Number(input.value);
  const body = FAULTS[kind][2](target, given);
  try {
    const applied = await api("POST", "v1/sim/faults", body);
    text(result, `${applied.target}: ${applied.detail} (sim t=${applied.sim_time_s.toFixed(1)} s)`);
    result.dataset.ok = "yes";
    raiseLocal(
      `fault:${applied.target}:${applied.sim_time_s}`,
      "warning",
      "Fault injected",
      `${applied.target}: ${kind}: ${applied.detail}`,
      kind === "move-worker" ? null : target,
    );
  } catch (exc) {
    const why = exc.status === 503 ? "no simulator answered (503)" : `${exc.status} ${exc.code}: ${exc.message}`;
    text(result, `fault not injected: ${why}`);
    result.dataset.ok = "no";
  }
}
