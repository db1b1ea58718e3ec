"""The onboard agent: a behaviour tree executing one UAV's plan over MAVLink (to come)."""
