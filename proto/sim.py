"""Simulator control: fault injection commands, on ``sim/fault``."""

from __future__ import annotations

from proto.base import Fraction, Id, Message, Positive


class BatteryFault(Message, frozen=True, kw_only=True, tag="battery"):
    """Set ``uav_id``'s battery to ``fraction`` of capacity at once."""

    uav_id: Id
    fraction: Fraction


class MotorFailure(Message, frozen=True, kw_only=True, tag="motor"):
    """``uav_id`` loses thrust: it falls if airborne."""

    uav_id: Id


class LinkDrop(Message, frozen=True, kw_only=True, tag="link"):
    """``uav_id``'s MAVLink endpoint goes silent for ``duration_s``."""

    uav_id: Id
    duration_s: Positive


class GpsFreeze(Message, frozen=True, kw_only=True, tag="gps"):
    """``uav_id`` reports a frozen position for ``duration_s``."""

    uav_id: Id
    duration_s: Positive


SimFault = BatteryFault | MotorFailure | LinkDrop | GpsFreeze
