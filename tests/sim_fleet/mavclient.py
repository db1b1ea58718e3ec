"""A pymavlink ground-station client for the integration tests (udpout to the sim)."""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from typing import Any

os.environ["MAVLINK20"] = "1"
from pymavlink import mavutil

mavlink = mavutil.mavlink
SPEEDUP = 20.0  # simulated seconds per wall second in the pymavlink tests


class Client:
    """Connects like ``mavproxy --master udpout:127.0.0.1:PORT``: it speaks first."""

    def __init__(self, port: int, target_system: int, *, streams_hz: float = 10.0) -> None:
        self.conn = mavutil.mavlink_connection(
            f"udpout:127.0.0.1:{port}", source_system=255, source_component=190
        )
        self.target = target_system
        self.texts: list[str] = []
        self.hello()
        if streams_hz > 0:
            self.request_streams(streams_hz)

    def request_streams(self, hz: float) -> None:
        """What MAVProxy does on connecting: every stream group at ``hz``."""
        self.conn.mav.request_data_stream_send(
            self.target, 1, mavlink.MAV_DATA_STREAM_ALL, round(hz), 1
        )

    def hello(self) -> None:
        self.conn.mav.heartbeat_send(mavlink.MAV_TYPE_GCS, mavlink.MAV_AUTOPILOT_INVALID, 0, 0, 0)

    def close(self) -> None:
        self.conn.close()

    def wait(
        self,
        msg_type: str | tuple[str, ...],
        pred: Callable[[Any], bool] = lambda m: True,
        timeout_s: float = 10.0,
    ) -> Any:
        """The first ``msg_type`` message (or one of several types) satisfying
        ``pred`` within the deadline."""
        types = (msg_type,) if isinstance(msg_type, str) else msg_type
        deadline = time.monotonic() + timeout_s
        last_hello = time.monotonic()
        while time.monotonic() < deadline:
            if time.monotonic() - last_hello > 1.0:
                self.hello()
                last_hello = time.monotonic()
            msg = self.conn.recv_match(blocking=True, timeout=0.2)
            if msg is None:
                continue
            if msg.get_type() == "STATUSTEXT":
                self.texts.append(msg.text)
            if msg.get_type() in types and pred(msg):
                return msg
        raise AssertionError(f"no {msg_type} matching within {timeout_s} s")

    def wait_text(self, pred: Callable[[str], bool], timeout_s: float = 10.0) -> str:
        """A STATUSTEXT satisfying ``pred``, including ones already received."""
        for text in self.texts:
            if pred(text):
                return text
        return self.wait("STATUSTEXT", lambda m: pred(m.text), timeout_s).text

    def command(self, command: int, *params: float) -> Any:
        """COMMAND_LONG; returns its COMMAND_ACK."""
        p = list(params) + [0.0] * (7 - len(params))
        self.conn.mav.command_long_send(self.target, 1, command, 0, *p)
        return self.wait("COMMAND_ACK", lambda m: m.command == command)

    def command_int(self, command: int, frame: int, *params: float) -> Any:
        p1, p2, p3, p4, x, y, z = list(params) + [0.0] * (7 - len(params))
        self.conn.mav.command_int_send(
            self.target, 1, frame, command, 0, 0, p1, p2, p3, p4, int(x), int(y), z
        )
        return self.wait("COMMAND_ACK", lambda m: m.command == command)

    def set_mode(self, custom_mode: int) -> Any:
        return self.command(mavlink.MAV_CMD_DO_SET_MODE, 1, custom_mode)

    def goto_global(self, lat_deg: float, lon_deg: float, rel_alt_m: float) -> None:
        self.conn.mav.set_position_target_global_int_send(
            0, self.target, 1, mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, 0b110111111000,
            round(lat_deg * 1e7), round(lon_deg * 1e7), rel_alt_m, 0, 0, 0, 0, 0, 0, 0, 0,
        )  # fmt: skip
