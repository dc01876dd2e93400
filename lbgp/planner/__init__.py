"""Timed-elastic-band local planner solved with OSQP: goal in, (v, w) out, person as a moving obstacle."""

from lbgp.planner.config import JACKAL_PLANNER, TURTLEBOT2_PLANNER, PlannerConfig, checked_changes, planner_config_for
from lbgp.planner.teb import (
    DIVERGED,
    GOAL_IN_COLLISION,
    INFEASIBLE,
    INVALID_INPUT,
    OK,
    SOLVER_ERROR,
    Plan,
    TebPlanner,
    clamp_command,
    safe_stop,
)

__all__ = [
    "DIVERGED", "GOAL_IN_COLLISION", "INFEASIBLE", "INVALID_INPUT", "OK", "SOLVER_ERROR",
    "JACKAL_PLANNER", "TURTLEBOT2_PLANNER", "Plan", "PlannerConfig", "TebPlanner",
    "checked_changes", "clamp_command", "planner_config_for", "safe_stop",
]
