"""Hypothesis strategies for any msgspec wire type, derived from its declared
types and constraints (so new messages are covered without new code)."""

from __future__ import annotations

import functools
import typing

import msgspec.inspect as mi
from hypothesis import strategies as st

from proto.base import SCHEMA_VERSION


@functools.cache
def for_type(tp: typing.Any) -> st.SearchStrategy[typing.Any]:
    """A strategy producing valid values of ``tp`` (a Struct, union, scalar...)."""
    return _from_info(mi.type_info(tp))


def _from_info(info: mi.Type) -> st.SearchStrategy[typing.Any]:
    match info:
        case mi.Metadata(type=inner):
            return _from_info(inner)
        case mi.StructType(cls=cls, fields=fields):
            kwargs = {
                f.name: st.just(SCHEMA_VERSION) if f.name == "schema_version" else _deferred(f.type)
                for f in fields
            }
            return st.builds(cls, **kwargs)
        case mi.UnionType(types=types):
            return st.one_of([_from_info(t) for t in types])
        case mi.IntType(ge=ge, gt=gt, le=le, lt=lt):
            low = ge if ge is not None else (gt + 1 if gt is not None else -(2**31))
            high = le if le is not None else (lt - 1 if lt is not None else 2**31)
            return st.integers(low, high)
        case mi.FloatType(ge=ge, gt=gt, le=le, lt=lt):
            return st.floats(
                min_value=ge if ge is not None else gt,
                max_value=le if le is not None else lt,
                exclude_min=gt is not None,
                exclude_max=lt is not None,
                allow_nan=False,
                allow_infinity=False,
            )
        case mi.StrType(pattern=pattern, min_length=low, max_length=high):
            if pattern:
                return st.from_regex(pattern, fullmatch=True)
            return st.text(min_size=low or 0, max_size=min(high or 20, 20))
        case mi.BoolType():
            return st.booleans()
        case mi.NoneType():
            return st.none()
        case mi.ListType(item_type=item):
            return st.lists(_from_info(item), max_size=3)
        case mi.DictType(key_type=key, value_type=value):
            return st.dictionaries(_from_info(key), _from_info(value), max_size=3)
        case mi.EnumType(cls=cls):
            return st.sampled_from(list(cls))
    raise NotImplementedError(f"no strategy for {info!r}")


def _deferred(info: mi.Type) -> st.SearchStrategy[typing.Any]:
    return st.deferred(lambda: _from_info(info))
