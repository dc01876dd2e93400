"""How the simulated person walks: one motion model per curriculum level, plus path tracking.

Every model is a unicycle command source: once per control step (0.2 s) it returns the person's
linear and angular velocity (v, w); the simulator integrates the exact arc between steps. Models
draw randomness only from the ``numpy.random.Generator`` passed to :meth:`reset`.
"""

from __future__ import annotations

import math

import numpy as np

from lbgp.geometry import wrap_angle
from lbgp.sim.paths import draw_path, resample_path


class PersonMotion:
    """Base class: ``reset`` at the start of an episode, then ``command`` once per control step."""

    def reset(self, rng: np.random.Generator, pose: np.ndarray) -> np.ndarray:
        """Start an episode; returns the person's initial world pose (may differ from ``pose``)."""
        return np.asarray(pose, dtype=float)

    def command(self, pose: np.ndarray, dt: float) -> tuple[float, float]:
        raise NotImplementedError


class StraightMotion(PersonMotion):
    """Walk straight at one speed; the speed is drawn per episode unless given."""

    def __init__(self, speed: float | None = None, speed_range=(0.3, 1.0)):
        self.fixed_speed = speed
        self.speed_range = speed_range
        self.speed = speed if speed is not None else 0.5

    def reset(self, rng, pose):
        if self.fixed_speed is None:
            self.speed = float(rng.uniform(*self.speed_range))
        return super().reset(rng, pose)

    def command(self, pose, dt):
        return self.speed, 0.0


class CircleMotion(PersonMotion):
    """Walk a circle: v in [0.2, 0.6] m/s, |w| in [0.3, 0.8] rad/s, either direction (paper)."""

    def __init__(self, v: float | None = None, w: float | None = None, v_range=(0.2, 0.6), w_range=(0.3, 0.8)):
        self.fixed = (v, w)
        self.v_range, self.w_range = v_range, w_range
        self.v, self.w = (v or 0.3), (w or 0.3)

    def reset(self, rng, pose):
        v, w = self.fixed
        self.v = float(rng.uniform(*self.v_range)) if v is None else v
        self.w = float(rng.uniform(*self.w_range) * rng.choice([-1.0, 1.0])) if w is None else w
        return super().reset(rng, pose)

    def command(self, pose, dt):
        return self.v, self.w


class SmoothedMotion(PersonMotion):
    """Random smooth curves (paper): V_t = V_{t-1} - (V_{t-1} - R)/3 with R redrawn every step,
    R1 in [0, 1] for the linear and R2 in [-1, 1] for the angular velocity."""

    def __init__(self):
        self.v = self.w = 0.0
        self.rng = None

    def reset(self, rng, pose):
        self.rng = rng
        self.v = float(rng.uniform(0.0, 1.0))
        self.w = float(rng.uniform(-1.0, 1.0))
        return super().reset(rng, pose)

    def command(self, pose, dt):
        r1 = self.rng.uniform(0.0, 1.0)
        r2 = self.rng.uniform(-1.0, 1.0)
        self.v = float(self.v - (self.v - r1) / 3.0)
        self.w = float(self.w - (self.w - r2) / 3.0)
        return self.v, self.w


class PathMotion(PersonMotion):
    """Follow a waypoint path with a PID controller on the heading error to a look-ahead point.

    The person walks at ``speed`` and stops at the end of the path. With ``paths`` holding several
    paths (the training library), each episode picks one at random and starts at a random point in
    its first ``start_fraction``; the path is moved so that it starts at the person's spawn pose.
    """

    def __init__(
        self,
        paths,
        speed: float | None = 0.5,
        speed_range=(0.4, 0.8),
        start_fraction: float = 0.0,
        anchor: bool = True,
        lookahead: float = 0.4,
        gains=(2.5, 0.0, 0.15),
        max_yaw_rate: float = 1.5,
    ):
        if isinstance(paths, np.ndarray):
            paths = [paths]
        self.paths = [resample_path(p) for p in paths]
        self.fixed_speed = speed
        self.speed_range = speed_range
        self.start_fraction = start_fraction
        self.anchor = anchor
        self.lookahead = lookahead
        self.kp, self.ki, self.kd = gains
        self.max_yaw_rate = max_yaw_rate
        self.path = self.paths[0]
        self.speed = speed or 0.5
        self._reset_tracker()

    def _reset_tracker(self):
        self.index = 0
        self.integral = 0.0
        self.prev_error = None
        self.finished = False

    def reset(self, rng, pose):
        path = self.paths[int(rng.integers(len(self.paths)))] if len(self.paths) > 1 else self.paths[0]
        start = int(rng.integers(0, max(1, int(self.start_fraction * (len(path) - 1)) + 1)))
        path = path[start:]
        if len(path) < 2:
            path = self.paths[0]
        self.speed = float(rng.uniform(*self.speed_range)) if self.fixed_speed is None else self.fixed_speed
        self._reset_tracker()
        pose = np.asarray(pose, dtype=float)
        if self.anchor:
            # rigidly move the path so that it starts at the spawn pose, initial direction = heading
            d = path[min(3, len(path) - 1)] - path[0]
            path_heading = math.atan2(d[1], d[0])
            rot = pose[2] - path_heading
            c, s = math.cos(rot), math.sin(rot)
            rel = path - path[0]
            self.path = pose[:2] + rel @ np.array([[c, s], [-s, c]])
            return pose
        self.path = path
        d = path[min(3, len(path) - 1)] - path[0]
        return np.array([path[0, 0], path[0, 1], math.atan2(d[1], d[0])])

    def command(self, pose, dt):
        if self.finished:
            return 0.0, 0.0
        pts = self.path
        # advance the progress index to the nearest waypoint ahead (never backwards)
        window = pts[self.index : self.index + 40]
        self.index += int(np.argmin(np.linalg.norm(window - pose[:2], axis=1)))
        if np.linalg.norm(pts[-1] - pose[:2]) < 0.15 or self.index >= len(pts) - 1:
            self.finished = True
            return 0.0, 0.0
        seg = np.linalg.norm(np.diff(pts[self.index :], axis=0), axis=1)
        k = self.index + int(np.searchsorted(np.cumsum(seg), self.lookahead))
        target = pts[min(k, len(pts) - 1)]
        error = wrap_angle(math.atan2(target[1] - pose[1], target[0] - pose[0]) - pose[2])
        self.integral += error * dt
        deriv = 0.0 if self.prev_error is None else wrap_angle(error - self.prev_error) / dt
        self.prev_error = error
        w = self.kp * error + self.ki * self.integral + self.kd * deriv
        w = float(np.clip(w, -self.max_yaw_rate, self.max_yaw_rate))
        # slow down for sharp heading errors, like a person turning on the spot
        v = self.speed * max(0.2, math.cos(min(abs(error), math.pi / 2)))
        return v, w


class DrawnPathMotion(PathMotion):
    """PathMotion on a freshly drawn human-like path every episode instead of the library's 20.

    Each episode draws a path of ``length`` metres with :func:`lbgp.sim.paths.draw_path` (the
    generator of the library and of the evaluation paths), seeded from the episode's random stream,
    and walks it as :class:`PathMotion` walks the library's: the same straights, arcs and speeds,
    never the same layout twice. For training only (``lbgp train --set drawn_paths=true``).
    """

    def __init__(self, length: float, **kwargs):
        if not (math.isfinite(length) and length > 0.0):
            raise ValueError(f"a drawn path needs a finite length > 0 m, got {length!r}")
        self.length = float(length)
        super().__init__(draw_path(0, self.length), speed=None, **kwargs)

    def reset(self, rng, pose):
        self.paths = [resample_path(draw_path(int(rng.integers(2**31)), self.length))]
        return super().reset(rng, pose)
