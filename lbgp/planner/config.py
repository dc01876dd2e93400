"""Planner parameters, one preset per robot.

Starting point: the defaults published with the ROS ``teb_local_planner`` (weight_kinematics_nh
1000, weight_kinematics_forward_drive 1, min_obstacle_dist as a hard margin), then tuned for these
two robots and for a moving person (forward drive raised to 100 so that the band does not wiggle
backwards near the goal):
TEB's stock speed limits (0.4 m/s, 0.3 rad/s) are far too slow to get in front of a walking person,
so the limits below come from the robots' published top speeds, derated.
"""

from __future__ import annotations

import dataclasses

from lbgp.sim.robots import JACKAL, TURTLEBOT2, RobotSpec, get_robot

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
    footprint_radius: float = 0.27  # m
    person_radius: float = PERSON_RADIUS
    safety_margin: float = 0.08  # m, clearance kept between footprint and person
    dt_min: float = 0.01  # s, shortest time between two band poses
    # objective weights (TEB names in brackets)
    weight_goal: float = 20.0  # goal position error^2 of the last pose
    weight_goal_heading: float = 0.5
    weight_elastic: float = 1.0  # squared segment lengths: short, evenly spaced band
    weight_nonholonomic: float = 1000.0  # (weight_kinematics_nh)
    weight_turn: float = 1.0  # squared heading change per segment
    weight_forward_drive: float = 100.0  # (weight_kinematics_forward_drive)
    weight_clearance_slack: float = 1e3  # exact-penalty weight of a clearance violation (m)
    clearance_tolerance: float = 0.02  # m the next pose may dip into the safety distance
    slowdown_factors: tuple = (0.7, 0.5, 0.3, 0.15)  # speed-limit scales tried when the person crosses the band
    slowdown_horizon: float = 1.5  # s: only crossings this soon make the robot wait
    regularization: float = 1e-2  # proximal term of each SQP step
    # sequential QP
    sqp_iterations: int = 2  # iterations when warm-started (the band also keeps improving from call
    # to call, as in real-time-iteration MPC; 2 plans clearly better than 1 around a walking person)
    sqp_iterations_init: int = 6  # iterations after a (re)initialisation
    sqp_time_budget: float | None = None  # s: anytime mode (deployment): no further SQP iteration once it would
    # end past this budget (at least one always runs); None: the fixed counts above (simulation, reproducible)
    trust_region_position: float = 0.4  # m per iteration
    trust_region_heading: float = 0.8  # rad per iteration
    step_tolerance: float = 1e-3  # stop early when the step is this small
    reinit_goal_jump: float = 1.0  # m: a goal moving farther than this re-initialises the band
    control_period: float = 0.1  # s between planner calls (for the acceleration clamp)
    osqp_max_iter: int = 200
    osqp_eps: float = 1e-3

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


def planner_config_for(robot: str | RobotSpec) -> PlannerConfig:
    name = robot.name if isinstance(robot, RobotSpec) else get_robot(robot).name
    return PRESETS[name]
