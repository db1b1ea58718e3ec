"""The public development token is refused unless a run says it is development."""

from __future__ import annotations

import os
import subprocess
import sys

from ground_station.gateway.settings import DEV_TOKEN


def gateway(*args: str, **env: str) -> subprocess.CompletedProcess[str]:
    clean = {k: v for k, v in os.environ.items() if not k.startswith("LINECREW_")}
    argv = [sys.executable, "-m", "ground_station.gateway", "--scenario", "nonexistent", *args]
    return subprocess.run(argv, env=clean | env, capture_output=True, text=True, timeout=60)


def test_the_dev_token_stops_the_gateway_with_a_message_saying_what_to_do():
    refused = gateway(f"--token={DEV_TOKEN}")
    assert refused.returncode == 1 and "LINECREW_ALLOW_DEV_TOKEN=1" in refused.stderr
    from_env = gateway(LINECREW_TOKEN=DEV_TOKEN)
    assert from_env.returncode == 1 and "is public" in from_env.stderr


def test_with_the_flag_the_dev_token_passes_the_check():
    allowed = gateway(f"--token={DEV_TOKEN}", LINECREW_ALLOW_DEV_TOKEN="1")
    assert allowed.returncode == 1  # it gets as far as loading the (missing) scenario
    assert "is public" not in allowed.stderr and "nonexistent" in allowed.stderr
