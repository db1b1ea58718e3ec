"""The ``linecrew bench`` benches of the bus, the ground station, the
simulator, the live plan and the whole fleet (the planner's bench is in
:mod:`linecrew.planner_tools`). Operator tools: nothing below imports them."""
