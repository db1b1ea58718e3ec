"""Planner exceptions.

::

    PlanningProblemError   invalid input; ``field`` names the offending path

It is a ``LinecrewError`` (:mod:`proto.errors`), as is every error linecrew
raises on purpose. Expected planning failures are not exceptions: they are ``Unplaced`` values
in the returned plan. Any other exception is a bug.
"""

from __future__ import annotations

from proto.errors import LinecrewError


class PlanningProblemError(LinecrewError, ValueError):
    """The problem (or plan) document is invalid.

    Raised by the loaders and by ``plan``/``replan`` before any work. Not
    retryable: fix the input. ``field`` is a JSON-path like
    ``$.actions[2].duration_s``.
    """

    code = "planning_problem_invalid"

    def __init__(self, field: str, message: str) -> None:
        super().__init__(f"{field}: {message}")
        self.field = field
        self.message = message
