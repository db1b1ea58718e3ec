"""The error tree shared by every linecrew process.

::

    LinecrewError           "linecrew_error"
    ├── ProtocolError       "protocol_error"   bytes or keys that break the wire contract
    │   ├── DecodeError     "decode_error"     bad, truncated, oversized, wrong-version bytes
    │   ├── EncodeError     "encode_error"     a message that cannot go on the wire
    │   └── InvalidKey      "invalid_key"      an id or key outside the key space
    ├── Unavailable         "unavailable"      the Zenoh network (router) cannot be reached
    └── RequestError        "request_error"    an RPC answered with a typed error reply
        └── RequestTimeout  "request_timeout"  nobody answered in time

Grown from ``LinecrewError`` where they are raised (each also the builtin
it was before, so existing handlers still catch it):

    PlanningProblemError  "planning_problem_invalid"    ground_station.planner (ValueError)
    DevTokenRefused       "dev_token_refused"           ground_station.gateway (ValueError)
    SigningKeyError       "signing_key_invalid"         linecrew.mavlink_keys (ValueError)
    StartError            "start_failed"                linecrew.launch.supervisor
    SecureProfileError    "secure_profile_unavailable"  linecrew.launch.secure
    NetnsError            "netns_unavailable"           linecrew.chaos.netns (RuntimeError)
    RunDirError           "run_dir_invalid"             linecrew.report.data (RuntimeError)
    NoRunError            "no_run"                      linecrew.client.session (RuntimeError)
    NotReady              "fleet_not_ready"             linecrew.bench.fleet (RuntimeError)

Each class carries a stable ``code`` (the string that also travels in
:class:`proto.rpc.ErrorReply`) and a human message.
"""

from __future__ import annotations


class LinecrewError(Exception):
    """Base of every error linecrew raises on purpose.

    ``code`` is stable and machine-readable; ``str(err)`` is for humans.
    """

    code = "linecrew_error"

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message


class ProtocolError(LinecrewError):
    """Something on the wire (bytes or key) violates the contract."""

    code = "protocol_error"


class DecodeError(ProtocolError):
    """Raised by :func:`proto.codec.decode` for any payload it cannot accept.

    Covers malformed, truncated, oversized, wrong-type and wrong-schema-version
    bytes. Never retry the same bytes: drop the message and count it.
    """

    code = "decode_error"


class EncodeError(ProtocolError):
    """Raised by :func:`proto.codec.encode` for a message over the size limit
    or with values MessagePack cannot hold. A bug in the sender: do not retry.
    """

    code = "encode_error"


class InvalidKey(ProtocolError):
    """Raised by :mod:`proto.keys` for ids that would break the key space
    (empty, ``/``, ``*``, ``$``, ``#``, ``?``, a leading ``@``) and for keys
    that are not linecrew keys. Reject the input; do not retry.
    """

    code = "invalid_key"


class Unavailable(LinecrewError):
    """Raised when opening a bus cannot reach any router in the time allowed.
    Retry later, or check the connect endpoints."""

    code = "unavailable"


class RequestError(LinecrewError):
    """An RPC got a typed error reply. ``code`` is the server's error code and
    ``field`` names the offending request field when there is one. Retrying
    the same request gives the same answer.
    """

    code = "request_error"

    def __init__(self, message: str, *, code: str | None = None, field: str | None = None):
        super().__init__(message)
        if code is not None:
            self.code = code
        self.field = field


class RequestTimeout(RequestError):
    """An RPC got no reply within its timeout (server down or partitioned).
    Safe to retry: state-changing requests are idempotent on their request id.
    """

    code = "request_timeout"
