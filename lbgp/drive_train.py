"""The drive train between a (v, w) command and a base's wheel setpoints: the firmware side of
``lbgp.dynamics.Dynamics`` (a command queue with latency plus per-command jitter, the acceleration
limiter, a first-order lag), advanced once per physics step. The simulator runs it in front of its
wheel servos (``lbgp.sim.drive``), system identification (``lbgp.real.sysid``) on logged commands to
predict the robot's velocity, and the planner's drive model (``lbgp.drive_model``) to predict where
the robot will be when a command acts.
"""

from __future__ import annotations

import collections
import math

import numpy as np

from lbgp.dynamics import Dynamics


class DriveTrain:
    """Commanded (v, w) -> the body-velocity setpoint the wheel servos get, one ``advance(dt)`` at a time."""

    def __init__(self, dynamics: Dynamics, rng: np.random.Generator | None = None):
        self.dynamics = dynamics
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self.reset()

    def reset(self, time: float = 0.0) -> None:
        self.queue: collections.deque = collections.deque()  # (time it acts, v, w)
        self.target = (0.0, 0.0)  # the latest command that has arrived
        self.limited = [0.0, 0.0]  # after the acceleration limiter
        self.output = [0.0, 0.0]  # after the lag: what the servos track
        self.time = time
        self._last_arrival = -math.inf

    def command(self, time: float, v: float, w: float) -> None:
        """A command sent at ``time``; it acts after the latency (commands never overtake each other)."""
        d = self.dynamics
        delay = d.latency + (float(self.rng.uniform(0.0, d.latency_jitter)) if d.latency_jitter > 0 else 0.0)
        arrival = max(time + delay, self._last_arrival)
        self._last_arrival = arrival
        self.queue.append((arrival, float(v), float(w)))

    def advance(self, dt: float) -> tuple[float, float]:
        """Advance ``dt`` seconds; returns the (v, w) setpoint for the servos over that step."""
        d = self.dynamics
        self.time += dt
        while self.queue and self.queue[0][0] <= self.time + 1e-12:
            _, v, w = self.queue.popleft()
            self.target = (v, w)
        limits = (d.max_linear_accel * dt, d.max_angular_accel * dt)
        for i in (0, 1):
            change = self.target[i] - self.limited[i]
            self.limited[i] += min(max(change, -limits[i]), limits[i])
        if d.time_constant > 0:
            alpha = 1.0 - math.exp(-dt / d.time_constant)
            for i in (0, 1):
                self.output[i] += alpha * (self.limited[i] - self.output[i])
        else:
            self.output[0], self.output[1] = self.limited
        return self.output[0], self.output[1]


def simulate_setpoints(dynamics: Dynamics, command_times, commands, sample_times, dt: float = 0.005) -> np.ndarray:
    """The (v, w) setpoints a ``DriveTrain`` with ``dynamics`` (no jitter) gives at ``sample_times``
    for commands sent at ``command_times`` (system identification's model)."""
    drive = DriveTrain(dynamics.replace(latency_jitter=0.0))
    t0 = float(min(command_times[0], sample_times[0]))
    drive.reset(t0)
    out = np.zeros((len(sample_times), 2))
    ci, n_cmd = 0, len(command_times)
    setpoint = (0.0, 0.0)
    for si, ts in enumerate(sample_times):
        while drive.time + dt <= ts + 1e-12:
            while ci < n_cmd and command_times[ci] <= drive.time + 1e-12:
                drive.command(command_times[ci], *commands[ci])
                ci += 1
            setpoint = drive.advance(dt)
        out[si] = setpoint
    return out
