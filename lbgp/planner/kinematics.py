"""The band's poses as a function of the commands between them (diff-drive kinematics, exact).

A band of N poses is timed at a fixed interval h; between pose k and k+1 the robot drives (v_k, w_k)
for h seconds. Each segment is integrated with the midpoint heading,

    theta_{k+1} = theta_k + w_k h
    p_{k+1}     = p_k + v_k h (cos phi_k, sin phi_k),   phi_k = theta_k + w_k h / 2,

so the band is non-holonomic by construction. The rollout is vectorised over the band; the
planner linearises these same equations (one segment at a time) as the equality rows of its QP.
"""

from __future__ import annotations

import math

import numpy as np


def rollout(pose0, v: np.ndarray, w: np.ndarray, h: float) -> np.ndarray:
    """Poses (M+1, 3) from ``pose0`` driving the commands ``v``, ``w`` (M,) for ``h`` s each.
    Headings are continuous (not wrapped)."""
    theta = pose0[2] + h * np.concatenate([[0.0], np.cumsum(w)])
    phi = theta[:-1] + 0.5 * h * w
    poses = np.empty((len(v) + 1, 3))
    poses[0, 0], poses[0, 1] = pose0[0], pose0[1]
    poses[1:, 0] = pose0[0] + np.cumsum(h * v * np.cos(phi))
    poses[1:, 1] = pose0[1] + np.cumsum(h * v * np.sin(phi))
    poses[:, 2] = theta
    return poses


def pursuit_commands(pose0, v_start: float, w_start: float, goal_path, goal_vel, h: float, first_period: float,
                     M: int, limits, reverse: bool, wait: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """A deterministic first guess for the band: a simple pursuit of the moving goal, rolled out
    for M segments within the velocity and acceleration limits.

    The robot steers towards where the goal will be at the end of each segment (``goal_path``,
    (M, 2)) and matches the goal's current velocity ``goal_vel`` plus a proportional correction
    along its heading. With ``reverse`` it faces
    the goal with whichever end is closer (the goal behind it is reached by slowing or reversing);
    without, it turns its front towards the goal (a goal behind it means turning around). With
    ``wait`` it brakes to a stop while steering (to let a person cross in front of it first).
    """
    x, y, th = float(pose0[0]), float(pose0[1]), float(pose0[2])
    gvx, gvy = float(goal_vel[0]), float(goal_vel[1])
    v_prev, w_prev = v_start, w_start
    vs, ws = [0.0] * M, [0.0] * M
    tau_v, tau_w, look = 0.6, 0.35, 1.0  # s: time constants and look-ahead (only shape the first guess)
    acc_v, acc_w = limits.acc_lim_x, limits.acc_lim_theta
    v_lo, v_hi, w_hi = -limits.max_vel_x_backwards, limits.max_vel_x, limits.max_vel_theta
    sin, cos, atan2 = math.sin, math.cos, math.atan2
    half_pi, pi = 0.5 * math.pi, math.pi
    for k, (gx, gy) in enumerate(goal_path[:M].tolist()):
        rx, ry = gx - x, gy - y
        c, s = cos(th), sin(th)
        # steer towards where the goal will be ``look`` s later: well defined even on the goal
        ax, ay = rx + gvx * look, ry + gvy * look
        e = atan2(ay, ax) - th
        e = atan2(sin(e), cos(e))
        if reverse and abs(e) > half_pi:
            e = e - math.copysign(pi, e)
        v_des = 0.0 if wait else (gvx * c + gvy * s) + (rx * c + ry * s) / tau_v
        if not reverse:
            v_des = max(v_des, 0.0)  # turning the front towards the goal: turn (on the spot), never back up
        w_des = e / tau_w * min(1.0, math.hypot(ax, ay) / 0.3)
        dt_acc = first_period if k == 0 else h
        dv, dw = acc_v * dt_acc, acc_w * dt_acc
        v = min(max(v_des, v_prev - dv, v_lo), v_prev + dv, v_hi)
        w = min(max(w_des, w_prev - dw, -w_hi), w_prev + dw, w_hi)
        phi = th + 0.5 * w * h
        x += v * h * cos(phi)
        y += v * h * sin(phi)
        th += w * h
        vs[k], ws[k] = v, w
        v_prev, w_prev = v, w
    return np.array(vs), np.array(ws)
