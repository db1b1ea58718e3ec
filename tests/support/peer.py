"""A small bus peer for integration tests, run as its own process:
declares ``alive/sim/{name}`` and answers ``gs/rpc/echo`` with a
:class:`HistoryReply` holding one event whose ``seq`` echoes ``after_seq``
(``limit == 13`` gets a typed error reply instead)."""

from __future__ import annotations

import argparse
import asyncio
import sys

from linecrew_runtime.bus import Bus, BusConfig
from linecrew_runtime.process import Shutdown
from proto import EventKind, GetHistory, GsEvent, HistoryReply, KeySpace, RequestError, Role


def echo(request: GetHistory) -> HistoryReply:
    if request.limit == 13:
        raise RequestError("13 is unlucky", code="unlucky", field="limit")
    return HistoryReply(events=[GsEvent(seq=request.after_seq, stamp_s=0.0, kind=EventKind.FAULT)])


async def serve(endpoint: str, name: str, shutdown: Shutdown) -> None:
    keys = KeySpace()
    with Bus.open(BusConfig(connect=(endpoint,))) as bus:
        bus.serve(keys.rpc("echo"), GetHistory, echo)
        bus.declare_token(keys.alive(Role.SIM, name))
        print("ready", flush=True)
        await shutdown.wait_async()


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--connect", required=True)
    parser.add_argument("--name", default="peer")
    args = parser.parse_args()
    asyncio.run(serve(args.connect, args.name, Shutdown().install()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
