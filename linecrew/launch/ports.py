"""Free loopback ports for the processes of a local run."""

from __future__ import annotations

import random
import socket


def free_udp_block(count: int, attempts: int = 200) -> int:
    """A base port such that ``base .. base+count-1`` are free for UDP on loopback."""
    rng = random.Random()
    for _ in range(attempts):
        base = rng.randrange(20000, 60000 - count)
        sockets = []
        try:
            for port in range(base, base + count):
                sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
                sockets.append(sock)
                sock.bind(("127.0.0.1", port))
            return base
        except OSError:
            continue
        finally:
            for sock in sockets:
                sock.close()
    raise RuntimeError(f"no block of {count} free UDP ports found")
