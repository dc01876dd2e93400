"""Planner parameters, one preset per robot.

The weights are those of a least-squares tracking problem in SI units (see ``teb.py``); the
safety margin plays the role of TEB's ``min_obstacle_dist``.
TEB's stock speed limits (0.4 m/s, 0.3 rad/s) are far too slow to get in front of a walking person,
so the limits below come from the robots' published top speeds, derated.
"""

from __future__ import annotations

import dataclasses
import numbers

import numpy as np

from lbgp.robots import JACKAL, TURTLEBOT2, RobotSpec, get_robot

PERSON_RADIUS = 0.25  # m, half the shoulder width of the simulated person


@dataclasses.dataclass(frozen=True)
class PlannerConfig:
    n_poses: int = 20  # poses in the band (N); the first is the robot's current pose
    # robot limits (hard in the returned command)
    max_vel_x: float = 1.5  # m/s forward
    max_vel_x_backwards: float = 0.3  # m/s
    max_vel_theta: float = 2.0  # rad/s
    acc_lim_x: float = 1.5  # m/s^2
    acc_lim_theta: float = 3.0  # rad/s^2
    lateral_acc_limit: float = 1.0  # m/s^2: |v w| at most this (turn gently at speed; a skid-steer base slips less then) ...
    lateral_acc_limit_clear: float | None = None  # m/s^2: ... near the person; where a band pose is lateral_acc_ramp or
    # more beyond the safety distance from the person's predicted position, at most this (None: lateral_acc_limit everywhere)
    lateral_acc_ramp: float = 0.5  # m over which the limit rises linearly from lateral_acc_limit to lateral_acc_limit_clear
    footprint_radius: float = 0.27  # m
    person_radius: float = PERSON_RADIUS
    safety_margin: float = 0.08  # m, clearance kept between footprint and person
    band_dt: float = 0.1  # s between band poses (= the control period: the first segment is the command)
    # objective weights (least squares; units m, rad, m/s, rad/s)
    weight_track: float = 1.0  # every pose: squared distance from the moving goal at that pose's time
    weight_track_start: float = 0.1  # share of weight_track on the first pose, rising linearly to 1 at the last
    weight_goal: float = 4.0  # extra on the last pose's goal distance
    weight_goal_heading: float = 0.5  # last pose's heading vs the goal's
    weight_heading_track: float = 0.2  # every pose's heading vs the goal's at that time (ramped like the tracking)
    weight_acc: float = 0.05  # squared change of v between segments (and from the current v)
    weight_alpha: float = 0.1  # squared change of w between segments (and from the current w)
    weight_turn: float = 0.05  # squared w sent to the wheels (through a calibration's scale s: the band's w times s)
    weight_clearance_slack: float = 10.0  # quadratic penalty of a clearance violation (m)
    weight_clearance_l1: float = 100.0  # exact (L1) penalty of a clearance violation (m)
    clearance_tolerance: float = 0.02  # m the next pose may dip into the safety distance
    regularization: float = 1e-4  # proximal (Levenberg-Marquardt) term of each SQP step
    # sequential QP
    sqp_iterations: int = 3  # at most, per candidate band; stops earlier at step_tolerance (benchmarks/sqp_iterations.py)
    sqp_time_budget: float | None = None  # s: anytime mode (deployment): no further SQP iteration once it would
    # end past this budget (at least one always runs); None: iterate to step_tolerance (simulation, reproducible)
    trust_region_v: float = 0.75  # m/s change of each segment's v per iteration
    trust_region_w: float = 1.5  # rad/s change of each segment's w per iteration
    step_tolerance: float = 1e-3  # converged when no v (m/s) or w (rad/s) moves more than this
    turn_around_candidate: bool = True  # turn to face a goal behind the robot when that is faster than backing up
    turn_candidate_angle: float = 1.0  # rad: the turn band is tried for a goal more than this off the robot's heading
    turn_candidate_distance: float = 0.05  # m: ... and farther than this at the end of the horizon
    weight_time_to_go: float = 2.0  # per s: candidate bands are compared with the time they leave to the goal
    wait_candidate: bool = True  # also solve a band that brakes first when the band passes near the person
    wait_margin: float = 0.3  # m beyond the safety distance that counts as near
    pass_candidate: bool = True  # also solve a band that passes the person on one side when the band is stuck behind them
    control_period: float = 0.1  # s between planner calls (for the acceleration clamp)
    osqp_max_iter: int = 4000
    osqp_eps: float = 1e-3  # absolute and relative tolerance of every QP, then polished (exact active set)
    osqp_rho: float = 0.03  # OSQP's initial ADMM step size, where every band's first QP starts (OSQP's default 0.1
    # needs ~15-25 % more ADMM iterations per QP here: docs/planner.md, "The initial step size")
    # a QP whose active set polishing did not confirm is continued to this tolerance and polished again
    # (None: accurate to osqp_eps only); that pass stops at osqp_refine_max_iter, keeping whichever
    # iterate has the smaller residuals (docs/planner.md: the 1 cm accuracy target needs it)
    osqp_refine_eps: float | None = 1e-4
    osqp_refine_max_iter: int = 1000  # 300 until 2026-12-03: one TurtleBot 2 QP stopped there 1.5 cm off (docs/planner.md)

    @property
    def safety_distance(self) -> float:
        """Minimum robot-centre to person-centre distance along the band."""
        return self.footprint_radius + self.person_radius + self.safety_margin

    def with_(self, **changes) -> "PlannerConfig":
        return dataclasses.replace(self, **changes)


JACKAL_PLANNER = PlannerConfig(
    max_vel_x=1.5,
    max_vel_x_backwards=0.3,
    max_vel_theta=2.0,
    acc_lim_x=1.5,
    acc_lim_theta=3.0,
    lateral_acc_limit_clear=2.0,  # E2E's command range (1 m/s x 2 rad/s) allows as much; near the person 1.0 (docs/planner.md)
    weight_turn=0.02,  # 0.05 until 2026-12-06: HC and LBGP both score more, HC's trajectory_three back (docs/planner.md, "Planner weights against the leads")
    footprint_radius=JACKAL.footprint_radius,
)

TURTLEBOT2_PLANNER = PlannerConfig(
    max_vel_x=0.65,
    max_vel_x_backwards=0.15,
    max_vel_theta=2.5,
    acc_lim_x=1.0,
    acc_lim_theta=3.0,
    footprint_radius=TURTLEBOT2.footprint_radius,
)

PRESETS = {"jackal": JACKAL_PLANNER, "turtlebot2": TURTLEBOT2_PLANNER}


def planner_config_for(robot: str | RobotSpec, changes: dict | None = None) -> PlannerConfig:
    """The robot's preset, with ``changes`` (field -> value, checked by ``checked_changes``) applied."""
    name = robot.name if isinstance(robot, RobotSpec) else get_robot(robot).name
    return PRESETS[name].with_(**checked_changes(changes)) if changes else PRESETS[name]


CHANGE_WORDS = {"none": None, "true": True, "false": False}  # the words changes_from_text reads


def changes_from_text(text: str) -> dict:
    """``"weight_turn=0.05,lateral_acc_limit_clear=none"`` -> the checked changes dict (``checked_changes``):
    comma-separated NAME=VALUE pairs, VALUE a number, true, false or none; "" -> {}."""
    changes = {}
    for item in filter(None, (part.strip() for part in text.split(","))):
        name, sep, raw = item.partition("=")
        name, raw = name.strip(), raw.strip().lower()
        if not sep or not name or not raw:
            raise ValueError(f"planner setting {item!r} is not NAME=VALUE")
        if raw in CHANGE_WORDS:
            changes[name] = CHANGE_WORDS[raw]
        else:
            try:
                changes[name] = float(raw)
            except ValueError:
                raise ValueError(f"planner setting {item!r}: {raw!r} is not a number, none, true or false") from None
    return checked_changes(changes)


def checked_changes(changes) -> dict:
    """``changes`` as a plain dict of ``PlannerConfig`` fields and values of their types (a policy
    file carries such a dict); a ValueError naming the problem for anything else."""
    if not isinstance(changes, dict):
        raise ValueError(f"planner changes must be a mapping of PlannerConfig fields to values, got {type(changes).__name__}")
    fields = {f.name: f for f in dataclasses.fields(PlannerConfig)}
    checked = {}
    for name, value in changes.items():
        if name not in fields:
            raise ValueError(f"{name!r} is not a planner setting (PlannerConfig has no such field)")
        kind = str(fields[name].type)  # postponed annotations: "int", "float | None", "bool"
        if value is None and "None" in kind:
            checked[name] = None
        elif kind == "bool" and isinstance(value, bool):
            checked[name] = value
        elif kind != "bool" and isinstance(value, numbers.Real) and not isinstance(value, bool) and np.isfinite(value) and (
                not kind.startswith("int") or float(value).is_integer()):
            checked[name] = int(value) if kind.startswith("int") else float(value)
        else:
            raise ValueError(f"planner setting {name} takes a value of type {kind}, got {value!r}")
    return checked
