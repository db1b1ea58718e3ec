"""MAVLink 2 signing keys shared by an onboard agent and its autopilot.

A key file holds one passphrase on its first line; the 32-byte secret is its
SHA-256, the derivation MAVProxy's ``signing setup PASSPHRASE`` uses, so the
same file can be loaded into an ArduPilot flight controller (which stores
the key and then accepts only signed packets) and given to the agent. The
secured profile writes one file per vehicle (``mavlink/uav-K.key``).
"""

from __future__ import annotations

import hashlib
import pathlib
import time

from proto.errors import LinecrewError

SIGNING_EPOCH_S = 1420070400  # MAVLink signing timestamps count from 2015-01-01 UTC
MIN_PASSPHRASE = 8


class SigningKeyError(LinecrewError, ValueError):
    """A key file that is missing, empty or too short (the path is in the message)."""

    code = "signing_key_invalid"


def load_key(path: str | pathlib.Path) -> bytes:
    """The 32-byte signing secret of the key file at ``path``."""
    try:
        lines = pathlib.Path(path).read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise SigningKeyError(f"cannot read MAVLink key file {path}: {exc}") from exc
    passphrase = lines[0].strip() if lines else ""
    if len(passphrase) < MIN_PASSPHRASE:
        raise SigningKeyError(
            f"MAVLink key file {path}: the passphrase on its first line needs "
            f">= {MIN_PASSPHRASE} characters"
        )
    return hashlib.sha256(passphrase.encode("utf-8")).digest()


def key_path(directory: str | pathlib.Path, uav_id: str) -> pathlib.Path:
    """Where the secured profile keeps ``uav_id``'s key."""
    return pathlib.Path(directory) / f"{uav_id}.key"


def signing_timestamp(now_s: float | None = None) -> int:
    """A signing timestamp (10 microsecond units since 2015-01-01) for ``now_s``."""
    now = time.time() if now_s is None else now_s
    return int(max(now - SIGNING_EPOCH_S, 0.0) * 100_000)
