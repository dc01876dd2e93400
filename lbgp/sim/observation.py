"""The policy's observation, built by the same code in simulation and on the real robot.

Frames arrive at 5 Hz (one per control step). From the last 10 frames the observation stacks, as
the paper does, the robot's relative state z^r and the person's past poses z^h, all expressed in
the *current* person frame:

    index  0..2                  z^r_t       = (x, y, phi) of the robot now
    index  3 + 6(i-1) .. +2      z^h_{t-i}   = (x, y, phi) of the person i frames ago, i = 1..9
    index  6 + 6(i-1) .. +2      z^r_{t-i}   = (x, y, phi) of the robot i frames ago
                                 (z^h_t is the origin and is left out) -> 57 numbers in all.

Scaling to [-1, 1]: x and y are divided by ``POSITION_SCALE`` = 6 m, phi by pi, then clipped. At
the start of an episode the history is filled with copies of the first frame.

Optional Gaussian noise (std ``noise_std`` = (metres, radians)) is added to the relative states
before scaling; it is on in training levels and off in evaluation scenarios by default.

``mirror(obs)`` is the observation of the mirror-image world, reflected about the person's heading
line (y -> -y, phi -> -phi in every frame): the task is symmetric under it (the reward depends on D
and |alpha|, the training levels walk both turn directions), which a policy can use when it acts
(``lbgp.agent.policy``).
"""

from __future__ import annotations

import collections
import math

import numpy as np

from lbgp.conventions import AGENT_PERIOD
from lbgp.geometry import to_frame

FRAMES = 10
FRAME_PERIOD = AGENT_PERIOD  # s, 5 Hz: one frame per agent step
POSITION_SCALE = 6.0  # m
ANGLE_SCALE = math.pi
SIZE = 3 + 6 * (FRAMES - 1)
DEFAULT_NOISE_STD = (0.03, 0.03)  # m, rad


class ObservationStack:
    """Keeps the last 10 (robot, person) world-pose frames and builds the scaled observation."""

    def __init__(self, frames: int = FRAMES, noise_std=None):
        self.frames = frames
        self.noise_std = noise_std
        self._history: collections.deque = collections.deque(maxlen=frames)

    @property
    def size(self) -> int:
        return 3 + 6 * (self.frames - 1)

    def reset(self, robot_pose, person_pose) -> None:
        self._history.clear()
        for _ in range(self.frames):
            self.push(robot_pose, person_pose)

    def push(self, robot_pose, person_pose) -> None:
        robot_pose = np.asarray(robot_pose, dtype=float).copy()
        person_pose = np.asarray(person_pose, dtype=float).copy()
        if not (np.all(np.isfinite(robot_pose)) and np.all(np.isfinite(person_pose))):
            raise ValueError("observation frame has a non-finite pose")
        if not self._history:
            self._history.extend([(robot_pose, person_pose)] * self.frames)
        self._history.append((robot_pose, person_pose))

    def relative_states(self) -> tuple[np.ndarray, np.ndarray]:
        """(robot, person) relative states, newest first, each (frames, 3), in the current person frame."""
        robots = np.array([r for r, _ in reversed(self._history)])
        persons = np.array([p for _, p in reversed(self._history)])
        frame = persons[0]
        return to_frame(robots, frame), to_frame(persons, frame)

    def vector(self, rng: np.random.Generator | None = None) -> np.ndarray:
        z_r, z_h = self.relative_states()
        if self.noise_std is not None and rng is not None:
            std = np.array([self.noise_std[0], self.noise_std[0], self.noise_std[1]])
            z_r = z_r + rng.normal(0.0, 1.0, z_r.shape) * std
            z_h = z_h + rng.normal(0.0, 1.0, z_h.shape) * std
            z_h[0] = 0.0  # the current person pose is the frame's origin by definition
        return scale(layout(z_r, z_h))


def layout(z_r: np.ndarray, z_h: np.ndarray) -> np.ndarray:
    """Interleave relative states newest first: z^r_t, z^h_{t-1}, z^r_{t-1}, ..., z^h_{t-9}, z^r_{t-9}."""
    pairs = np.stack([z_h[1:], z_r[1:]], axis=1).reshape(-1)
    return np.concatenate([z_r[0], pairs])


def split(raw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`layout`: (z_r, z_h), each (frames, 3), newest first; z_h[0], the person
    now, is the frame's origin (zeros)."""
    raw = np.asarray(raw, dtype=float).reshape(-1, 3)
    pairs = raw[1:].reshape(-1, 2, 3)
    z_r = np.concatenate([raw[:1], pairs[:, 1]])
    z_h = np.concatenate([np.zeros((1, 3)), pairs[:, 0]])
    return z_r, z_h


_INV_SCALE = 1.0 / np.array([POSITION_SCALE, POSITION_SCALE, ANGLE_SCALE])


def scale(raw: np.ndarray) -> np.ndarray:
    raw = np.asarray(raw, dtype=float).reshape(-1, 3) * _INV_SCALE
    return np.clip(raw.ravel(), -1.0, 1.0).astype(np.float32)


_MIRROR = np.tile(np.array([1.0, -1.0, -1.0], dtype=np.float32), SIZE // 3)


def mirror(obs: np.ndarray) -> np.ndarray:
    """The observation of the world reflected about the person's heading line: every relative
    state's y and phi change sign (the scaling and its clipping to [-1, 1] are symmetric, so this
    is exact on scaled observations). Works on one observation or a batch (last axis: the 57)."""
    obs = np.asarray(obs, dtype=np.float32)
    if obs.shape[-1:] != (SIZE,):
        raise ValueError(f"an observation has {SIZE} numbers, got shape {obs.shape}")
    return obs * _MIRROR


TURN_RATE_FRAMES = 5  # past person frames (1 s) in the turn-rate estimate below


def turn_rate_weights(frames: int = TURN_RATE_FRAMES) -> np.ndarray:
    """Weights w with ``obs @ w`` = the person's turn rate (rad/s, left positive) seen in a scaled
    observation: the least-squares slope, through the origin, of the person's past headings in the
    current person frame (a person turning at omega was heading -omega * i * FRAME_PERIOD i frames
    ago) over the last ``frames`` frames. Linear in the observation, so it works on numpy arrays and
    torch tensors alike, one observation or a batch; the mirror image's turn rate is its negative."""
    if not 1 <= frames < FRAMES:
        raise ValueError(f"the turn-rate estimate uses 1 to {FRAMES - 1} past frames, got {frames}")
    return _person_slope_weights(2, frames, ANGLE_SCALE).astype(np.float32)


def _person_slope_weights(component: int, frames: int, scale: float) -> np.ndarray:
    """Weights (SIZE,) of the least-squares slope through the origin, per second, of the person's
    past ``component`` (0: x, 1: y, 2: heading; scaled by ``scale``) over the last ``frames``
    frames, in the current person frame, where the person now is the origin: a quantity that
    changes at rate r was -r * i * FRAME_PERIOD i frames ago."""
    i = np.arange(1, frames + 1)
    w = np.zeros(SIZE)
    w[3 + 6 * (i - 1) + component] = -i * scale / (np.sum(i * i) * FRAME_PERIOD)
    return w


MOTION_FEATURES = ("person_vx", "person_vy", "person_turn_rate", "robot_vx", "robot_vy")
VELOCITY_FRAMES = 2  # past person frames (0.4 s) in the person-velocity estimate below


def motion_feature_weights() -> np.ndarray:
    """Weights W (SIZE, 5) with ``obs @ W`` = motion estimates read linearly off a scaled
    observation, in the current person frame (x ahead, y left), SI units: the person's velocity
    (m/s; the slope of their last ``VELOCITY_FRAMES`` past positions, as ``turn_rate_weights``
    takes the slope of their headings), their turn rate (rad/s, ``turn_rate_weights``) and the
    robot's velocity over the ground expressed in the current person frame (m/s; its last
    frame-to-frame displacement). The stacked frames already hold all of this; an optional actor
    and critic input (``D4PGConfig.motion_features``) that spares the network learning the
    differences. Linear, so numpy and torch alike; the mirror image's y velocities and turn rate are
    the negatives."""
    w = np.zeros((SIZE, len(MOTION_FEATURES)))
    w[:, 0] = _person_slope_weights(0, VELOCITY_FRAMES, POSITION_SCALE)
    w[:, 1] = _person_slope_weights(1, VELOCITY_FRAMES, POSITION_SCALE)
    w[:, 2] = turn_rate_weights()
    w[0, 3] = w[1, 4] = POSITION_SCALE / FRAME_PERIOD  # z^r_t - z^r_{t-1}
    w[6, 3] = w[7, 4] = -POSITION_SCALE / FRAME_PERIOD
    return w.astype(np.float32)


def unscale(obs: np.ndarray) -> np.ndarray:
    """Metric relative states back from a (noise-free, unclipped) observation vector."""
    return (np.asarray(obs, dtype=float).reshape(-1, 3) / _INV_SCALE).ravel()


def estimate_person_motion(track, t_now: float, pose, period: float = FRAME_PERIOD) -> tuple[np.ndarray, float]:
    """Person world velocity (vx, vy) and yaw rate by finite difference over about ``period``
    seconds: from the latest pose in ``track`` (an oldest-first sequence of (t, pose)) that is at
    least ``period`` older than ``pose`` at ``t_now`` (the oldest one while none is) to ``pose``.
    The one rule of the simulator (``FollowAheadTask``) and the deploy loop (``lbgp.real.loop``)."""
    older = [(t, p) for t, p in track if t <= t_now - period + 1e-6]
    t0, p0 = older[-1] if older else track[0]
    return estimate_person_velocity(p0, pose, t_now - t0), estimate_person_turn_rate(p0, pose, t_now - t0)


def estimate_person_turn_rate(prev_pose, pose, dt: float) -> float:
    """Person yaw rate (rad/s) by finite difference of two poses ``dt`` seconds apart."""
    if dt <= 0:
        return 0.0
    return math.remainder(float(pose[2]) - float(prev_pose[2]), 2.0 * math.pi) / dt


def estimate_person_velocity(prev_pose, pose, dt: float) -> np.ndarray:
    """Person world velocity (vx, vy) by finite difference of two poses ``dt`` seconds apart."""
    if dt <= 0:
        return np.zeros(2)
    return (np.asarray(pose[:2], dtype=float) - np.asarray(prev_pose[:2], dtype=float)) / dt
