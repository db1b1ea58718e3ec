"""Network namespaces on one Linux machine, for real link cuts without Docker.

One "switch" namespace holds a bridge; every host namespace gets a veth
whose other end is a bridge port, with an address ``10.A.B.n/24``; the root
namespace (the observer: the chaos runner or a test) is plugged in too, as
``10.A.B.254``. Names carry a random prefix and the subnet is random, so
parallel runs never collide.

A host is cut off by :meth:`Network.block_port`: an nft table in the host's
namespace drops TCP to and from one port (the Zenoh router's), except with
the observer. Only that traffic is cut: an agent keeps its MAVLink link
(UDP) to the simulated autopilot, and the observer keeps watching.

:func:`network` is a context manager that tears everything down on exit;
:func:`check_available` raises :class:`NetnsError` with the reason when this
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

from proto.errors import LinecrewError

NFT_TABLE = "lcchaos"


class NetnsError(LinecrewError, RuntimeError):
    """Network namespaces cannot be used here; the message says why."""

    code = "netns_unavailable"


def _ip(*args: str) -> None:
    subprocess.run(["ip", *args], check=True, capture_output=True, text=True)


def check_available() -> None:
    """Raise :class:`NetnsError` unless ``ip netns add`` and ``nft`` work here."""
    missing = [tool for tool in ("ip", "nft") if shutil.which(tool) is None]
    if missing:
        raise NetnsError(f"network namespaces need {' and '.join(missing)} (not found)")
    probe = f"lcprobe{os.getpid()}"
    try:
        _ip("netns", "add", probe)
    except subprocess.CalledProcessError as exc:
        raise NetnsError(
            "network namespaces need `ip netns add` (root or CAP_SYS_ADMIN); "
            f"here it failed: {exc.stderr.strip() or exc.returncode}"
        ) from None
    subprocess.run(["ip", "netns", "del", probe], check=False, capture_output=True)


@dataclasses.dataclass
class Host:
    """One host namespace on the switch."""

    name: str  # the caller's name, e.g. "router" or "uav-1"
    netns: str  # the namespace
    port: str  # its bridge port in the switch namespace
    address: str  # 10.A.B.n


@dataclasses.dataclass
class Network:
    """A switch and its hosts; the observer (root namespace) is at ``root_address``."""

    prefix: str
    subnet: str  # "10.A.B"
    switch: str
    hosts: dict[str, Host] = dataclasses.field(default_factory=dict)

    @property
    def root_address(self) -> str:
        """Where the observer sits on the switch."""
        return f"{self.subnet}.254"

    def add_host(self, name: str) -> Host:
        """A new namespace for ``name`` plugged into the switch."""
        index = len(self.hosts) + 1
        host = Host(name, f"{self.prefix}-{index}", f"{self.prefix}p{index}", "")
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

    def block_port(self, name: str, port: int) -> None:
        """Drop TCP to and from ``port`` inside host ``name`` (either end, both
        directions), except with the observer."""
        root, table = self.root_address, f"inet {NFT_TABLE}"
        rules = (
            f"add table {table}\n"
            f"add chain {table} out {{ type filter hook output priority 0; }}\n"
            f"add chain {table} in {{ type filter hook input priority 0; }}\n"
            f"add rule {table} out ip daddr != {root} tcp dport {port} drop\n"
            f"add rule {table} out ip daddr != {root} tcp sport {port} drop\n"
            f"add rule {table} in ip saddr != {root} tcp dport {port} drop\n"
            f"add rule {table} in ip saddr != {root} tcp sport {port} drop\n"
        )
        self._nft(name, ["-f", "-"], rules)

    def unblock(self, name: str) -> None:
        """Undo :meth:`block_port`."""
        self._nft(name, ["delete", "table", "inet", NFT_TABLE])

    def _nft(self, name: str, args: list[str], script: str | None = None) -> None:
        subprocess.run(
            [*self.exec_prefix(name), "nft", *args],
            input=script,
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
    """A switch with ``hosts`` and the observer on it; torn down on exit.
    Raises :class:`NetnsError` where namespaces are not permitted."""
    check_available()
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
