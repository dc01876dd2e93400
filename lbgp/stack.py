"""The composition root: how a robot, its planner limits and the controller between the policy and
the wheels are put together. The simulated task (``lbgp.sim.tasks``) and the deploy loop
(``lbgp.real.loop``) both build theirs here, so a setting such as the planner period has one home
and reaches every part that depends on it (the planner's acceleration clamp included)."""

from __future__ import annotations

import dataclasses

from lbgp.control import GoalController, VelocityController
from lbgp.drive_model import DrivePrediction, within_drive_limits
from lbgp.dynamics import Dynamics
from lbgp.conventions import PLANNER_PERIOD
from lbgp.planner import PlannerConfig, TebPlanner, planner_config_for
from lbgp.robots import RobotSpec, get_robot

CONTROL_MODES = ("goal", "velocity")


def planner_limits(robot: str | RobotSpec, planner_period: float = PLANNER_PERIOD, config: PlannerConfig | None = None,
                   time_budget: float | None = None) -> PlannerConfig:
    """The robot's planner configuration (or ``config``), with the control period set to the period
    at which the controller is really ticked, and an anytime SQP budget if given (seconds)."""
    if not planner_period > 0:
        raise ValueError(f"planner period must be above 0 s, got {planner_period}")
    spec = robot if isinstance(robot, RobotSpec) else get_robot(robot)
    base = config or planner_config_for(spec)
    budget = base.sqp_time_budget if time_budget is None else time_budget
    return dataclasses.replace(base, control_period=float(planner_period), sqp_time_budget=budget)


def policy_planner(policy, robot: str | RobotSpec, config: PlannerConfig | None = None) -> PlannerConfig | None:
    """The planner configuration ``policy`` drives with: ``config`` where the caller names one, else
    the robot's preset with the changes the policy was trained with (``Policy.planner_changes``);
    None (the preset) for a policy that has none (HC, scripted, the shipped policies)."""
    changes = getattr(policy, "planner_changes", None)
    if config is not None or not changes:
        return config
    return planner_config_for(robot, changes)


def policy_planner_note(policy, robot) -> str:
    """One line saying which planner ``policy`` drives where it is not the preset ("" otherwise)."""
    changes = getattr(policy, "planner_changes", None)
    if not changes:
        return ""
    name = robot.name if isinstance(robot, RobotSpec) else robot
    settings = ", ".join(f"{k}={v}" for k, v in changes.items())
    return f"planner: the {name} preset with {settings} (the policy was trained on that planner)"


def planner_notes(policies: dict, robot) -> str:
    """For an experiment's table: a paragraph per method whose policy drives another planner than the
    preset (``policies``: method name -> policy), "" when all drive the preset."""
    notes = [f"{method.upper()}'s {note}.\n\n" for method, policy in policies.items()
             if (note := policy_planner_note(policy, robot))]
    return "".join(notes) + ("The methods not named here drive the preset.\n\n" if notes else "")


def make_controller(control: str, limits: PlannerConfig, drive_model: Dynamics | None = None, calibration=None):
    """``goal``: the policy's goal goes through the planner (LBGP, HC); ``velocity``: the policy's
    (v, w) is clamped to the limits (E2E). ``drive_model`` (``lbgp.drive_model``): the planner keeps
    within the drive's acceleration limits and plans from the state predicted one latency ahead;
    a velocity policy's commands are its own and pass unchanged. ``calibration`` (``lbgp.calibration``,
    ``lbgp.online_calibration``): the scaling the commands get after the controller; the planner
    reads its current turn scale at every call."""
    if control == "goal":
        if drive_model is None:
            return GoalController(TebPlanner(limits), calibration=calibration)
        return GoalController(TebPlanner(within_drive_limits(limits, drive_model)), prediction=DrivePrediction(drive_model),
                              calibration=calibration)
    if control == "velocity":
        return VelocityController(limits)
    raise ValueError(f"unknown control mode {control!r}; use 'goal' or 'velocity'")
