"""Frame times of the operator console under a 50-UAV, 5 Hz feed.

``python -m tests.browser.bench_console [--uavs 50] [--rate 5] [--seconds 10]``
serves the real gateway app over a fake fleet (:mod:`tests.fakes.fleet`),
opens the console in chromium polling the fleet at the feed's rate, and
prints the requestAnimationFrame deltas (max, p99, mean) and the console's
own render time per frame. It measures; it asserts nothing about speed.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time

from tests.fakes.fleet import TOKEN, fake_app, serving

FRAME_PROBE = """
window.__frames = [];
window.__longTasks = [];
(() => {
  let last = 0;
  const step = (t) => {
    if (last) window.__frames.push(t - last);
    last = t;
    requestAnimationFrame(step);
  };
  requestAnimationFrame(step);
  try {
    new PerformanceObserver((list) => {
      for (const e of list.getEntries()) window.__longTasks.push(e.duration);
    }).observe({ type: "longtask", buffered: true });
  } catch (e) {}
})();
"""


def measure(browser, url: str, uavs: int, seconds: float, poll_ms: int, warmup_s: float = 3.0):
    """Load the console, let it settle, record ``seconds`` of frames; a dict."""
    context = browser.new_context(viewport={"width": 1500, "height": 1300})
    try:
        page = context.new_page()
        page.add_init_script(FRAME_PROBE)
        page.goto(f"{url}/#token={TOKEN}&poll={poll_ms}")
        page.wait_for_function(
            f"() => document.querySelectorAll('#map .uav').length === {uavs}", timeout=20_000
        )
        page.wait_for_function(f"() => document.querySelectorAll('#gantt .bar').length >= {uavs}")
        time.sleep(warmup_s)
        page.evaluate(
            "() => { window.__frames.length = 0; window.__longTasks.length = 0;"
            " Object.assign(window.linecrewConsole.stats,"
            " {frames: 0, maxMs: 0, totalMs: 0, parts: {}}); }"
        )
        before = page.evaluate("() => document.querySelector('#map .uav').dataset.x")
        time.sleep(seconds)
        frames = page.evaluate("() => window.__frames.slice()")
        long_tasks = page.evaluate("() => window.__longTasks.slice()")
        stats = page.evaluate("() => ({...window.linecrewConsole.stats})")
        after = page.evaluate("() => document.querySelector('#map .uav').dataset.x")
        nodes = page.evaluate("() => document.getElementsByTagName('*').length")
        shot = page.screenshot(full_page=True)
    finally:
        context.close()
    frames.sort()
    return {
        "uavs": uavs,
        "poll_ms": poll_ms,
        "seconds": seconds,
        "frames": len(frames),
        "fps": round(len(frames) / seconds, 1),
        "max_frame_ms": round(frames[-1], 1) if frames else None,
        "p99_frame_ms": round(frames[int(0.99 * (len(frames) - 1))], 1) if frames else None,
        "mean_frame_ms": round(statistics.fmean(frames), 2) if frames else None,
        "long_tasks": len(long_tasks),
        "longest_task_ms": round(max(long_tasks), 1) if long_tasks else 0.0,
        "render_frames": stats["frames"],
        "max_render_ms": round(stats["maxMs"], 2),
        "mean_render_ms": round(stats["totalMs"] / stats["frames"], 2) if stats["frames"] else None,
        "max_render_ms_by_view": {k: round(v, 2) for k, v in stats["parts"].items()},
        "dom_nodes": nodes,
        "moved": before != after,
        "screenshot": shot,
    }


def report(result: dict) -> str:
    shown = {k: v for k, v in result.items() if k != "screenshot"}
    return (
        f"console frame time, {result['uavs']} UAVs, fleet polled every {result['poll_ms']} ms: "
        f"max {result['max_frame_ms']} ms, p99 {result['p99_frame_ms']} ms, "
        f"mean {result['mean_frame_ms']} ms over {result['frames']} frames; "
        f"render max {result['max_render_ms']} ms, mean {result['mean_render_ms']} ms\n"
        + json.dumps(shown)
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--uavs", type=int, default=50)
    parser.add_argument("--rate", type=float, default=5.0, help="telemetry updates per second")
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--chromium", default="/usr/bin/chromium")
    parser.add_argument("--screenshot", help="write a PNG of the console here")
    args = parser.parse_args(argv)
    from playwright.sync_api import sync_playwright

    app, _client = fake_app(args.uavs, args.rate)
    with serving(app) as url, sync_playwright() as playwright:
        browser = playwright.chromium.launch(
            executable_path=args.chromium, args=["--no-sandbox", "--disable-dev-shm-usage"]
        )
        result = measure(browser, url, args.uavs, args.seconds, int(1000 / args.rate))
        browser.close()
    if args.screenshot:
        with open(args.screenshot, "wb") as out:
            out.write(result["screenshot"])
    print(report(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
