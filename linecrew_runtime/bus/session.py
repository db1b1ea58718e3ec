"""The bus: a thin typed layer over one Zenoh session.

Typed publish and subscribe (every payload goes through :mod:`proto.codec`;
malformed samples are counted and dropped), hand-off to asyncio, typed
queryables and queries with timeouts and error replies, liveliness tokens
and watchers, and a clean close that undeclares everything.
"""

from __future__ import annotations

import asyncio
import contextlib
import inspect
import logging
import time
from collections.abc import Awaitable, Callable
from typing import TYPE_CHECKING, Any, TypeVar

import msgspec
import zenoh

from linecrew_runtime.bus.config import BusConfig
from linecrew_runtime.bus.handoff import AsyncQueue
from linecrew_runtime.bus.stats import BusStats
from proto import codec
from proto.base import MAX_TEXT
from proto.errors import (
    DecodeError,
    EncodeError,
    LinecrewError,
    RequestError,
    RequestTimeout,
    Unavailable,
)
from proto.rpc import ErrorReply

if TYPE_CHECKING:
    from typing_extensions import TypeForm  # a message class or a union of them

log = logging.getLogger(__name__)

T = TypeVar("T")
Handler = Callable[..., Awaitable[msgspec.Struct] | msgspec.Struct]


class Declared:
    """Something declared on the bus (subscriber, queryable, token); ``close()``
    undeclares it. Subscriptions made for asyncio also iterate their items."""

    def __init__(self, bus: Bus, handle: Any, queue: AsyncQueue[Any] | None = None) -> None:
        self._bus = bus
        self._handle = handle
        self._queue = queue

    def close(self) -> None:
        """Undeclare; idempotent."""
        if self._handle is not None:
            handle, self._handle = self._handle, None
            self._bus._forget(self)
            _undeclare(handle)

    def __enter__(self) -> Declared:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    async def __aenter__(self) -> Declared:
        return self

    async def __aexit__(self, *_exc: object) -> None:
        self.close()

    def __aiter__(self) -> AsyncQueue[Any]:
        if self._queue is None:
            raise TypeError("only subscriptions made with an async method can be iterated")
        return self._queue

    async def get(self) -> Any:
        """The next item of an async subscription."""
        return await self.__aiter__().get()

    def drain(self) -> list[Any]:
        """Every item of an async subscription waiting now, without waiting."""
        return self.__aiter__().drain()


class Bus:
    """A Zenoh session with typed operations. Open with :meth:`open`."""

    def __init__(self, session: zenoh.Session) -> None:
        self._session = session
        self._declared: set[Declared] = set()
        self._publishers: dict[str, zenoh.Publisher] = {}
        self._tasks: set[asyncio.Task[None]] = set()
        self.stats = BusStats()

    @classmethod
    def open(
        cls,
        config: BusConfig,
        *,
        wait_s: float | None = 30.0,
        should_stop: Callable[[], bool] = lambda: False,
    ) -> Bus:
        """Open a session; a client keeps trying to reach a router for up to
        ``wait_s`` seconds (``None``: until ``should_stop()``). Raises
        :class:`Unavailable` when it gives up."""
        deadline = None if wait_s is None else time.monotonic() + wait_s
        zconfig = config.to_zenoh()
        warned = False
        while True:
            try:
                return cls(zenoh.open(zconfig))
            except zenoh.ZError as exc:
                if config.mode == "router" or should_stop():
                    raise Unavailable(f"cannot open zenoh session: {exc}") from exc
                if deadline is not None and time.monotonic() >= deadline:
                    raise Unavailable(
                        f"no zenoh router reachable at {', '.join(config.connect)} "
                        f"after {wait_s:.0f} s"
                    ) from exc
                if not warned:
                    log.warning("waiting for a zenoh router at %s", ", ".join(config.connect))
                    warned = True
                zconfig = config.to_zenoh()

    @property
    def session(self) -> zenoh.Session:
        """The underlying Zenoh session (for what this layer does not cover)."""
        return self._session

    def close(self) -> None:
        """Undeclare everything and close the session; idempotent."""
        for declared in list(self._declared):
            declared.close()
        for publisher in self._publishers.values():
            _undeclare(publisher)
        self._publishers.clear()
        for task in self._tasks:
            task.cancel()
        self._session.close()

    def __enter__(self) -> Bus:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    # -- publish / subscribe ---------------------------------------------------

    def publish(self, key: str, message: msgspec.Struct) -> None:
        """Encode and put ``message`` on ``key``."""
        publisher = self._publishers.get(key)
        if publisher is None:
            publisher = self._publishers[key] = self._session.declare_publisher(key)
        publisher.put(codec.encode(message))
        self.stats.count_published()

    def subscribe(
        self, key: str, message_type: TypeForm[T], callback: Callable[[str, T], None]
    ) -> Declared:
        """Call ``callback(key, message)`` for each decodable sample on ``key``
        (on a Zenoh thread: keep it short). Malformed samples are dropped and
        counted; an exception in the callback is logged, never fatal."""

        def on_sample(sample: zenoh.Sample) -> None:
            sample_key = str(sample.key_expr)
            try:
                message = codec.decode(sample.payload.to_bytes(), message_type)
            except DecodeError as exc:
                self.stats.count_malformed(sample_key, str(exc))
                return
            self.stats.count_received()
            try:
                callback(sample_key, message)
            except Exception:
                log.exception("subscriber callback failed on %s", sample_key)

        return self._track(self._session.declare_subscriber(key, on_sample))

    def subscribe_async(self, key: str, message_type: TypeForm[T], maxsize: int = 1000) -> Declared:
        """Like :meth:`subscribe`, but items ``(key, message)`` are handed to
        the running asyncio loop: ``async with bus.subscribe_async(k, T) as s:
        async for key, msg in s: ...``. When full, the oldest item is dropped."""
        queue: AsyncQueue[tuple[str, T]] = AsyncQueue(
            asyncio.get_running_loop(), maxsize, self.stats.count_overflow
        )
        declared = self.subscribe(key, message_type, lambda k, m: queue.put_threadsafe((k, m)))
        declared._queue = queue
        return declared

    # -- queries -----------------------------------------------------------------

    def serve(
        self, key: str, request_type: TypeForm[T], handler: Handler, *, with_key: bool = False
    ) -> Declared:
        """Answer queries on ``key`` from the running asyncio loop.

        ``handler(request)`` (sync or async; ``handler(query_key, request)``
        ``with_key``, for a handler that trusts a query only as far as the
        key it was sent to) returns the reply message. A
        :class:`LinecrewError` it raises, or a request that cannot be decoded,
        becomes an :class:`ErrorReply` sent as an error reply; an unexpected
        exception becomes ``internal_error`` and is logged."""
        loop = asyncio.get_running_loop()

        def on_query(query: zenoh.Query) -> None:
            try:
                answer = self._answer(query, request_type, handler, with_key)
                loop.call_soon_threadsafe(self._spawn, answer)
            except RuntimeError:  # loop closed while shutting down
                query.drop()

        return self._track(self._session.declare_queryable(key, on_query))

    def _spawn(self, coro: Awaitable[None]) -> None:
        task = asyncio.ensure_future(coro)
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)

    async def _answer(
        self, query: zenoh.Query, request_type: Any, handler: Handler, with_key: bool
    ) -> None:
        with query:
            key = str(query.key_expr)
            try:
                payload = query.payload.to_bytes() if query.payload is not None else b""
                request = codec.decode(payload, request_type)
                result = handler(key, request) if with_key else handler(request)
                reply = await result if inspect.isawaitable(result) else result
            except LinecrewError as exc:
                field = getattr(exc, "field", None)
                reply = ErrorReply(code=exc.code, message=exc.message[:MAX_TEXT], field=field)
            except Exception:
                log.exception("query handler failed on %s", key)
                reply = ErrorReply(code="internal_error", message="the server failed; see its log")
            try:
                if isinstance(reply, ErrorReply):
                    query.reply_err(codec.encode(reply))
                else:
                    query.reply(key, codec.encode(reply))
            except EncodeError as exc:  # a reply too large (or absurd) still answers
                log.warning("cannot encode the reply on %s: %s", key, exc)
                error = ErrorReply(
                    code=exc.code, message=f"the reply cannot be sent: {exc}"[:MAX_TEXT]
                )
                with contextlib.suppress(zenoh.ZError):
                    query.reply_err(codec.encode(error))
            except (zenoh.ZError, LinecrewError) as exc:
                log.warning("cannot reply on %s: %s", key, exc)

    def query(
        self, key: str, request: msgspec.Struct, reply_type: TypeForm[T], timeout_s: float = 2.0
    ) -> T:
        """Send ``request`` to the queryable on ``key`` and return its decoded
        reply. Raises :class:`RequestError` for an error reply or an undecodable
        reply, :class:`RequestTimeout` when nobody answers in ``timeout_s``."""
        replies = self._session.get(key, payload=codec.encode(request), timeout=timeout_s)
        for reply in replies:
            if reply.ok is not None:
                try:
                    return codec.decode(reply.ok.payload.to_bytes(), reply_type)
                except DecodeError as exc:
                    raise RequestError(f"bad reply from {key}: {exc}", code=exc.code) from exc
            if reply.err is None:
                raise RequestError(f"a reply from {key} with neither a value nor an error")
            raise _error_from(key, reply.err.payload.to_bytes())
        raise RequestTimeout(f"no reply on {key} within {timeout_s:g} s (is the server up?)")

    async def query_async(
        self, key: str, request: msgspec.Struct, reply_type: TypeForm[T], timeout_s: float = 2.0
    ) -> T:
        """:meth:`query` without blocking the event loop."""
        return await asyncio.to_thread(self.query, key, request, reply_type, timeout_s)

    # -- liveliness --------------------------------------------------------------

    def declare_token(self, key: str) -> Declared:
        """Declare a liveliness token on ``key``; it vanishes when closed, when
        the process dies, or when its link's lease expires."""
        return self._track(self._session.liveliness().declare_token(key))

    def watch_liveliness(self, key: str, callback: Callable[[str, bool], object]) -> Declared:
        """Call ``callback(token_key, alive)`` for tokens matching ``key``:
        first for those already alive, then on every appearance / loss."""

        def on_sample(sample: zenoh.Sample) -> None:
            try:
                callback(str(sample.key_expr), sample.kind == zenoh.SampleKind.PUT)
            except Exception:
                log.exception("liveliness callback failed on %s", sample.key_expr)

        handle = self._session.liveliness().declare_subscriber(key, on_sample, history=True)
        return self._track(handle)

    def watch_liveliness_async(self, key: str) -> Declared:
        """Like :meth:`watch_liveliness`; iterate ``(token_key, alive)`` in asyncio."""
        queue: AsyncQueue[tuple[str, bool]] = AsyncQueue(
            asyncio.get_running_loop(), on_overflow=self.stats.count_overflow
        )
        declared = self.watch_liveliness(key, lambda k, a: queue.put_threadsafe((k, a)))
        declared._queue = queue
        return declared

    def alive(self, key: str, timeout_s: float = 1.0) -> set[str]:
        """Keys of the liveliness tokens matching ``key`` alive now."""
        replies = self._session.liveliness().get(key, timeout=timeout_s)
        return {str(r.ok.key_expr) for r in replies if r.ok is not None}

    # -- bookkeeping -------------------------------------------------------------

    def _track(self, handle: Any) -> Declared:
        declared = Declared(self, handle)
        self._declared.add(declared)
        return declared

    def _forget(self, declared: Declared) -> None:
        self._declared.discard(declared)


def _undeclare(handle: Any) -> None:
    try:
        handle.undeclare()
    except zenoh.ZError as exc:  # already gone with its session
        log.debug("undeclare failed: %s", exc)


def _error_from(key: str, payload: bytes) -> RequestError:
    """The error an error reply on ``key`` stands for: the server's own
    (:class:`ErrorReply`), else one from the network on its behalf (Zenoh
    answers ``Timeout`` for a query it gave up on, e.g. across a cut):
    a :class:`RequestTimeout`, safe to retry, not a server failure."""
    try:
        error = codec.decode(payload, ErrorReply)
    except DecodeError:
        return RequestTimeout(f"the network answered for {key}: {payload[:200]!r}")
    return RequestError(error.message, code=error.code, field=error.field)
