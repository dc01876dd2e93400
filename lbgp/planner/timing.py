"""Time-optimal timing of a band: the dt between poses that makes the band as fast as the velocity
and acceleration limits allow (TEB's "minimal total time" objective, solved in closed form).

Each segment i moves ``length[i]`` metres (signed: negative = backwards) and turns ``turn[i]``
radians. Speeds are capped by the velocity limits, then by a forward pass (accelerating from the
robot's current velocity) and a backward pass (braking into the goal velocity), the classic
v^2 <= v_prev^2 + 2 a s rule applied to the linear and the angular motion separately.
"""

from __future__ import annotations

import math

import numpy as np


def _speed_profile(dist, cap, acc: float, start: float, end: float) -> list[float]:
    """Largest speeds per segment (>= 0) under ``cap``, reachable from ``start`` and able to brake
    to ``end``. Plain floats: this runs every planner iteration on ~20 segments."""
    v = list(cap)
    prev = start
    for i, d in enumerate(dist):
        prev = v[i] = min(v[i], math.sqrt(prev * prev + 2.0 * acc * d))
    nxt = end
    for i in range(len(v) - 1, -1, -1):
        nxt = v[i] = min(v[i], math.sqrt(nxt * nxt + 2.0 * acc * dist[i]))
    return v


def time_segments(
    length,
    turn,
    v_now: float,
    w_now: float,
    goal_speed: float,
    max_vel_x: float,
    max_vel_x_backwards: float,
    max_vel_theta: float,
    acc_lim_x: float,
    acc_lim_theta: float,
    dt_min: float,
) -> np.ndarray:
    """dt of each segment (seconds, >= dt_min)."""
    length = [float(x) for x in length]
    turn = [float(x) for x in turn]
    dist = [abs(x) for x in length]
    angle = [abs(x) for x in turn]
    cap_v = [max_vel_x_backwards if x < 0.0 else max_vel_x for x in length]
    # the robot carries its current speed into the first segment only if it moves the same way
    start_v = abs(v_now) if (v_now >= 0.0) == (length[0] >= 0.0) else 0.0
    end_v = max(goal_speed, 0.0) if length[-1] >= 0.0 else 0.0
    speed = _speed_profile(dist, cap_v, acc_lim_x, min(start_v, cap_v[0]), end_v)
    start_w = abs(w_now) if (w_now >= 0.0) == (turn[0] >= 0.0) else 0.0
    omega = _speed_profile(angle, [max_vel_theta] * len(angle), acc_lim_theta, min(start_w, max_vel_theta), 0.0)
    dt = []
    for d, v, a, w in zip(dist, speed, angle, omega):
        t = dt_min
        if d > 1e-9:
            t = max(t, d / max(v, 1e-9))
        if a > 1e-9:
            t = max(t, a / max(w, 1e-9))
        dt.append(t)
    return np.array(dt)
