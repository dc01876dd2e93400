"""HC: the hand-crafted follow-ahead method the paper compares to (Nikdel et al. 2018).

An EKF (CTRV, see ``ekf.py``) estimates the person's motion from the person's past poses, the goal
is a point ``distance`` ahead of the person's position predicted ``horizon`` seconds ahead, along
the predicted heading, and the same TEB planner drives there. The default horizon is 0 s (the
filtered current pose and heading): our planner already moves the goal with the person's velocity,
so a forecast on top double-counts; ``horizon`` is kept for experiments.

HC uses exactly what the learned policy sees: the observation (the person's last 10 poses at 5 Hz
in the current person frame, noisy where the observation is noisy). Each call filters that window
oldest to newest, so sim and real, reset or not, behave the same.
"""

from __future__ import annotations

import math

import numpy as np

from lbgp.actions import action_from_goal
from lbgp.conventions import DESIRED_DISTANCE
from lbgp.baselines.ekf import PersonEKF
from lbgp.sim import observation as obs_lib


class HCPolicy:
    control = "goal"
    method = "hc"

    def __init__(self, distance: float = DESIRED_DISTANCE, horizon: float = 0.0, turn_rate: bool = True):
        self.distance = distance  # m ahead of the predicted person
        self.horizon = horizon  # s of prediction
        self.turn_rate = turn_rate

    def reset(self) -> None:
        pass

    def goal(self, observation) -> np.ndarray:
        """The goal (x, y) in the current person frame."""
        _, people = obs_lib.split(obs_lib.unscale(np.asarray(observation, dtype=float)))
        people = people[::-1]  # oldest first; the last is the person now, the frame's origin
        ekf = PersonEKF(turn_rate=self.turn_rate)
        for pose in people:
            ekf.step(pose, obs_lib.FRAME_PERIOD)
        x, y, th = ekf.forecast(self.horizon)
        return np.array([x + self.distance * math.cos(th), y + self.distance * math.sin(th)])

    def act(self, observation) -> np.ndarray:
        return action_from_goal(self.goal(observation)).astype(np.float32)
