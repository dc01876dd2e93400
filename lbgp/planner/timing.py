"""Time-optimal timing of a band: the dt between poses that makes the band as fast as the velocity
and acceleration limits allow (TEB's "minimal total time" objective, solved in closed form).

Each segment i moves ``length[i]`` metres (signed: negative = backwards) and turns ``turn[i]``
radians. Speeds are capped by the velocity limits, then by a forward pass (accelerating from the
robot's current velocity) and a backward pass (braking into the goal velocity), the classic
v^2 <= v_prev^2 + 2 a s rule applied to the linear and the angular motion separately.
"""

from __future__ import annotations

import numpy as np


def _speed_profile(dist: np.ndarray, cap: np.ndarray, acc: float, start: float, end: float) -> np.ndarray:
    """Largest speeds per segment (>= 0) under ``cap``, reachable from ``start`` and able to brake
    to ``end``.

    In squared speeds the forward pass u_i = min(cap_i^2, u_{i-1} + 2 a d_i) unrolls to
    u_i = 2 a S_i + min(start^2, min_{j <= i}(cap_j^2 - 2 a S_j)) with S the running sum of d,
    a cumulative minimum; the backward pass is the same on the reversed segments.
    """
    two_a = 2.0 * acc
    cap2 = cap * cap
    s = np.cumsum(dist)
    forward = two_a * s + np.minimum(start * start, np.minimum.accumulate(cap2 - two_a * s))
    r = np.cumsum(dist[::-1])
    backward = (two_a * r + np.minimum(end * end, np.minimum.accumulate(cap2[::-1] - two_a * r)))[::-1]
    return np.sqrt(np.maximum(np.minimum(forward, backward), 0.0))


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
    length = np.asarray(length, dtype=float)
    turn = np.asarray(turn, dtype=float)
    dist, angle = np.abs(length), np.abs(turn)
    backwards = length < 0.0
    cap_v = np.where(backwards, max_vel_x_backwards, max_vel_x)
    # the robot carries its current speed into the first segment only if it moves the same way
    start_v = abs(v_now) if (v_now >= 0.0) == (not backwards[0]) else 0.0
    end_v = max(goal_speed, 0.0) if not backwards[-1] else 0.0
    speed = _speed_profile(dist, cap_v, acc_lim_x, min(start_v, cap_v[0]), end_v)
    start_w = abs(w_now) if (w_now >= 0.0) == (turn[0] >= 0.0) else 0.0
    omega = _speed_profile(angle, np.full(len(angle), max_vel_theta), acc_lim_theta, min(start_w, max_vel_theta), 0.0)
    t_lin = dist / np.maximum(speed, 1e-9)
    t_ang = angle / np.maximum(omega, 1e-9)
    return np.maximum(np.maximum(t_lin, t_ang), dt_min)
