"""The ground station: the site's Zenoh router, and (to come) the mission
manager, planner, fleet monitor, durable store and operator gateway."""
