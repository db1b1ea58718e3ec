"""Base classes and constrained scalar types for wire structs."""

from __future__ import annotations

from typing import Annotated

import msgspec

SCHEMA_VERSION = 1
"""Schema version written into every top-level message."""

MIN_SCHEMA_VERSION = 1
"""Oldest schema version this code still decodes."""

MAX_MAGNITUDE = 1e15
"""Every float on the wire is finite and within this magnitude (NaN and
infinities fail validation, so a sample holding one is dropped and counted)."""
Finite = Annotated[float, msgspec.Meta(ge=-MAX_MAGNITUDE, le=MAX_MAGNITUDE)]
Fraction = Annotated[float, msgspec.Meta(ge=0.0, le=1.0, description="fraction 0..1")]
NonNegative = Annotated[float, msgspec.Meta(ge=0.0, le=MAX_MAGNITUDE)]
Positive = Annotated[float, msgspec.Meta(gt=0.0, le=MAX_MAGNITUDE)]
MAX_TEXT = 4096
"""Longest free text (reasons, details, modes) on the wire, in characters."""
Text = Annotated[str, msgspec.Meta(max_length=MAX_TEXT)]
MAX_REQUEST_ID = 128
RequestId = Annotated[
    str,
    msgspec.Meta(min_length=1, max_length=MAX_REQUEST_ID, description="a client's idempotency key"),
]
MAX_INT = 2**53
"""Integers on the wire stay below this: exact in every JSON reader's doubles."""
Count = Annotated[int, msgspec.Meta(ge=0, le=MAX_INT)]
PositiveCount = Annotated[int, msgspec.Meta(ge=1, le=MAX_INT)]
Priority = Annotated[
    float, msgspec.Meta(gt=0.0, le=1000.0, description="an action's weight, 0 < p <= 1000")
]
Bearing = Annotated[float, msgspec.Meta(ge=0.0, lt=360.0)]
"""Degrees counter-clockwise from the site's +x axis (east), in [0, 360)."""
ID_PATTERN = r"^[A-Za-z0-9._-]{1,64}$"
"""An id is one key-expression chunk: safe in every key of :mod:`proto.keys`."""

Id = Annotated[
    str,
    msgspec.Meta(
        pattern=ID_PATTERN,
        description="one key-expression chunk of [A-Za-z0-9._-]",
    ),
]


class Record(msgspec.Struct, frozen=True, kw_only=True, forbid_unknown_fields=False):
    """A value nested inside a message (no schema version of its own)."""


class Message(Record, frozen=True, kw_only=True):
    """A top-level wire message: carries ``schema_version``.

    Schema evolution rule: new fields get defaults and go at the end; a
    field's type never changes.
    """

    schema_version: Annotated[int, msgspec.Meta(ge=0, le=65535)] = SCHEMA_VERSION
