"""Network namespaces for partition tests without Docker.

One "switch" namespace holds a bridge; every host namespace gets a veth
whose other end is a bridge port, with an address ``10.A.B.n/24``; the root
namespace (the test itself) is plugged in too, as ``10.A.B.254``. Names carry
a random prefix and the subnet is random, so parallel runs never collide.

Two ways to cut a host off:

- :meth:`Network.cut_link` sets its bridge port down: everything is cut;
- :meth:`Network.block_tcp_port` adds an nft table in the host's namespace
  that drops TCP to and from one port: only that traffic is cut (used to cut
  an agent's Zenoh link to the router while its MAVLink link to the
  simulator, the on-board autopilot, keeps working).

:func:`network` is a context manager that tears everything down in
``finally``; :func:`require_netns` skips the test with the reason when this
machine does not allow ``ip netns add`` (not root, no CAP_SYS_ADMIN, no
``ip``/``nft``).
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import random
import shutil
import subprocess
from collections.abc import Iterator

import pytest

NFT_TABLE = "lcchaos"


def _ip(*args: str) -> None:
    subprocess.run(["ip", *args], check=True, capture_output=True, text=True)


def require_netns() -> None:
    """Skip the calling test, with the reason, unless namespaces and nft work here."""
    missing = [tool for tool in ("ip", "nft") if shutil.which(tool) is None]
    if missing:
        pytest.skip(f"network-namespace partitions need {' and '.join(missing)} (not found)")
    probe = f"lcprobe{os.getpid()}"
    try:
        subprocess.run(["ip", "netns", "add", probe], check=True, capture_output=True, text=True)
    except subprocess.CalledProcessError as exc:
        pytest.skip(
            "network-namespace partitions need `ip netns add` (root or CAP_SYS_ADMIN); "
            f"here it failed: {exc.stderr.strip() or exc.returncode}"
        )
    subprocess.run(["ip", "netns", "del", probe], check=False, capture_output=True)


@dataclasses.dataclass
class Host:
    """One host namespace on the switch."""

    name: str  # the caller's name, e.g. "ground"
    netns: str  # the namespace
    port: str  # its bridge port in the switch namespace
    address: str  # 10.A.B.n


@dataclasses.dataclass
class Network:
    """A switch and its hosts; the root namespace is at ``root_address``."""

    prefix: str
    subnet: str  # "10.A.B"
    switch: str
    hosts: dict[str, Host] = dataclasses.field(default_factory=dict)

    @property
    def root_address(self) -> str:
        """Where the test itself sits on the switch."""
        return f"{self.subnet}.254"

    def add_host(self, name: str) -> Host:
        """A new namespace ``name`` plugged into the switch."""
        index = len(self.hosts) + 1
        host = Host(name, f"{self.prefix}-{name}", f"{self.prefix}p{index}", "")
        host.address = f"{self.subnet}.{index}"
        _ip("netns", "add", host.netns)
        self.hosts[name] = host
        peer = f"{self.prefix}h{index}"
        _ip("-n", self.switch, "link", "add", host.port, "type", "veth", "peer", "name", peer)
        _ip("-n", self.switch, "link", "set", peer, "netns", host.netns)
        _ip("-n", self.switch, "link", "set", host.port, "master", "br0", "up")
        _ip("-n", host.netns, "link", "set", peer, "name", "eth0")
        _ip("-n", host.netns, "addr", "add", f"{host.address}/24", "dev", "eth0")
        _ip("-n", host.netns, "link", "set", "eth0", "up")
        _ip("-n", host.netns, "link", "set", "lo", "up")
        return host

    def exec_prefix(self, name: str) -> list[str]:
        """The command prefix that runs a program inside host ``name``."""
        return ["ip", "netns", "exec", self.hosts[name].netns]

    def cut_link(self, name: str) -> None:
        """Everything to and from ``name`` is cut (its bridge port goes down)."""
        _ip("-n", self.switch, "link", "set", self.hosts[name].port, "down")

    def restore_link(self, name: str) -> None:
        """Undo :meth:`cut_link`."""
        _ip("-n", self.switch, "link", "set", self.hosts[name].port, "up")

    def block_tcp_port(self, name: str, port: int) -> None:
        """Drop TCP to and from ``port`` inside host ``name`` (both directions)."""
        rules = (
            f"add table inet {NFT_TABLE}\n"
            f"add chain inet {NFT_TABLE} out {{ type filter hook output priority 0; }}\n"
            f"add chain inet {NFT_TABLE} in {{ type filter hook input priority 0; }}\n"
            f"add rule inet {NFT_TABLE} out tcp dport {port} drop\n"
            f"add rule inet {NFT_TABLE} in tcp sport {port} drop\n"
        )
        subprocess.run(
            [*self.exec_prefix(name), "nft", "-f", "-"],
            input=rules,
            check=True,
            capture_output=True,
            text=True,
        )

    def unblock(self, name: str) -> None:
        """Undo :meth:`block_tcp_port`."""
        subprocess.run(
            [*self.exec_prefix(name), "nft", "delete", "table", "inet", NFT_TABLE],
            check=True,
            capture_output=True,
            text=True,
        )

    def teardown(self) -> None:
        """Delete every namespace (their veths go with them) and the root's veth."""
        for host in self.hosts.values():
            subprocess.run(["ip", "netns", "del", host.netns], check=False, capture_output=True)
        subprocess.run(["ip", "link", "del", f"{self.prefix}r"], check=False, capture_output=True)
        subprocess.run(["ip", "netns", "del", self.switch], check=False, capture_output=True)


@contextlib.contextmanager
def network(hosts: list[str]) -> Iterator[Network]:
    """A switch with ``hosts`` and the root namespace on it; torn down on exit."""
    require_netns()
    rng = random.Random()
    prefix = f"lc{rng.randrange(16**5):05x}"
    net = Network(prefix, f"10.{rng.randint(100, 250)}.{rng.randint(0, 255)}", f"{prefix}-sw")
    try:
        _ip("netns", "add", net.switch)
        _ip("-n", net.switch, "link", "add", "br0", "type", "bridge")
        _ip("-n", net.switch, "link", "set", "br0", "up")
        root, root_port = f"{prefix}r", f"{prefix}rs"
        _ip("link", "add", root, "type", "veth", "peer", "name", root_port)
        _ip("link", "set", root_port, "netns", net.switch)
        _ip("-n", net.switch, "link", "set", root_port, "master", "br0", "up")
        _ip("addr", "add", f"{net.root_address}/24", "dev", root)
        _ip("link", "set", root, "up")
        for name in hosts:
            net.add_host(name)
        yield net
    finally:
        net.teardown()
