// The gateway's REST API and event stream, with the operator's bearer token.
//
// The token comes from the URL fragment (#token=..., which browsers never
// send to the server), else from sessionStorage, else a prompt; it is kept
// in sessionStorage (this tab only) and removed from the address bar.

const TOKEN_KEY = "linecrew.console.token";

export class ApiError extends Error {
  constructor(status, body) {
    const message = (body && body.message) || `HTTP ${status}`;
    super(message);
    this.status = status;
    this.code = (body && body.error) || `http_${status}`;
    this.field = (body && body.field) || null;
  }
}

/** Options from the URL fragment: token=...&poll=MS (the token is removed). */
export function readFragment() {
  const params = new URLSearchParams(location.hash.replace(/^#/, ""));
  const token = params.get("token");
  if (token) {
    sessionStorage.setItem(TOKEN_KEY, token);
    params.delete("token");
    const rest = params.toString();
    history.replaceState(null, "", location.pathname + location.search + (rest ? `#${rest}` : ""));
  }
  return params;
}

export function token() {
  return sessionStorage.getItem(TOKEN_KEY) || "";
}

/** Ask the operator for a token; true if one was given. */
export function askToken(message = "Bearer token of the linecrew gateway") {
  const given = window.prompt(message, "");
  if (given && given.trim()) {
    sessionStorage.setItem(TOKEN_KEY, given.trim());
    return true;
  }
  return false;
}

const listeners = { auth: [], status: [] };

/** React to 401 answers (fn(error)) and to API reachability (fn(ok, error)). */
export function on(what, fn) {
  listeners[what].push(fn);
}

function emit(what, ...args) {
  for (const fn of listeners[what]) fn(...args);
}

/** One API call; the decoded JSON answer, or an ApiError. */
export async function api(method, path, body) {
  const headers = { Authorization: `Bearer ${token()}` };
  const init = { method, headers, cache: "no-store" };
  if (body !== undefined) {
    headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  let response;
  try {
    response = await fetch(path, init);
  } catch (exc) {
    const error = new ApiError(0, { error: "network", message: `gateway unreachable: ${exc}` });
    emit("status", false, error);
    throw error;
  }
  const text = await response.text();
  let data = null;
  try {
    data = text ? JSON.parse(text) : null;
  } catch {
    data = { message: text };
  }
  if (!response.ok) {
    const error = new ApiError(response.status, data);
    if (response.status === 401) emit("auth", error);
    else if (response.status >= 500) emit("status", false, error);
    throw error;
  }
  emit("status", true, null);
  return data;
}

/** Parse SSE text into frames; returns the unparsed tail. */
export function parseFrames(buffer, onFrame) {
  let at;
  while ((at = buffer.indexOf("\n\n")) >= 0) {
    const block = buffer.slice(0, at);
    buffer = buffer.slice(at + 2);
    const frame = { id: null, event: "message", data: [] };
    for (const line of block.split("\n")) {
      if (!line || line.startsWith(":")) continue;
      const colon = line.indexOf(":");
      const field = colon < 0 ? line : line.slice(0, colon);
      const value = colon < 0 ? "" : line.slice(colon + 1).replace(/^ /, "");
      if (field === "data") frame.data.push(value);
      else if (field === "id") frame.id = value;
      else if (field === "event") frame.event = value;
    }
    if (frame.data.length) onFrame(frame);
  }
  return buffer;
}

/**
 * Follow /v1/events with fetch() and a stream reader (EventSource cannot
 * send the Authorization header). Replays history after `afterSeq`, then
 * live events; reconnects from the last seq seen. onEvent(event) per event,
 * onState("live" | "connecting" | "down" | "unauthorized").
 */
export function followEvents(afterSeq, onEvent, onState) {
  let last = afterSeq;
  let stopped = false;
  let controller = null;
  let delay = 500;

  async function once() {
    controller = new AbortController();
    onState("connecting");
    const response = await fetch(`v1/events?after_seq=${last}`, {
      headers: { Authorization: `Bearer ${token()}`, Accept: "text/event-stream" },
      signal: controller.signal,
      cache: "no-store",
    });
    if (response.status === 401) {
      onState("unauthorized");
      emit("auth", new ApiError(401, await response.json().catch(() => null)));
      return false;
    }
    if (!response.ok || !response.body) throw new Error(`HTTP ${response.status}`);
    onState("live");
    delay = 500;
    const reader = response.body.pipeThrough(new TextDecoderStream()).getReader();
    let buffer = "";
    for (;;) {
      const { value, done } = await reader.read();
      if (done) break;
      buffer = parseFrames(buffer + value.replace(/\r\n/g, "\n"), (frame) => {
        const event = JSON.parse(frame.data.join("\n"));
        if (typeof event.seq === "number" && event.seq > last) last = event.seq;
        onEvent(event);
      });
    }
    return true;
  }

  (async () => {
    while (!stopped) {
      let again = true;
      try {
        again = await once();
      } catch {
        if (stopped) break;
      }
      if (!again || stopped) break;
      onState("down");
      await new Promise((r) => setTimeout(r, delay));
      delay = Math.min(delay * 2, 10000);
    }
  })();

  return {
    stop() {
      stopped = true;
      if (controller) controller.abort();
    },
    get lastSeq() {
      return last;
    },
  };
}
