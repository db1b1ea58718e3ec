"""The one codec of the wire: MessagePack via msgspec, with a size limit and
a schema-version check. :func:`decode` raises :class:`DecodeError` and
nothing else, whatever the bytes.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any, TypeVar

import msgspec

from proto.base import MIN_SCHEMA_VERSION, SCHEMA_VERSION
from proto.errors import DecodeError, EncodeError

if TYPE_CHECKING:
    from typing_extensions import TypeForm  # a message class or a union of them

MAX_MESSAGE_BYTES = 1 << 20
"""Largest payload accepted or produced (1 MiB)."""

T = TypeVar("T")

_encoder = msgspec.msgpack.Encoder()


class _Header(msgspec.Struct):
    schema_version: int = 0


_decoders: dict[Any, msgspec.msgpack.Decoder[Any]] = {}
_decoders_lock = threading.Lock()


def _decoder(message_type: Any) -> msgspec.msgpack.Decoder[Any]:
    """The cached decoder of ``message_type``. Built under a lock: two threads
    building msgspec type information at once (Zenoh callbacks do) crashed
    the interpreter."""
    decoder = _decoders.get(message_type)
    if decoder is None:
        with _decoders_lock:
            decoder = _decoders.get(message_type)
            if decoder is None:
                decoder = _decoders[message_type] = msgspec.msgpack.Decoder(message_type)
    return decoder


_header_decoder = msgspec.msgpack.Decoder(_Header)


def encode(message: msgspec.Struct) -> bytes:
    """Encode a message to MessagePack bytes.

    Raises :class:`EncodeError` if it exceeds :data:`MAX_MESSAGE_BYTES` or
    holds a value MessagePack cannot represent.
    """
    try:
        data = _encoder.encode(message)
    except (TypeError, ValueError, OverflowError) as exc:
        raise EncodeError(f"cannot encode {type(message).__name__}: {exc}") from exc
    if len(data) > MAX_MESSAGE_BYTES:
        raise EncodeError(
            f"{type(message).__name__} is {len(data)} bytes, over the {MAX_MESSAGE_BYTES} limit"
        )
    return data


def decode(data: bytes | bytearray | memoryview, message_type: TypeForm[T]) -> T:
    """Decode ``data`` as ``message_type`` (a message class or a union of them).

    Raises :class:`DecodeError` for oversized, malformed, truncated or
    wrong-type bytes and for a schema version this code does not support.
    """
    if len(data) > MAX_MESSAGE_BYTES:
        raise DecodeError(f"payload is {len(data)} bytes, over the {MAX_MESSAGE_BYTES} limit")
    try:
        message = _decoder(message_type).decode(data)
    except Exception as exc:  # untrusted bytes: msgspec may also raise UnicodeDecodeError etc.
        raise DecodeError(_explain(data, exc)) from exc
    version = getattr(message, "schema_version", SCHEMA_VERSION)
    if not MIN_SCHEMA_VERSION <= version <= SCHEMA_VERSION:
        raise DecodeError(_version_message(version))
    return message


def _version_message(version: int) -> str:
    return (
        f"unsupported schema version {version} "
        f"(this build reads {MIN_SCHEMA_VERSION}..{SCHEMA_VERSION})"
    )


def _explain(data: bytes | bytearray | memoryview, exc: Exception) -> str:
    """Say why decoding failed, naming a wrong schema version when that is the cause."""
    try:
        version = _header_decoder.decode(data).schema_version
    except Exception:
        version = None
    if version is not None and version and not MIN_SCHEMA_VERSION <= version <= SCHEMA_VERSION:
        return _version_message(version)
    return f"malformed message: {exc}"
