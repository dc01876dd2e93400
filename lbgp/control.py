"""From a policy action to a (v, w) command: the piece between the policy (5 Hz) and the wheels.

Both controllers have the same two calls, used identically by the simulator and the real robot:

* ``set_action(action, state)`` once per agent step (0.2 s);
* ``command(state) -> Command`` at the planner rate (every 0.1 s by default).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from lbgp.actions import DESIRED_GOAL, goal_from_action, velocity_from_action
from lbgp.geometry import from_frame
from lbgp.planner import OK, Plan, PlannerConfig, TebPlanner, clamp_command
from lbgp.world import WorldState


@dataclasses.dataclass
class Command:
    v: float
    w: float
    status: str = OK
    goal: np.ndarray | None = None  # world (x, y, yaw) of the current goal, if any
    plan: Plan | None = None


class VelocityController:
    """E2E: the action is the (v, w) command itself (clamped to the robot's limits)."""

    kind = "velocity"

    def __init__(self, limits: PlannerConfig):
        self.limits = limits
        self._vw = (0.0, 0.0)

    def reset(self) -> None:
        self._vw = (0.0, 0.0)

    def set_action(self, action, state: WorldState) -> None:
        self._vw = velocity_from_action(action)

    def command(self, state: WorldState) -> Command:
        v_now, w_now = (float(x) for x in state.robot_velocity)
        v, w = clamp_command(self._vw[0], self._vw[1], v_now, w_now, self.limits)
        return Command(v, w)

    def sent(self, t: float, v: float, w: float) -> None:
        """A command sent at ``t`` that did not come from ``command`` (a safety stop): nothing to track."""


class GoalController:
    """LBGP/HC: the action is a goal in the person frame; the TEB planner drives there.

    The goal stays fixed in the person frame while the person walks, so it is re-expressed in the
    world at every planner call, heading along the person's heading, and the planner predicts it
    along the person's predicted arc (velocity and turn rate): every band pose tracks where the goal
    will be at that pose's time, also while the person turns.
    """

    kind = "goal"

    def __init__(self, planner: TebPlanner, prediction=None, calibration=None):
        self.planner = planner
        self.calibration = calibration  # the command calibration after it (lbgp.calibration): the planner's turn limit is on what is sent
        self.prediction = prediction  # lbgp.drive_model.DrivePrediction: plan from the state when the command acts
        self.goal_person = np.array(DESIRED_GOAL)

    def reset(self) -> None:
        self.planner.reset()
        if self.prediction is not None:
            self.prediction.reset()
        self.goal_person = np.array(DESIRED_GOAL)

    def set_action(self, action, state: WorldState) -> None:
        self.set_goal(goal_from_action(action))

    def set_goal(self, goal_person_xy) -> None:
        """Set the goal directly in metres in the person frame (used by scripted and HC goals)."""
        self.goal_person = np.asarray(goal_person_xy, dtype=float).reshape(2)

    def command(self, state: WorldState) -> Command:
        seen = state if self.prediction is None else self.prediction.predict(state)
        goal = from_frame(np.array([self.goal_person[0], self.goal_person[1], 0.0]), seen.person_pose)
        plan = self.planner.plan(
            seen.robot_pose, seen.robot_velocity, goal, seen.person_pose, seen.person_velocity,
            person_turn_rate=seen.person_turn_rate, goal_moves_with_person=True,
            command_scale_w=1.0 if self.calibration is None else float(self.calibration.scale_w),
        )
        self.sent(state.t, plan.v, plan.w)
        return Command(plan.v, plan.w, plan.status, goal, plan)

    def sent(self, t: float, v: float, w: float) -> None:
        """A command sent at ``t`` (``command`` reports its own; the deploy loop reports its safety
        stops): the drive model's commands in flight."""
        if self.prediction is not None:
            self.prediction.sent(t, v, w)
