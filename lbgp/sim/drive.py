"""Applying a robot's ``Dynamics`` (``lbgp.dynamics``) to a compiled MuJoCo model: servo gains,
torque limits, mass, inertia and friction. The firmware side in front of the wheel servos (latency,
limiter, lag) is ``lbgp.drive_train.DriveTrain``, shared with system identification and the
planner's drive model.
"""

from __future__ import annotations

import numpy as np

from lbgp.dynamics import Dynamics


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
