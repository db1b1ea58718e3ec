"""The error tree shared by every linecrew process, and the one table from
error code to HTTP status.

::

    class                      code                  HTTP
    LinecrewError              linecrew_error        500
    ├── ProtocolError          protocol_error        422  bytes or keys break the contract
    │   ├── DecodeError        decode_error          422  bad, oversized, wrong-version bytes
    │   ├── EncodeError        encode_error          503  an answer that cannot go on the bus
    │   └── InvalidKey         invalid_key           422  an id or key outside the key space
    ├── Unavailable            unavailable           503  no Zenoh router can be reached
    └── RequestError           request_error         500  an RPC answered with an error reply
        ├── RequestTimeout     request_timeout       503  nobody answered in time
        ├── StoreUnavailable   store_unavailable     503  the gs cannot write its store
        ├── InvalidRequest     invalid_request       422  a request that breaks its schema
        │   ├── InvalidAction  invalid_action        422  the site or fleet cannot take it
        │   ├── ToolOutOfStock tool_out_of_stock     422  no copy left at the station
        │   └── UnknownGesture unknown_gesture       422  not in the gateway's vocabulary
        ├── NotFound           not_found             404  an id the server does not know
        ├── Conflict           conflict              409  a request id reused
        │   └── InvalidTransition invalid_transition 409  e.g. cancelling a completed action
        ├── Unauthorized       unauthorized          401  missing or wrong bearer token
        ├── Forbidden          forbidden             403  one UAV asking for another's plan
        ├── MethodNotAllowed   method_not_allowed    405
        └── BodyTooLarge       body_too_large        413

Each class carries a stable ``code`` (the string that also travels in
:class:`proto.rpc.ErrorReply`), its HTTP ``status`` and a human message;
:data:`HTTP_STATUS` is read off the classes here, so a code and its status
are written once. A request error that arrives over the bus is a
:class:`RequestError` holding the server's code; :func:`http_status` maps
it.

Process-local errors grow from ``LinecrewError`` where they are raised
(each also the builtin it was before, so existing handlers still catch it);
they never reach an HTTP answer:

    PlanningProblemError  "planning_problem_invalid"    ground_station.planner (ValueError)
    DevTokenRefused       "dev_token_refused"           ground_station.gateway (ValueError)
    SigningKeyError       "signing_key_invalid"         linecrew_runtime.mavlink_keys (ValueError)
    ScenarioError         "invalid_scenario"            linecrew_runtime.scenarios
    StartError            "start_failed"                linecrew.launch.supervisor
    SecureProfileError    "secure_profile_unavailable"  linecrew.launch.secure
    NetnsError            "netns_unavailable"           linecrew.chaos.netns (RuntimeError)
    RunDirError           "run_dir_invalid"             linecrew.report.data (RuntimeError)
    NoRunError            "no_run"                      linecrew.client.session (RuntimeError)
    GatewayError          "gateway_error"               linecrew.client.gateway
    NotReady              "fleet_not_ready"             linecrew.bench.fleet (RuntimeError)
    UnknownUav            "unknown_uav"                 onboard_agent
    AutopilotError        "autopilot_error"             onboard_agent.autopilot (and its three)
"""

from __future__ import annotations


class LinecrewError(Exception):
    """Base of every error linecrew raises on purpose.

    ``code`` is stable and machine-readable; ``str(err)`` is for humans.
    """

    code = "linecrew_error"
    status = 500

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message


class ProtocolError(LinecrewError):
    """Something on the wire (bytes or key) violates the contract."""

    code = "protocol_error"
    status = 422


class DecodeError(ProtocolError):
    """Raised by :func:`proto.codec.decode` for any payload it cannot accept.

    Covers malformed, truncated, oversized, wrong-type and wrong-schema-version
    bytes. Never retry the same bytes: drop the message and count it.
    """

    code = "decode_error"
    status = 422


class EncodeError(ProtocolError):
    """Raised by :func:`proto.codec.encode` for a message over the size limit
    or with values MessagePack cannot hold. A bug in the sender: do not retry.
    """

    code = "encode_error"
    status = 503  # the server's answer cannot go on the bus


class InvalidKey(ProtocolError):
    """Raised by :mod:`proto.keys` for ids that would break the key space
    (empty, ``/``, ``*``, ``$``, ``#``, ``?``, a leading ``@``) and for keys
    that are not linecrew keys. Reject the input; do not retry.
    """

    code = "invalid_key"
    status = 422


class Unavailable(LinecrewError):
    """Raised when opening a bus cannot reach any router in the time allowed.
    Retry later, or check the connect endpoints."""

    code = "unavailable"
    status = 503


class RequestError(LinecrewError):
    """An RPC got a typed error reply. ``code`` is the server's error code and
    ``field`` names the offending request field when there is one; ``extra``
    holds further JSON fields for an HTTP answer (they do not travel on the
    bus). Retrying the same request gives the same answer.
    """

    code = "request_error"

    def __init__(
        self,
        message: str,
        *,
        code: str | None = None,
        field: str | None = None,
        **extra: object,
    ) -> None:
        super().__init__(message)
        if code is not None:
            self.code = code
        self.field = field
        self.extra = extra


class RequestTimeout(RequestError):
    """An RPC got no reply within its timeout (server down or partitioned).
    Safe to retry: state-changing requests are idempotent on their request id.
    """

    code = "request_timeout"
    status = 503


class StoreUnavailable(RequestError):
    """The ground station cannot write its store (disk full, read-only, I/O
    error): nothing of the request was kept. Retry once the disk is fixed."""

    code = "store_unavailable"
    status = 503


class InvalidRequest(RequestError):
    """A request that breaks its schema (a bad body, parameter or id).
    ``field`` names it; fix the request, do not retry it as is."""

    code = "invalid_request"
    status = 422


class InvalidAction(InvalidRequest):
    """An action that the site or fleet cannot accept (unknown worker, tool or
    station, no capable UAV, out-of-range value, a changed kind)."""

    code = "invalid_action"


class ToolOutOfStock(InvalidRequest):
    """Every copy of the tool at that station is delivered or reserved.
    Choose another station or tool; retrying the same request is refused."""

    code = "tool_out_of_stock"


class UnknownGesture(InvalidRequest):
    """A gesture the gateway's vocabulary does not hold (``extra`` lists the
    known ones)."""

    code = "unknown_gesture"


class NotFound(RequestError):
    """An id (action, UAV, worker) the server does not know. Do not retry."""

    code = "not_found"
    status = 404


class Conflict(RequestError):
    """A request id reused for a different request. Use a new request id."""

    code = "conflict"
    status = 409


class InvalidTransition(Conflict):
    """An event that does not apply to the action's state (e.g. cancelling a
    completed action)."""

    code = "invalid_transition"


class Unauthorized(RequestError):
    """A missing or wrong bearer token."""

    code = "unauthorized"
    status = 401


class Forbidden(RequestError):
    """A request this sender may not make (an agent's plan query for another
    UAV's plan)."""

    code = "forbidden"
    status = 403


class MethodNotAllowed(RequestError):
    """An HTTP method the path does not take."""

    code = "method_not_allowed"
    status = 405


class BodyTooLarge(RequestError):
    """A request body over the gateway's limit."""

    code = "body_too_large"
    status = 413


def _tree(cls: type[LinecrewError]) -> list[type[LinecrewError]]:
    return [cls, *(c for sub in cls.__subclasses__() for c in _tree(sub))]


HTTP_STATUS: dict[str, int] = {
    cls.code: cls.status for cls in _tree(LinecrewError) if cls.__module__ == __name__
}
"""Error code -> HTTP status, for every code of the tree drawn above."""


def http_status(code: str) -> int:
    """The HTTP status for ``code``: 500 for a code this module does not know
    (a process-local error or a server fault)."""
    return HTTP_STATUS.get(code, 500)
