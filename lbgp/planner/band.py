"""The timed elastic band itself: N poses plus N-1 time intervals, and how it is (re)initialised
and warm-started between planner calls."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from lbgp.geometry import wrap_angle


@dataclasses.dataclass
class Band:
    """Poses (N, 3) with continuous (unwrapped) headings, and dt (N-1,) between them."""

    poses: np.ndarray
    dt: np.ndarray

    @property
    def times(self) -> np.ndarray:
        return np.concatenate([[0.0], np.cumsum(self.dt)])

    def copy(self) -> "Band":
        return Band(self.poses.copy(), self.dt.copy())


def _polyline_poses(points: np.ndarray, n: int, start_yaw: float, goal_yaw: float) -> np.ndarray:
    """n poses evenly spaced by arc length along a polyline; headings follow the path direction."""
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    total = cum[-1]
    s = np.linspace(0.0, total, n)
    xy = np.stack([np.interp(s, cum, points[:, 0]), np.interp(s, cum, points[:, 1])], axis=1)
    poses = np.zeros((n, 3))
    poses[:, :2] = xy
    if total < 0.05:
        headings = start_yaw + np.linspace(0.0, 1.0, n) * wrap_angle(goal_yaw - start_yaw)
    else:
        d = np.diff(xy, axis=0)
        direction = np.arctan2(d[:, 1], d[:, 0])
        headings = np.concatenate([[start_yaw], direction[1:], [goal_yaw]])
        headings = np.concatenate([[start_yaw], start_yaw + np.cumsum(wrap_angle(np.diff(headings)))])
    poses[:, 2] = headings
    return poses


def initial_band(robot_pose, goal, person_xy, clearance: float, n: int) -> Band:
    """A straight band from the robot to the goal, bent around the person when the line passes too close."""
    start = np.asarray(robot_pose[:2], dtype=float)
    end = np.asarray(goal[:2], dtype=float)
    points = np.stack([start, end])
    line = end - start
    length = float(np.linalg.norm(line))
    if length > 1e-6:
        rel = np.asarray(person_xy, dtype=float) - start
        s = float(np.clip(rel @ line / length**2, 0.0, 1.0))
        closest = start + s * line
        if np.linalg.norm(person_xy - closest) < clearance and 0.0 < s < 1.0:
            normal = np.array([-line[1], line[0]]) / length
            side = -1.0 if float(rel @ normal) > 0 else 1.0  # pass on the side away from the person
            via = np.asarray(person_xy, dtype=float) + side * normal * (clearance + 0.2)
            points = np.stack([start, via, end])
    poses = _polyline_poses(points, n, float(robot_pose[2]), float(goal[2]))
    return Band(poses, np.full(n - 1, 0.1))  # the planner times the band before using dt


def shifted_band(band: Band, robot_pose, dt_min: float) -> Band:
    """Warm start: prune the poses the robot has passed (TEB's way) and resample the rest of the
    previous band by arc length from the robot's pose (the planner re-times it)."""
    poses, times = band.poses, band.times
    n = len(poses)
    robot_xy = np.asarray(robot_pose[:2], dtype=float)
    # closest pose to the robot, searched among the first half (the robot cannot be further along)
    j = int(np.argmin(np.linalg.norm(poses[: max(2, n // 2), :2] - robot_xy, axis=1)))
    rest = np.vstack([np.r_[robot_xy, poses[j, 2]], poses[j + 1 :]]) if j + 1 < n else np.vstack([np.r_[robot_xy, poses[j, 2]], poses[-1:]])
    seg = np.linalg.norm(np.diff(rest[:, :2], axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    if cum[-1] < 1e-9:
        cum = np.linspace(0.0, 1.0, len(rest))
    s = np.linspace(0.0, cum[-1], n)
    new = np.stack([np.interp(s, cum, rest[:, k]) for k in range(3)], axis=1)
    yaw0 = new[0, 2] + wrap_angle(float(robot_pose[2]) - new[0, 2])
    new[:, 2] += (yaw0 - new[0, 2]) * np.linspace(1.0, 0.0, n)
    remaining = max(times[-1] - times[j], dt_min * (n - 1))
    return Band(new, np.full(n - 1, remaining / (n - 1)))


def band_is_sane(band: Band, scale: float) -> bool:
    """False when the band holds a non-finite number or has blown up far beyond the problem's scale."""
    if not (np.all(np.isfinite(band.poses)) and np.all(np.isfinite(band.dt))):
        return False
    spread = float(np.max(np.linalg.norm(band.poses[:, :2] - band.poses[0, :2], axis=1)))
    return spread < 10.0 * scale + 5.0 and math.isfinite(spread)
