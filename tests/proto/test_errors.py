"""The error tree: one table of codes and HTTP statuses, and every error a
process answers a request with takes its code from that table."""

import importlib
import pkgutil

import pytest

import ground_station
import sim_fleet
from proto.errors import (
    HTTP_STATUS,
    InvalidAction,
    InvalidTransition,
    LinecrewError,
    RequestError,
    http_status,
)


def _subclasses(cls: type) -> set[type]:
    return {cls, *(c for sub in cls.__subclasses__() for c in _subclasses(sub))}


def _import_all(package) -> None:
    for module in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
        if not module.name.endswith("__main__"):
            importlib.import_module(module.name)


@pytest.mark.parametrize(
    ("code", "status"),
    [
        ("invalid_action", 422),
        ("tool_out_of_stock", 422),
        ("not_found", 404),
        ("invalid_transition", 409),
        ("forbidden", 403),
        ("store_unavailable", 503),
        ("request_timeout", 503),
        ("internal_error", 500),
        ("no_such_code", 500),
    ],
)
def test_a_code_maps_to_its_status_and_an_unknown_one_to_500(code, status):
    assert http_status(code) == status


def test_a_subclass_inherits_its_parents_status_with_its_own_code():
    assert InvalidAction.code != "invalid_request" and InvalidAction.status == 422
    assert InvalidTransition("x").status == 409


def test_every_error_a_server_answers_with_has_a_code_of_the_one_table():
    _import_all(ground_station)
    _import_all(sim_fleet)
    answered = _subclasses(RequestError)
    outside = {c for c in answered if c.__module__ != "proto.errors"}
    assert outside, "the product grows no request error of its own: the walk found nothing"
    strays = {c.__qualname__: c.code for c in answered if c.code not in HTTP_STATUS}
    assert strays == {}


def test_every_linecrew_error_has_a_code_and_a_status():
    for cls in _subclasses(LinecrewError):
        assert cls.code and 400 <= cls.status <= 599, cls
