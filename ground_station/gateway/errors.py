"""How linecrew errors become HTTP answers: the status is the error tree's
(:data:`proto.errors.HTTP_STATUS`), the JSON shape is one,
``{"error": code, "message": ..., "field": ...}``."""

from __future__ import annotations

from typing import TYPE_CHECKING, TypeVar

import msgspec
from fastapi import Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException

from proto.errors import InvalidRequest, LinecrewError, http_status

if TYPE_CHECKING:
    from typing_extensions import TypeForm  # a class or a union of them, as msgspec takes

T = TypeVar("T")


class ErrorBody(msgspec.Struct, frozen=True, kw_only=True):
    """Every error answer: a code of :data:`proto.errors.HTTP_STATUS`, a sentence for
    people and the request field at fault (null: the request as a whole)."""

    error: str
    message: str
    field: str | None = None


def error_response(code: str, message: str, field: str | None = None, **extra: object):
    """The JSON error answer for ``code``."""
    body = {"error": code, "message": message, "field": field, **extra}
    return JSONResponse(body, status_code=http_status(code))


async def linecrew_error_handler(_request: Request, exc: Exception) -> JSONResponse:
    """FastAPI handler for every :class:`LinecrewError`."""
    assert isinstance(exc, LinecrewError)
    extra = getattr(exc, "extra", {})
    return error_response(exc.code, exc.message, getattr(exc, "field", None), **extra)


async def http_error_handler(_request: Request, exc: Exception) -> JSONResponse:
    """FastAPI's own 404 / 405 in the same shape as every other error."""
    assert isinstance(exc, HTTPException)
    code = {404: "not_found", 405: "method_not_allowed"}.get(exc.status_code, "http_error")
    response = error_response(code, str(exc.detail))
    response.status_code = exc.status_code
    for name, value in (exc.headers or {}).items():
        response.headers[name] = value
    return response


async def validation_error_handler(_request: Request, exc: Exception) -> JSONResponse:
    """A bad path or query parameter: 422 naming it, in the same shape."""
    assert isinstance(exc, RequestValidationError)
    first = exc.errors()[0] if exc.errors() else {}
    field = ".".join(str(p) for p in first.get("loc", ())[1:]) or None
    return error_response("invalid_request", first.get("msg", "invalid request"), field)


def known_query_only(request: Request) -> None:
    """Refuse a query parameter the operation does not take (a typo would
    otherwise be ignored silently): 422 naming it."""
    dependant = getattr(request.scope.get("route"), "dependant", None)
    allowed = {p.alias for p in dependant.query_params} if dependant is not None else set()
    unknown = sorted(set(request.query_params) - allowed)
    if unknown:
        name = unknown[0]
        raise InvalidRequest(f"unknown query parameter {name!r}", field=name)


def decode_body(body: bytes, body_type: TypeForm[T]) -> T:
    """Decode a JSON body; a bad one is a 422 naming the field."""
    try:
        return msgspec.json.decode(body, type=body_type)
    except msgspec.ValidationError as exc:
        field = str(exc).rsplit("at `$.", 1)[-1].rstrip("`") if "at `$." in str(exc) else None
        raise InvalidRequest(str(exc), field=field) from exc
    except msgspec.DecodeError as exc:
        raise InvalidRequest(f"body is not valid JSON: {exc}") from exc
