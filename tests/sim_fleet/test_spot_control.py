"""The stations' spot controllers: one UAV per spot, granted first come,
ended by take-off, by another claim, by giving it up or by not coming."""

from __future__ import annotations

import dataclasses

from proto.keys import KeySpace
from proto.spots import SpotClaim
from sim_fleet.spot_control import SpotControl, SpotService

SPOTS = {"C1": ((-11.0, 10.0, 0.0), (-9.0, 10.0, 0.0)), "C2": ((0.0, 20.0, 0.0),)}


@dataclasses.dataclass
class Craft:
    id: str
    position: tuple[float, float, float]
    airborne: bool = True


def test_a_spot_is_granted_to_the_first_claimant_only():
    control = SpotControl(SPOTS, dock_radius_m=1.0)
    assert control.claim("uav-1", "C1", 0, 0.0)
    assert not control.claim("uav-2", "C1", 0, 0.1)  # granted to another
    assert control.claim("uav-2", "C1", 1, 0.1)
    assert not control.claim("uav-3", "C1", 2, 0.2)  # no such spot
    assert not control.claim("uav-3", "C9", 0, 0.2)  # no such station
    assert control.state("C1").granted == ["uav-1", "uav-2"]


def test_a_taken_spot_is_refused_and_the_sitter_may_claim_it():
    control = SpotControl(SPOTS, dock_radius_m=1.0)
    control.observe([Craft("uav-3", (0.4, 20.0, 0.0), airborne=False)], 0.0)
    assert control.state("C2").landed == ["uav-3"]
    assert not control.claim("uav-1", "C2", 0, 1.0)
    assert control.claim("uav-3", "C2", 0, 1.0)


def test_a_home_spot_is_granted_to_its_owner_only():
    """A UAV cut off from the controller lands at home unannounced: no other
    UAV may be sitting on its home spot then, even while it is away."""
    control = SpotControl(SPOTS, dock_radius_m=1.0, owners={"C1": ("uav-1", None)})
    assert not control.claim("uav-2", "C1", 0, 0.0)  # uav-1's home spot
    assert control.claim("uav-2", "C1", 1, 0.0)  # the shared one
    assert control.claim("uav-1", "C1", 0, 0.1)
    assert control.claim("uav-3", "C2", 0, 0.1)  # no owners given: all shared
    assert control.state("C1").granted == ["uav-1", "uav-2"]


def test_a_grant_ends_on_take_off_on_another_claim_on_release_or_when_unused():
    control = SpotControl(SPOTS, dock_radius_m=1.0, grant_ttl_s=60.0)
    control.claim("uav-1", "C1", 0, 0.0)
    uav1 = Craft("uav-1", (-11.0, 10.0, 0.0), airborne=False)
    control.observe([uav1], 10.0)  # landed on it: the grant holds while it sits
    control.observe([uav1], 100.0)
    assert control.state("C1").granted[0] == "uav-1"
    uav1.airborne = True
    control.observe([uav1], 101.0)  # took off: the grant ends
    assert control.state("C1").granted == [None, None]
    control.claim("uav-1", "C1", 1, 102.0)
    control.claim("uav-1", "C2", 0, 103.0)  # another claim ends the first
    assert control.state("C1").granted == [None, None]
    assert control.state("C2").granted == ["uav-1"]
    control.claim("uav-1", None, 0, 104.0)
    assert control.state("C2").granted == [None]
    control.claim("uav-2", "C2", 0, 105.0)
    control.observe([], 164.0)
    assert control.state("C2").granted == ["uav-2"]
    control.observe([], 166.0)  # never came within the time allowed
    assert control.state("C2").granted == [None]


class FakeBus:
    def __init__(self) -> None:
        self.published: list[tuple[str, object]] = []

    def publish(self, key: str, message: object) -> None:
        self.published.append((key, message))


class FakeWorld:
    time_s = 5.0
    vehicles: dict = {}


def test_a_claim_is_trusted_only_from_the_key_of_the_uav_it_names():
    keys = KeySpace("default")
    bus = FakeBus()
    service = SpotService(SpotControl(SPOTS, 1.0), FakeWorld(), bus, keys)  # type: ignore[arg-type]
    forged = SpotClaim(uav_id="uav-1", station_id="C2", spot=0)
    service.on_claim(keys.uav("uav-2", "spot"), forged)
    assert service.control.state("C2").granted == [None] and bus.published == []
    service.on_claim(keys.uav("uav-1", "spot"), forged)
    assert service.control.state("C2").granted == ["uav-1"]
    sent = dict(bus.published)
    assert sent[keys.station_spots("C2")].granted == ["uav-1"]  # answered at once


def test_a_spot_stays_taken_until_the_uav_that_took_off_from_it_is_clear():
    """Granted at once, the next UAV would come down onto one still climbing
    out of the spot (chaos seed 11: uav-1 landing at C2 as uav-2 left it), or
    still above it however high (seed 15)."""
    control = SpotControl(SPOTS, dock_radius_m=1.0)
    uav2 = Craft("uav-2", (0.0, 20.0, 0.0), airborne=False)
    control.observe([uav2], 0.0)
    uav2.airborne, uav2.position = True, (0.0, 20.0, 2.5)  # climbing out
    control.observe([uav2], 1.0)
    assert control.state("C2").landed == ["uav-2"]
    assert not control.claim("uav-1", "C2", 0, 1.0)
    uav2.position = (0.3, 20.0, 6.0)  # up at its height, still above the spot
    control.observe([uav2], 1.5)
    assert control.state("C2").landed == ["uav-2"]  # chaos seed 15: one came down onto it
    uav2.position = (4.2, 20.0, 6.0)  # on its way: 4.2 m from the spot's column
    control.observe([uav2], 2.0)
    assert control.state("C2").landed == [None]
    assert control.claim("uav-1", "C2", 0, 2.0)
    control.observe([uav2], 3.0)  # gone for good: not taken again
    uav2.position = (0.5, 20.0, 6.0)  # even if it passes back over the spot
    control.observe([uav2], 4.0)
    assert control.state("C2").landed == [None]
