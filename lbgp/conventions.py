"""The few numbers every layer of lbgp agrees on, each defined once (see ../shared/design.md).

The bottom layer: imports nothing from lbgp.
"""

AGENT_PERIOD = 0.2  # s: one agent (policy) step = one observation frame (5 Hz)
PLANNER_PERIOD = 0.1  # s between controller ticks (planner calls) unless a caller picks another
DESIRED_DISTANCE = 1.5  # m: where the reward peaks, straight in front of the person (alpha = 0)
DESIRED_GOAL = (DESIRED_DISTANCE, 0.0)  # m, person frame: the goal at the desired spot
