"""The leaves and decorators of the agent's trees, one behaviour per module
(conditions answer at once; actions issue autopilot commands and check them
on later ticks). Subtrees are assembled in :mod:`onboard_agent.idioms`."""
