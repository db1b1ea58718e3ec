"""HTTP access to a linecrew gateway for the operator CLI (which gateway:
:mod:`linecrew.client.session`)."""

from __future__ import annotations

import json
import os
import ssl
from collections.abc import Iterator
from typing import Any

import httpx

from proto.errors import LinecrewError


class GatewayError(LinecrewError):
    """The gateway refused a request or could not be reached; the message
    says which, and why."""

    code = "gateway_error"

    def __init__(self, message: str, status: int | None = None, body: Any = None) -> None:
        super().__init__(message)
        # The gateway's HTTP answer, None when it did not answer: not the int
        # LinecrewError.status this error would be served with.
        self.status = status  # type: ignore[assignment]
        self.body = body  # the decoded JSON error ({"error", "message", "field"}), if any


CA_ENV = "LINECREW_CA_FILE"
"""The CA that an HTTPS gateway's certificate is checked against (a
``--secure`` run's site CA); unset, the system's trust store."""


def tls_verify(ca_file: str | None = None) -> ssl.SSLContext | bool:
    """How to check an HTTPS gateway: against ``ca_file``, else ``$LINECREW_CA_FILE``,
    else the system's CAs."""
    ca_file = ca_file or os.environ.get(CA_ENV)
    return ssl.create_default_context(cafile=ca_file) if ca_file else True


def http_client(url: str, token: str, *, ca_file: str | None = None, timeout_s: float = 10.0):
    """An ``httpx.Client`` for the gateway at ``url``: the bearer token, the CA."""
    return httpx.Client(
        base_url=url,
        timeout=timeout_s,
        headers={"Authorization": f"Bearer {token}"},
        verify=tls_verify(ca_file),
    )


class Gateway:
    """A thin client: JSON in, JSON out, errors as :class:`GatewayError`."""

    def __init__(
        self, url: str, token: str, timeout_s: float = 10.0, *, ca_file: str | None = None
    ) -> None:
        self.url = url
        self._http = http_client(url, token, ca_file=ca_file, timeout_s=timeout_s)

    def call(self, method: str, path: str, **kwargs: Any) -> Any:
        """Send a request; the decoded JSON answer."""
        try:
            response = self._http.request(method, path, **kwargs)
        except httpx.HTTPError as exc:
            raise GatewayError(f"cannot reach the gateway at {self.url}: {exc}") from exc
        if response.status_code >= 400:
            raise GatewayError(_explain(response), response.status_code, _body(response))
        return response.json()

    def events(self, after_seq: int | None = None) -> Iterator[dict[str, Any]]:
        """Follow ``/v1/events`` (Server-Sent Events) until interrupted."""
        params = {"after_seq": after_seq} if after_seq is not None else {}
        try:
            with self._http.stream("GET", "/v1/events", params=params, timeout=None) as stream:
                if stream.status_code >= 400:
                    stream.read()
                    raise GatewayError(_explain(stream))
                for line in stream.iter_lines():
                    if line.startswith("data: "):
                        yield json.loads(line[6:])
        except httpx.HTTPError as exc:
            raise GatewayError(f"event stream from {self.url} failed: {exc}") from exc


def _explain(response: httpx.Response) -> str:
    try:
        body = response.json()
    except ValueError:
        return f"HTTP {response.status_code}: {response.text[:200]}"
    field = f" (field {body['field']})" if body.get("field") else ""
    known = f"; known: {', '.join(body['known'])}" if body.get("known") else ""
    return f"HTTP {response.status_code} {body.get('error')}: {body.get('message')}{field}{known}"


def _body(response: httpx.Response) -> Any:
    try:
        return response.json()
    except ValueError:
        return None
