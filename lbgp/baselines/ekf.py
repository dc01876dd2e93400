"""Extended Kalman filter for a walking person, constant turn rate and velocity (CTRV) model.

State ``s = (x, y, theta, v, omega)``; measurements are poses ``(x, y, theta)`` (e.g. from motion
capture or a detector). ``update(None)`` is a dropped measurement: the filter only predicts.
With ``omega`` held at zero (``turn_rate=False``) it is the constant-velocity model.
"""

from __future__ import annotations

import math

import numpy as np

from lbgp.geometry import wrap_angle


def ctrv(state: np.ndarray, dt: float) -> np.ndarray:
    x, y, th, v, w = state
    if abs(w) > 1e-6:
        x2 = x + v / w * (math.sin(th + w * dt) - math.sin(th))
        y2 = y - v / w * (math.cos(th + w * dt) - math.cos(th))
    else:
        x2 = x + v * dt * math.cos(th)
        y2 = y + v * dt * math.sin(th)
    return np.array([x2, y2, th + w * dt, v, w])


def ctrv_jacobian(state: np.ndarray, dt: float) -> np.ndarray:
    """d ctrv / d state (5x5), analytic; on the straight branch (|omega| <= 1e-6) the omega column
    is the turning branch's limit at omega -> 0."""
    x, y, th, v, w = state
    s0, c0 = math.sin(th), math.cos(th)
    J = np.eye(5)
    J[2, 4] = dt
    if abs(w) > 1e-6:
        s1, c1 = math.sin(th + w * dt), math.cos(th + w * dt)
        ds, dc = s1 - s0, c1 - c0
        J[0, 2], J[0, 3], J[0, 4] = v / w * dc, ds / w, v / w * dt * c1 - v / w**2 * ds
        J[1, 2], J[1, 3], J[1, 4] = v / w * ds, -dc / w, v / w * dt * s1 + v / w**2 * dc
    else:
        J[0, 2], J[0, 3], J[0, 4] = -v * dt * s0, dt * c0, -0.5 * v * dt**2 * s0
        J[1, 2], J[1, 3], J[1, 4] = v * dt * c0, dt * s0, 0.5 * v * dt**2 * c0
    return J


class PersonEKF:
    def __init__(self, pos_std: float = 0.05, yaw_std: float = 0.05, acc_std: float = 0.5, yaw_acc_std: float = 0.5, turn_rate: bool = True):
        self.R = np.diag([pos_std**2, pos_std**2, yaw_std**2])
        self.acc_std, self.yaw_acc_std = acc_std, yaw_acc_std
        self.turn_rate = turn_rate
        self._accel_cov = np.diag([acc_std**2, yaw_acc_std**2])
        self.state: np.ndarray | None = None
        self.P = np.eye(5)

    def reset(self, pose) -> None:
        self.state = np.array([pose[0], pose[1], pose[2], 0.0, 0.0], dtype=float)
        self.P = np.diag([self.R[0, 0], self.R[1, 1], self.R[2, 2], 1.0, 1.0])

    def predict(self, dt: float) -> None:
        F = ctrv_jacobian(self.state, dt)
        self.state = ctrv(self.state, dt)
        G = np.array([[0.5 * dt**2 * math.cos(self.state[2]), 0.0], [0.5 * dt**2 * math.sin(self.state[2]), 0.0],
                      [0.0, 0.5 * dt**2], [dt, 0.0], [0.0, dt]])
        Q = G @ self._accel_cov @ G.T
        self.P = F @ self.P @ F.T + Q
        if not self.turn_rate:
            self.state[4] = 0.0
            self.P[4, :] = self.P[:, 4] = 0.0

    def update(self, pose) -> None:
        """Fuse a measured pose; ``None`` (a dropped frame) or a non-finite pose is skipped."""
        if pose is None:
            return
        pose = np.asarray(pose, dtype=float)
        if not (math.isfinite(pose[0]) and math.isfinite(pose[1]) and math.isfinite(pose[2])):
            return
        innovation = pose - self.state[:3]
        innovation[2] = wrap_angle(innovation[2])
        # H = [I 0]: H P H' is P's top-left block, P H' its first three columns, K H is K beside zeros
        # (the same numbers as the products, without them)
        P = self.P
        S = P[:3, :3] + self.R
        K = P[:, :3] @ np.linalg.inv(S)
        self.state = self.state + K @ innovation
        self.state[2] = wrap_angle(self.state[2])
        I_KH = np.eye(5)
        I_KH[:, :3] -= K
        self.P = I_KH @ P

    def step(self, pose, dt: float) -> np.ndarray:
        """Predict ``dt`` then fuse ``pose`` (or start the filter on the first pose)."""
        if self.state is None:
            if pose is None:
                raise ValueError("the first measurement of a track cannot be missing")
            self.reset(pose)
        else:
            self.predict(dt)
            self.update(pose)
        return self.state.copy()

    def forecast(self, horizon: float) -> np.ndarray:
        """The pose predicted ``horizon`` seconds ahead (no update)."""
        return ctrv(self.state, horizon)[:3]
