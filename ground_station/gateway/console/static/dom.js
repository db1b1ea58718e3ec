// Small DOM helpers: create elements, and update attributes or text only
// when they change (so 50 UAVs at 5 Hz touch few nodes).

const SVG_NS = "http://www.w3.org/2000/svg";

/** A new element: tag "svg:rect" makes an SVG element. */
export function el(tag, attrs = {}, parent = null) {
  const node = tag.startsWith("svg:")
    ? document.createElementNS(SVG_NS, tag.slice(4))
    : document.createElement(tag);
  for (const [name, value] of Object.entries(attrs)) {
    if (name === "text") node.textContent = value;
    else node.setAttribute(name, value);
  }
  if (parent) parent.appendChild(node);
  return node;
}

/** Set an attribute if its value differs (numbers rounded to 0.01). */
export function attr(node, name, value) {
  const text = typeof value === "number" ? String(Math.round(value * 100) / 100) : String(value);
  if (node.getAttribute(name) !== text) node.setAttribute(name, text);
}

export function text(node, value) {
  const s = String(value);
  if (node.textContent !== s) node.textContent = s;
}

export function toggle(node, cls, on) {
  if (node.classList.contains(cls) !== Boolean(on)) node.classList.toggle(cls, Boolean(on));
}

/**
 * Elements keyed by id under `parent`: get(key) creates one with
 * create(key) the first time; prune(keys) removes those not in `keys`.
 */
export class Keyed {
  constructor(parent, create) {
    this.parent = parent;
    this.create = create;
    this.items = new Map();
  }

  get(key) {
    let item = this.items.get(key);
    if (!item) {
      item = this.create(key);
      this.items.set(key, item);
      const node = item.node || item;
      if (!node.parentNode) this.parent.appendChild(node);
    }
    return item;
  }

  has(key) {
    return this.items.has(key);
  }

  prune(keep) {
    for (const [key, item] of this.items) {
      if (!keep.has(key)) {
        (item.node || item).remove();
        this.items.delete(key);
      }
    }
  }

  /** Put the nodes of `keys` in that order (moves only when needed). */
  order(keys) {
    let expected = this.parent.firstChild;
    for (const key of keys) {
      const item = this.items.get(key);
      if (!item) continue;
      const node = item.node || item;
      if (node !== expected) this.parent.insertBefore(node, expected);
      else expected = expected.nextSibling;
    }
  }
}

/** Seconds as "+1:05" / "-12 s" relative to now. */
export function relative(seconds) {
  const sign = seconds < 0 ? "-" : "+";
  const s = Math.abs(seconds);
  if (s < 60) return `${sign}${Math.round(s)} s`;
  const m = Math.floor(s / 60);
  const r = Math.round(s - m * 60);
  return `${sign}${m}:${String(r).padStart(2, "0")}`;
}

/** Mission seconds as the mission clock's time of day, "HH:MM:SS" (UTC). */
export function timeOfDay(seconds) {
  const s = Math.floor(seconds) % 86400;
  const two = (n) => String(n).padStart(2, "0");
  return `${two(Math.floor(s / 3600))}:${two(Math.floor(s / 60) % 60)}:${two(s % 60)}`;
}

export function pct(fraction) {
  return `${Math.round((fraction || 0) * 100)}%`;
}
