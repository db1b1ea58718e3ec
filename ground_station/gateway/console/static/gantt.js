// The plan as a Gantt chart: one row per UAV, one bar per planned task
// (coloured by kind, labelled with its action), a "now" line on the
// mission clock, each row's plan epoch. Rows and bars are kept by id.

import { attr, el, Keyed, relative, text, timeOfDay, toggle } from "./dom.js";
import { byId, missionNow, onRender, select, unknownTasks } from "./store.js";

export const KINDS = {
  inspect: "inspect",
  monitor: "monitor",
  pick: "pick",
  deliver: "deliver",
  recharge: "recharge",
  wait: "wait",
  home: "home",
};

const LEFT = 110; // label column, px
const ROW = 24; // row height, px
const TOP = 22; // tick labels, px
const STEPS = [1, 2, 5, 10, 15, 30, 60, 120, 300, 600, 900, 1800, 3600, 7200];

let svg;
let rows;
let bars;
let ticks;
let nowLine;
let nowLabel;

export function initGantt(node, legend) {
  svg = node;
  for (const kind of Object.keys(KINDS)) {
    el("span", { class: `key kind-${kind}`, text: kind }, legend);
  }
  el("span", { class: "key fate-unknown", text: "unknown (its UAV is silent)" }, legend);
  const rowLayer = el("svg:g", { class: "rows" }, svg);
  const tickLayer = el("svg:g", { class: "ticks" }, svg);
  const barLayer = el("svg:g", { class: "bars" }, svg);
  nowLine = el("svg:line", { class: "gantt-now" }, svg);
  nowLabel = el("svg:text", { class: "gantt-now-label", text: "now" }, svg);
  rows = new Keyed(rowLayer, (id) => {
    const g = el("svg:g", { class: "gantt-row", "data-uav": id });
    const bg = el("svg:rect", { class: "row-bg", x: 0, height: ROW }, g);
    const label = el("svg:text", { class: "row-label", x: 6 }, g);
    return { node: g, bg, label };
  });
  bars = new Keyed(barLayer, () => {
    const g = el("svg:g", { class: "bar" });
    const rect = el("svg:rect", { height: ROW - 6, rx: 3 }, g);
    const label = el("svg:text", { class: "bar-label" }, g);
    const title = el("svg:title", {}, g);
    return { node: g, rect, label, title };
  });
  ticks = new Keyed(tickLayer, () => {
    const g = el("svg:g", { class: "tick" });
    return { node: g, line: el("svg:line", {}, g), label: el("svg:text", {}, g) };
  });
  svg.addEventListener("click", (event) => {
    const target = event.target.closest("[data-uav]");
    if (target) select(target.dataset.uav);
  });
  onRender("gantt", render);
}

let shown = null; // [t0, t1]: kept while it still fits, so bars stay put

/** The time axis: from a little before now (or the first task) to the last
 * task's end; kept as is while it still fits well, so that only the "now"
 * line moves between replans. */
function domain(s, now) {
  let first = Infinity;
  let last = -Infinity;
  for (const plan of s.plans.values()) {
    for (const t of plan.tasks) {
      first = Math.min(first, t.start_s);
      last = Math.max(last, t.end_s);
    }
  }
  if (now === null) now = Number.isFinite(first) ? first : 0;
  let t0 = now - 10;
  let t1 = now + 120;
  if (Number.isFinite(first)) {
    t0 = Math.min(Math.max(first, now - 60), now - 5);
    t1 = Math.max(last, now + 60);
    t1 += (t1 - t0) * 0.02;
  }
  if (shown) {
    const [a, b] = shown;
    const span = b - a;
    const fits = a <= t0 && b >= t1 && now < a + 0.8 * span && t1 - t0 > 0.6 * span;
    if (fits) return [a, b, now];
  }
  shown = [t0, t0 + (t1 - t0) * 1.15]; // some room ahead before the next re-fit
  return [...shown, now];
}

function render(s) {
  const width = Math.max(svg.clientWidth || svg.parentNode.clientWidth || 600, 300);
  const ids = byId(new Set([...s.fleet.keys(), ...s.plans.keys()]));
  const height = TOP + ids.length * ROW + 4;
  attr(svg, "height", height);
  attr(svg, "viewBox", `0 0 ${width} ${height}`);
  const [t0, t1, now] = domain(s, missionNow());
  const scale = (width - LEFT - 8) / (t1 - t0);
  const X = (t) => LEFT + (Math.min(Math.max(t, t0), t1) - t0) * scale;

  drawTicks(t0, t1, now, X, height);
  attr(nowLine, "x1", X(now));
  attr(nowLine, "x2", X(now));
  attr(nowLine, "y1", TOP - 4);
  attr(nowLine, "y2", height);
  attr(nowLabel, "x", X(now) + 3);
  attr(nowLabel, "y", TOP - 8);

  const keepBars = new Set();
  const unknown = unknownTasks();
  let latest = null;
  ids.forEach((id, i) => {
    const y = TOP + i * ROW;
    const row = rows.get(id);
    const plan = s.plans.get(id);
    attr(row.bg, "y", y);
    attr(row.bg, "width", width);
    attr(row.label, "y", y + ROW / 2 + 4);
    text(row.label, plan ? `${id}  e${plan.epoch}` : id);
    toggle(row.node, "selected", s.selected === id);
    if (!plan) return;
    if (!latest || plan.epoch > latest.epoch) latest = plan;
    plan.tasks.forEach((task, n) => {
      if (task.end_s < t0) return;
      const key = `${id}|${n}`; // by position: a replan updates bars, it does not rebuild them
      keepBars.add(key);
      const bar = bars.get(key);
      const x = X(task.start_s);
      const w = Math.max(X(task.end_s) - x, 2);
      const silent = unknown.get(task.task_id);
      const fate = silent ? " unknown" : "";
      attr(bar.node, "class", `bar kind-${task.type}${fate}${s.selected === id ? " selected" : ""}`);
      attr(bar.node, "data-fate", silent ? "unknown" : "");
      attr(bar.node, "data-uav", id);
      attr(bar.node, "data-task", task.task_id);
      attr(bar.node, "data-kind", task.type);
      attr(bar.node, "data-action", task.action_id || "");
      attr(bar.rect, "x", x);
      attr(bar.rect, "y", y + 3);
      attr(bar.rect, "width", w);
      const label = task.action_id || task.type;
      attr(bar.label, "x", x + 4);
      attr(bar.label, "y", y + ROW / 2 + 4);
      text(bar.label, w > label.length * 7 + 8 ? label : "");
      text(
        bar.title,
        `${task.type} ${task.task_id}` +
          (task.action_id ? `\naction ${task.action_id}` : "") +
          `\n${relative(task.start_s - now)} → ${relative(task.end_s - now)} (${Math.round(task.end_s - task.start_s)} s)` +
          `\nenergy after ${task.energy_after_wh.toFixed(1)} Wh\nplan epoch ${plan.epoch}` +
          (silent ? `\nfate unknown: ${id} silent since ${timeOfDay(silent.silent_since_s)}` : ""),
      );
    });
  });
  rows.prune(new Set(ids));
  bars.prune(keepBars);
  const epoch = document.getElementById("gantt-epoch");
  if (epoch) {
    text(epoch, latest ? `latest epoch ${latest.epoch} (${latest.uav_id})` : "no plan yet");
    epoch.dataset.epoch = latest ? String(latest.epoch) : "";
  }
}

function drawTicks(t0, t1, now, X, height) {
  const span = t1 - t0;
  const step = STEPS.find((s) => span / s <= 8) || STEPS[STEPS.length - 1];
  const keep = new Set();
  // ticks at fixed mission times (they stay put), labelled relative to now
  for (let k = Math.ceil(t0 / step); k * step <= t1; k++) {
    const at = k * step;
    if (Math.abs(at - now) < step * 0.3) continue; // the "now" label is there
    keep.add(k);
    const tick = ticks.get(k);
    const x = X(at);
    attr(tick.line, "x1", x);
    attr(tick.line, "x2", x);
    attr(tick.line, "y1", TOP - 4);
    attr(tick.line, "y2", height);
    attr(tick.label, "x", x - 12);
    attr(tick.label, "y", TOP - 8);
    text(tick.label, relative(at - now));
  }
  ticks.prune(keep);
}
