"""The planner's model of the robot's drive: plan from where the robot will be when a command acts.

The planner assumes a command acts at once, at any rate of change within its own limits. A real base
acts on it a latency later and reaches the commanded speed only gradually (a firmware acceleration
limiter, a motor lag: ``lbgp.dynamics``). Given a drive model, a ``Dynamics`` such as the one
``lbgp sysid`` identifies from a deploy log (``--drive-model FILE``), the goal controller

1. plans within the drive's acceleration limits (the lower of the planner's and the firmware's), so
   the commands it sends are ones the base can follow, and
2. plans from the robot's predicted state at the moment the command will act: the commands already
   sent and still in flight (its own, and the deploy loop's safety stops) are run through the very
   drive train the simulator uses (``lbgp.drive_train.DriveTrain``, without jitter) and integrated
   from the measured pose; the person moves along their predicted arc (velocity and turn rate) over
   the same time.

The prediction is open-loop over one latency only (0.1 s on the hardware-like robots), from the
newest measured pose at every call, so its errors do not accumulate. Sim and real use it alike: the
controller gets it from ``lbgp.stack.make_controller``.
"""

from __future__ import annotations

import collections
import copy
import dataclasses
import math

import numpy as np

from lbgp.dynamics import Dynamics, load_dynamics
from lbgp.geometry import predict_person
from lbgp.drive_train import DriveTrain
from lbgp.world import WorldState

STEP = 0.005  # s: integration step of the prediction (the physics step)


class DrivePrediction:
    """Predicts the world state one drive latency ahead, from the commands this controller sent."""

    def __init__(self, dynamics: Dynamics, horizon: float | None = None):
        self.dynamics = dynamics.replace(latency_jitter=0.0)
        # commands wait latency + U(0, jitter): by default, predict over the mean wait
        self.horizon = float(dynamics.latency + 0.5 * dynamics.latency_jitter if horizon is None else horizon)
        if not (math.isfinite(self.horizon) and 0.0 <= self.horizon <= 1.0):
            raise ValueError(f"drive model: prediction horizon must be in [0, 1] s, got {self.horizon}")
        self.reset()

    def reset(self) -> None:
        self.drive: DriveTrain | None = None  # started at the first call (its clock is the state's)

    def _drive_at(self, t: float) -> DriveTrain:
        if self.drive is None or t < self.drive.time - 1e-9:  # first call, or the clock went back: start afresh
            self.drive = DriveTrain(self.dynamics)
            self.drive.reset(t)
        while self.drive.time + STEP <= t + 1e-9:
            self.drive.advance(STEP)
        return self.drive

    def sent(self, t: float, v: float, w: float) -> None:
        """The command sent at ``t`` (after the call to ``predict`` that planned it)."""
        self._drive_at(t).command(t, v, w)

    def predict(self, state: WorldState) -> WorldState:
        """``state`` moved ``horizon`` seconds ahead: the robot by the commands in flight, the person
        along their arc. The robot's velocity stays the last command (the planner chains its limits from it)."""
        if self.horizon <= 0.0:
            return state
        live = self._drive_at(state.t)
        drive = copy.copy(live)  # a scratch copy to run ahead (the queue and filter states copied)
        drive.queue, drive.limited, drive.output = collections.deque(live.queue), list(live.limited), list(live.output)
        x, y, yaw = (float(c) for c in state.robot_pose)
        steps = max(1, int(round(self.horizon / STEP)))
        dt = self.horizon / steps
        for _ in range(steps):
            v, w = drive.advance(dt)
            x += v * math.cos(yaw + 0.5 * w * dt) * dt
            y += v * math.sin(yaw + 0.5 * w * dt) * dt
            yaw += w * dt
        # the person on the planner's constant-turn arc (velocity vector rotating at the turn rate)
        velocity = np.asarray(state.person_velocity, dtype=float)
        person = np.asarray(state.person_pose, dtype=float).copy()
        path, rotation = predict_person(person[:2], velocity, float(state.person_turn_rate), np.array([self.horizon]))
        angle = float(rotation[0])
        c, s = math.cos(angle), math.sin(angle)
        vx, vy = velocity
        person[:2] = path[0]
        person[2] = math.remainder(person[2] + angle, 2 * math.pi)
        return dataclasses.replace(
            state, t=state.t + self.horizon, robot_pose=np.array([x, y, math.remainder(yaw, 2 * math.pi)]),
            person_pose=person, person_velocity=np.array([c * vx - s * vy, s * vx + c * vy]))


def load_drive_model(spec, robot: str) -> Dynamics | None:
    """``None``/``"none"`` (the planner's own assumptions), a ``Dynamics``, a named set (nominal,
    hardware_like) or a JSON file of dynamics (``lbgp sysid``'s output)."""
    if spec is None or spec == "none":
        return None
    return load_dynamics(spec, robot)


def within_drive_limits(limits, dynamics: Dynamics | None):
    """The planner configuration ``limits`` with its acceleration limits lowered to the drive's."""
    if dynamics is None:
        return limits
    return dataclasses.replace(limits, acc_lim_x=min(limits.acc_lim_x, dynamics.max_linear_accel),
                               acc_lim_theta=min(limits.acc_lim_theta, dynamics.max_angular_accel))
