"""How smoothly the console renders 50 UAVs whose telemetry changes 5 times
a second (a fake fleet behind the real gateway app, the fleet polled every
200 ms, a replan every 3 s): prints the requestAnimationFrame deltas and
the console's render time per frame. It asserts that the console kept up
(every UAV drawn, markers moving, frames flowing), not a tight timing."""

from __future__ import annotations

import json

from tests.browser.bench_console import measure, report
from tests.fakes.fleet import fake_app, serving

UAVS = 50
RATE_HZ = 5.0


def test_frame_time_with_50_uavs_at_5_hz(browser, artefacts, capsys):
    app, _client = fake_app(UAVS, RATE_HZ)
    with serving(app) as url:
        result = measure(browser, url, UAVS, seconds=8.0, poll_ms=int(1000 / RATE_HZ))
    (artefacts / "frame-time-50-uavs.png").write_bytes(result.pop("screenshot"))
    (artefacts / "frame-time.json").write_text(json.dumps(result, indent=2))
    with capsys.disabled():
        print("\n" + report({**result, "screenshot": None}))
    assert result["moved"], "markers did not move"
    assert result["render_frames"] >= 8.0 * RATE_HZ * 0.5, result  # kept up with the feed
    assert result["fps"] > 10, result
