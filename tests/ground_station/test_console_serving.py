"""The gateway serves the operator console and the site: the page and its
assets need no token (and load nothing from elsewhere), every API path
still does; ``GET /v1/site`` is the site the gateway was given."""

from __future__ import annotations

import fnmatch
import re
import socket
import tomllib
from pathlib import Path

import httpx
import msgspec
import pytest

from ground_station.gateway import console
from ground_station.gateway.rpc import to_json
from linecrew_runtime.scenarios import load
from tests.fakes.fleet import TOKEN, fake_app, serving

ROOT = Path(__file__).resolve().parents[2]
STATIC = ROOT / "ground_station" / "gateway" / "console" / "static"
AUTH = {"Authorization": f"Bearer {TOKEN}"}
PAPER = load("paper").site


@pytest.fixture
def http():
    app, _client = fake_app(uavs=3, site=PAPER)
    with serving(app) as url, httpx.Client(base_url=url, timeout=10) as client:
        yield client


def test_the_page_is_public_html_with_a_same_origin_only_policy(http):
    page = http.get("/")
    assert page.status_code == 200
    assert page.headers["content-type"].startswith("text/html")
    assert '<script type="module" src="console/main.js">' in page.text
    policy = page.headers["content-security-policy"]
    assert "default-src 'self'" in policy and "connect-src 'self'" in policy
    assert "http" not in policy  # no other origin allowed


def test_every_asset_the_page_and_modules_name_is_served_without_a_token(http):
    page = http.get("/").text
    names = set(re.findall(r'(?:src|href)="console/([^"]+)"', page))
    for module in STATIC.glob("*.js"):
        names |= set(re.findall(r'from "\./([^"]+)"', module.read_text()))
    assert {"main.js", "console.css", "api.js", "map.js", "gantt.js"} <= names
    for name in names:
        answer = http.get(f"/console/{name}")
        assert answer.status_code == 200, name
        kind = "text/css" if name.endswith(".css") else "javascript"
        assert kind in answer.headers["content-type"], (name, answer.headers["content-type"])
    assert sorted(names | {"index.html"}) == console.static_files()


def test_nothing_is_loaded_from_another_origin_and_files_stay_small():
    for path in STATIC.iterdir():
        source = path.read_text()
        assert not re.search(r"https?://(?!www\.w3\.org/2000/svg)", source), path.name
        assert len(source.splitlines()) < 400, path.name


def test_api_paths_still_need_the_token(http):
    for path in ["/v1/site", "/v1/fleet", "/v1/plan", "/v1/actions", "/metrics", "/console"]:
        assert http.get(path).status_code == 401, path
    for path in ["/consolex/x", "/v1/console/main.js", "/console/../v1/fleet"]:
        assert http.get(path).status_code in (401, 404), path
        assert http.get(path).status_code != 200, path
    assert http.post("/v1/sim/faults", json={"type": "kill", "uav_id": "uav-1"}).status_code == 401
    assert http.get("/healthz").status_code == 200
    assert http.get("/console/missing.js").status_code == 404


def test_no_path_under_the_console_reaches_the_api_without_the_token(http):
    host, port = http.base_url.host, http.base_url.port
    for path in ["/console/../v1/fleet", "/console/%2e%2e/v1/fleet", "/console//v1/fleet"]:
        with socket.create_connection((host, port), timeout=5) as raw:
            raw.sendall(f"GET {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n".encode())
            answer = b""
            while chunk := raw.recv(65536):
                answer += chunk
        status = answer.split(b"\r\n", 1)[0]
        assert b" 404 " in status or b" 401 " in status, (path, status)
        assert b"uav_id" not in answer, path


def test_v1_site_is_the_site_the_gateway_serves(http):
    answer = http.get("/v1/site", headers=AUTH)
    assert answer.status_code == 200
    site = answer.json()
    assert site == msgspec.json.decode(to_json(PAPER))
    assert [t["id"] for t in site["towers"]] == ["T1", "T2", "T3"]
    assert site["lines"] == [{"id": "L1", "tower_ids": ["T1", "T2", "T3"]}]
    assert {s["id"]: s["pads"] for s in site["stations"]} == {"C1": 2, "C2": 2, "C3": 2}
    assert site["stations"][2]["recharge"] == {"type": "swap", "swap_s": 60.0}
    wrench = next(t for t in site["tool_stations"] if t["id"] == "tp-wrench")
    assert wrench["tools"][0]["name"] == "wrench" and wrench["tools"][0]["count"] == 1
    assert [w["id"] for w in site["workers"]] == ["W1", "W2", "W3"]
    assert site["origin"]["lat_deg"] == pytest.approx(37.4125)
    assert "/v1/site" in http.get("/openapi.json").json()["paths"]
    assert "/" not in http.get("/openapi.json").json()["paths"]


def test_the_static_files_are_package_data():
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text())
    patterns = pyproject["tool"]["setuptools"]["package-data"]["ground_station.gateway.console"]
    for path in STATIC.iterdir():
        relative = path.relative_to(STATIC.parent).as_posix()
        assert any(fnmatch.fnmatch(relative, p) for p in patterns), relative
    assert "playwright" in " ".join(pyproject["project"]["optional-dependencies"]["test"])
