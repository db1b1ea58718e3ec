"""The one way every process reads its settings: defaults, then environment
variables, then explicit overrides (its flags).

A settings class is a frozen dataclass mixing in :class:`EnvSettings`. Each
field is read from ``ENV_PREFIX`` + its upper-cased name (``tick_hz`` of
``LINECREW_AGENT_`` -> ``LINECREW_AGENT_TICK_HZ``), unless its metadata names
another variable (``{"env": "LINECREW_ZENOH_CONFIG"}``) or none
(``{"env": None}``: a value the process resolves itself). Values convert
with msgspec's lax rules (``"5"`` -> 5.0, ``"1e3"`` -> 1000, ``"0"`` / ``"off"``
-> False, a Literal checked); a tuple is comma separated. An empty variable
counts as unset. A bad value raises ``ValueError`` naming the variable.
"""

from __future__ import annotations

import dataclasses
import os
import typing
from collections.abc import Mapping
from typing import Any, ClassVar, Self

import msgspec

NOT_FROM_ENV: Mapping[str, None] = {"env": None}
"""Field metadata of a setting no variable sets."""

_BOOLEAN_WORDS = {"yes": "true", "on": "true", "no": "false", "off": "false"}


class EnvSettings:
    """Mixin of a frozen settings dataclass: ``from_env`` and ``check``."""

    ENV_PREFIX: ClassVar[str]
    __dataclass_fields__: ClassVar[dict[str, dataclasses.Field[Any]]]  # set by @dataclass

    @classmethod
    def from_env(cls, env: Mapping[str, str] | None = None, **overrides: object) -> Self:
        """Defaults, then the variables of ``env`` (default ``os.environ``),
        then ``overrides`` (``None`` values ignored); then :meth:`check`."""
        env = os.environ if env is None else env
        kinds = typing.get_type_hints(cls)
        values: dict[str, object] = {}
        for field in dataclasses.fields(cls):
            name = variable(cls, field)
            if name is not None and (raw := env.get(name)):
                values[field.name] = _convert(name, raw, kinds[field.name])
        values.update({k: v for k, v in overrides.items() if v is not None})
        settings = cls(**values)
        settings.check()
        return settings

    def check(self) -> None:
        """Raise ``ValueError`` for settings that cannot work (none by default)."""


def variable(cls: type[EnvSettings], field: dataclasses.Field[object]) -> str | None:
    """The environment variable of ``field``, ``None`` if it has none."""
    return field.metadata.get("env", cls.ENV_PREFIX + field.name.upper())


def _convert(name: str, raw: str, kind: object) -> object:
    value: object = raw
    if typing.get_origin(kind) is tuple:
        value = [part.strip() for part in raw.split(",") if part.strip()]
    elif kind is bool:
        value = _BOOLEAN_WORDS.get(raw.strip().lower(), raw.strip())
    try:
        return msgspec.convert(value, kind, strict=False)
    except msgspec.ValidationError as exc:
        raise ValueError(f"{name}={raw!r}: {exc}") from None
