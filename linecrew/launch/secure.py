"""The secured Zenoh profile for a local run (``linecrew up --secure``).

Generates a development CA, one certificate per identity and the matching
Zenoh configs (mutual TLS, access control by certificate name) into the run
directory with ``deploy/tls/gen-dev-ca.sh``, which needs a source checkout
and ``openssl``. Identities: ``gs``, ``gateway``, ``sim``, ``operator`` (the
launcher itself and the CLI tools) and ``uav-1`` .. ``uav-N``, each UAV also
with a MAVLink signing key shared by its agent and the simulator.
"""

from __future__ import annotations

import dataclasses
import os
import pathlib
import re
import shutil
import subprocess
import sys

from linecrew_runtime.mavlink_keys import key_path
from proto.errors import LinecrewError

GEN = pathlib.Path(__file__).resolve().parents[2] / "deploy" / "tls" / "gen-dev-ca.sh"
UAV_ID = re.compile(r"uav-(\d+)")


class SecureProfileError(LinecrewError):
    """The profile cannot be set up here (what is missing is in the message)."""

    code = "secure_profile_unavailable"


@dataclasses.dataclass(frozen=True)
class SecureProfile:
    """Certificates and configs under ``root`` (``root/zenoh/*.json5``)."""

    root: pathlib.Path

    def router_config(self) -> str:
        return str(self.root / "zenoh" / "router.json5")

    def client_config(self, identity: str) -> str:
        """The config of ``identity`` (``gs``, ``sim``, ``uav-2``, ...)."""
        return str(self.root / "zenoh" / f"client-{identity}.json5")

    def ca(self) -> str:
        """The site CA: clients of the gateway's HTTPS verify against it."""
        return str(self.root / "ca.pem")

    def https(self) -> tuple[str, str]:
        """The gateway's HTTPS certificate and key."""
        return str(self.root / "https.pem"), str(self.root / "https.key")

    def mavlink_keys(self) -> str:
        """The directory of every vehicle's MAVLink key (``uav-K.key``)."""
        return str(self.root / "mavlink")

    def mavlink_key(self, uav_id: str) -> str:
        return str(key_path(self.mavlink_keys(), uav_id))


def prepare(root: pathlib.Path, uav_ids: list[str]) -> SecureProfile:
    """Create the profile for a fleet whose UAVs are ``uav-1`` .. ``uav-N``;
    raises ``SecureProfileError`` if that or a tool is missing."""
    numbers = sorted(int(m.group(1)) for u in uav_ids if (m := UAV_ID.fullmatch(u)))
    if numbers != list(range(1, len(uav_ids) + 1)):
        raise SecureProfileError(
            f"the secured profile names UAVs uav-1 .. uav-N; this fleet has {uav_ids}"
        )
    if not GEN.is_file():
        raise SecureProfileError(f"{GEN} not found: --secure needs a source checkout")
    if shutil.which("openssl") is None:
        raise SecureProfileError("--secure needs openssl on PATH")
    done = subprocess.run(
        ["sh", str(GEN), str(len(uav_ids)), str(root)],
        env={**os.environ, "PYTHON": sys.executable},
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0:
        raise SecureProfileError(f"certificate generation failed: {done.stderr.strip()}")
    return SecureProfile(root)
