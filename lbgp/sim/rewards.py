"""The paper's follow-ahead reward and termination rule (section "Reward").

D is the robot-person distance in metres, alpha the person-robot angle in radians with
alpha = 0 meaning the robot is straight in front of the person.
"""

from __future__ import annotations

import math

import numpy as np

from lbgp.conventions import DESIRED_DISTANCE

MIN_DISTANCE = 0.5  # m: closer ends the episode
MAX_DISTANCE = 5.0  # m: farther ends the episode
CONE_DEG = 25.0  # half-angle of the rewarded cone in front of the person


def distance_reward(distance: float) -> float:
    """R_d: peaks (+0.25) at D = 1.5 m; note the paper's jump from 0 to -0.25 at D = 2 m."""
    d = float(distance)
    if d < MIN_DISTANCE or d > MAX_DISTANCE:
        return -1.0
    if d < 1.0:
        return -(1.0 - d)
    if d <= 2.0:
        return 0.5 * (0.5 - abs(d - DESIRED_DISTANCE))
    return -0.25 * (d - 1.0)


def orientation_reward(alpha: float) -> float:
    """R_o: +0.5 straight ahead, falling linearly to 0 at 25 deg, then -0.25 |alpha| / 180 deg."""
    a = abs(math.degrees(float(alpha)))
    if a < CONE_DEG:
        return 0.5 * (CONE_DEG - a) / CONE_DEG
    return -0.25 * a / 180.0


def follow_ahead_reward(distance: float, alpha: float) -> float:
    """R = clip(R_o + R_d, -1, 1); alpha in radians (0 = robot straight in front)."""
    if not (math.isfinite(distance) and math.isfinite(alpha)):
        raise ValueError(f"reward needs finite distance and alpha, got D={distance!r}, alpha={alpha!r}")
    return min(max(orientation_reward(alpha) + distance_reward(distance), -1.0), 1.0)


def out_of_range(distance: float) -> bool:
    """The paper's termination: too close (D < 0.5 m) or too far (D > 5 m)."""
    return distance < MIN_DISTANCE or distance > MAX_DISTANCE


def follow_ahead_reward_array(distance, alpha) -> np.ndarray:
    """The same reward for arrays of D (m) and alpha (rad), elementwise (for analysis tools)."""
    d = np.asarray(distance, dtype=float)
    a = np.abs(np.degrees(np.asarray(alpha, dtype=float)))
    r_d = np.select(
        [(d < MIN_DISTANCE) | (d > MAX_DISTANCE), d < 1.0, d <= 2.0],
        [-1.0, -(1.0 - d), 0.5 * (0.5 - np.abs(d - DESIRED_DISTANCE))],
        -0.25 * (d - 1.0),
    )
    r_o = np.where(a < CONE_DEG, 0.5 * (CONE_DEG - a) / CONE_DEG, -0.25 * a / 180.0)
    return np.clip(r_o + r_d, -1.0, 1.0)
