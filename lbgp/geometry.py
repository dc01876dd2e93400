"""Planar geometry shared by simulation, planner and real robot.

Poses are ``(x, y, yaw)`` in metres and radians. The person frame has its origin at the person,
x along the person's heading and y to the person's left.
"""

from __future__ import annotations

import math

import numpy as np


def wrap_angle(angle):
    """Wrap an angle (scalar or array) to (-pi, pi]."""
    if isinstance(angle, (float, int)):
        a = math.fmod(angle + math.pi, 2.0 * math.pi)
        a = a + 2.0 * math.pi if a < 0.0 else a
        a -= math.pi
        return a + 2.0 * math.pi if a <= -math.pi else a
    wrapped = np.mod(np.asarray(angle, dtype=float) + np.pi, 2.0 * np.pi) - np.pi
    wrapped = np.where(wrapped <= -np.pi, wrapped + 2.0 * np.pi, wrapped)
    return float(wrapped) if np.ndim(wrapped) == 0 else wrapped


def to_frame(pose, frame) -> np.ndarray:
    """Express world pose(s) ``pose`` (..., 3) in the frame of world pose ``frame`` (3,)."""
    pose = np.asarray(pose, dtype=float)
    fx, fy, fyaw = (float(v) for v in frame)
    c, s = math.cos(fyaw), math.sin(fyaw)
    dx = pose[..., 0] - fx
    dy = pose[..., 1] - fy
    out = np.empty(pose.shape, dtype=float)
    out[..., 0] = c * dx + s * dy
    out[..., 1] = -s * dx + c * dy
    out[..., 2] = wrap_angle(pose[..., 2] - fyaw)
    return out


def from_frame(pose, frame) -> np.ndarray:
    """Inverse of :func:`to_frame`: a pose given in ``frame`` expressed in the world."""
    pose = np.asarray(pose, dtype=float)
    fx, fy, fyaw = (float(v) for v in frame)
    c, s = math.cos(fyaw), math.sin(fyaw)
    out = np.empty(pose.shape, dtype=float)
    out[..., 0] = fx + c * pose[..., 0] - s * pose[..., 1]
    out[..., 1] = fy + s * pose[..., 0] + c * pose[..., 1]
    out[..., 2] = wrap_angle(pose[..., 2] + fyaw)
    return out


def distance_and_alpha(robot_pose, person_pose) -> tuple[float, float]:
    """D (m) and alpha (rad, 0 = robot straight in front of the person, + = to the person's left)."""
    dx = float(robot_pose[0]) - float(person_pose[0])
    dy = float(robot_pose[1]) - float(person_pose[1])
    c, s = math.cos(float(person_pose[2])), math.sin(float(person_pose[2]))
    x, y = c * dx + s * dy, -s * dx + c * dy  # the robot in the person frame
    return math.hypot(x, y), math.atan2(y, x)


def yaw_from_quaternion(x: float, y: float, z: float, w: float) -> float:
    """Rotation about the vertical axis (rad) of a unit quaternion (x, y, z, w), z up."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def pose_from_polar(person_pose, distance: float, alpha: float, relative_yaw: float = 0.0) -> np.ndarray:
    """World pose at ``distance`` and angle ``alpha`` from the person, heading person yaw + relative_yaw."""
    rel = np.array([distance * math.cos(alpha), distance * math.sin(alpha), relative_yaw])
    return from_frame(rel, person_pose)


def integrate_unicycle(pose, v: float, w: float, dt) -> np.ndarray:
    """Exact arc integration of a unicycle from ``pose`` with constant (v, w) for time(s) ``dt``.

    ``dt`` may be an array; the result then has shape (len(dt), 3).
    """
    x, y, yaw = (float(p) for p in pose)
    t = np.asarray(dt, dtype=float)
    if abs(w) < 1e-9:
        px = x + v * t * math.cos(yaw)
        py = y + v * t * math.sin(yaw)
        pyaw = np.full_like(t, yaw)
    else:
        pyaw = yaw + w * t
        px = x + v / w * (np.sin(pyaw) - math.sin(yaw))
        py = y - v / w * (np.cos(pyaw) - math.cos(yaw))
    out = np.stack([px, py, wrap_angle(pyaw)], axis=-1)
    return out


def predict_person(xy, velocity, turn_rate: float, times: np.ndarray):
    """The person's positions at ``times`` on a constant-turn arc (velocity vector rotating at
    ``turn_rate``), and how far the person has turned by then (rad)."""
    rotation = turn_rate * times
    if abs(turn_rate) < 1e-6:
        return xy[None, :] + times[:, None] * velocity[None, :], rotation
    # integral of R(w s) v ds = (1/w) [[sin wt, cos wt - 1], [1 - cos wt, sin wt]] v
    s_, c1 = np.sin(rotation), np.cos(rotation) - 1.0
    vx, vy = velocity
    dx = (s_ * vx + c1 * vy) / turn_rate
    dy = (-c1 * vx + s_ * vy) / turn_rate
    return xy[None, :] + np.stack([dx, dy], axis=1), rotation


def finite_pose(pose) -> bool:
    """True when every component of the pose is a finite number."""
    return bool(np.all(np.isfinite(np.asarray(pose, dtype=float))))
