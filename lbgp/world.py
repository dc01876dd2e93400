"""The world state that every consumer downstream reads: poses and velocities of robot and person.

The simulator fills it from MuJoCo; the real robot fills it from a pose source. Nothing downstream
(observation, policy, planner) knows which.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from lbgp.geometry import distance_and_alpha


@dataclasses.dataclass
class WorldState:
    t: float  # s
    robot_pose: np.ndarray  # (x, y, yaw) world
    robot_velocity: np.ndarray  # (v, w): body forward speed m/s, yaw rate rad/s
    person_pose: np.ndarray  # (x, y, yaw) world
    person_velocity: np.ndarray  # (vx, vy) world, m/s (estimated from poses)
    person_turn_rate: float = 0.0  # rad/s (estimated from poses, like the velocity)

    @property
    def distance_alpha(self) -> tuple[float, float]:
        return distance_and_alpha(self.robot_pose, self.person_pose)

    @property
    def person_speed(self) -> float:
        return float(np.hypot(*self.person_velocity))
