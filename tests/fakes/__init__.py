"""In-process stand-ins for one component's unit tests: an autopilot and
clock for the agent (:mod:`.autopilot`), a ground station behind the real
gateway app (:mod:`.fleet`). End-to-end tests use the real processes."""
