"""The simulated robot base between a (v, w) command and the wheel servos, and applying a robot's
``Dynamics`` (``lbgp.dynamics``) to a compiled MuJoCo model.

``DriveTrain`` is the firmware side: a command queue (latency plus per-command jitter), the
acceleration limiter, and a first-order lag, advanced once per physics step. System identification
(``lbgp.real.sysid``) runs the very same class on logged commands to predict the robot's velocity.
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


# --------------------------------------------------------------------------- the MuJoCo model side
class ModelDynamics:
    """Remembers a compiled model's nominal robot parameters and applies a ``Dynamics`` to them
    (again and again: per-episode randomisation starts from the nominal values each time)."""

    def __init__(self, model, robot_body: int, left, right):
        import mujoco

        self.model = model
        actuators = np.concatenate([np.asarray(left), np.asarray(right)]).astype(int)
        self.actuators = actuators
        robot_bodies = np.flatnonzero(model.body_rootid == robot_body)
        self.bodies = robot_bodies
        joints = model.actuator_trnid[actuators, 0]
        wheel_bodies = model.jnt_bodyid[joints]
        self.wheel_geoms = np.flatnonzero(np.isin(model.geom_bodyid, wheel_bodies) & (model.geom_contype != 0))
        if len(self.wheel_geoms) == 0:
            raise ValueError("robot MJCF: the wheel actuators' bodies have no colliding geoms")
        self.kv = model.actuator_gainprm[actuators, 0].copy()
        self.forcerange = model.actuator_forcerange[actuators].copy()
        self.forcelimited = model.actuator_forcelimited[actuators].copy()
        self.mass = model.body_mass[robot_bodies].copy()
        self.inertia = model.body_inertia[robot_bodies].copy()
        self.friction = model.geom_friction[self.wheel_geoms].copy()
        self._mujoco = mujoco

    @property
    def nominal_sliding_friction(self) -> float:
        return float(self.friction[0, 0])

    def apply(self, dynamics: Dynamics, data=None) -> None:
        m, a = self.model, self.actuators
        kv = self.kv * dynamics.servo_gain_scale
        m.actuator_gainprm[a, 0] = kv
        m.actuator_biasprm[a, 2] = -kv
        if dynamics.torque_limit is None:
            m.actuator_forcerange[a] = self.forcerange
            m.actuator_forcelimited[a] = self.forcelimited
        else:
            m.actuator_forcerange[a] = np.array([-1.0, 1.0]) * dynamics.torque_limit
            m.actuator_forcelimited[a] = 1
        m.body_mass[self.bodies] = self.mass * dynamics.mass_scale
        m.body_inertia[self.bodies] = self.inertia * dynamics.inertia_scale
        friction = self.friction.copy()
        if dynamics.sliding_friction is not None:
            friction[:, 0] = dynamics.sliding_friction
        if dynamics.torsional_friction is not None:
            friction[:, 1] = dynamics.torsional_friction
        m.geom_friction[self.wheel_geoms] = friction
        if data is not None:
            self._mujoco.mj_setConst(m, data)  # derived quantities (body_subtreemass, ...) follow the new masses
