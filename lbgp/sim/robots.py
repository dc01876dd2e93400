"""MuJoCo side of the robot descriptions: finding a robot's wheel actuators in a compiled model.

The descriptions themselves (``RobotSpec``, ``DiffDrive``, ``get_robot``, ...) live in
``lbgp.robots``, below the simulator, the planner and the real robot; they are re-exported here
for code written against the old location.
"""

from __future__ import annotations

import numpy as np

from lbgp.robots import ASSETS, JACKAL, ROBOTS, TURTLEBOT2, DiffDrive, RobotSpec, get_robot

__all__ = ["ASSETS", "JACKAL", "ROBOTS", "TURTLEBOT2", "DiffDrive", "RobotSpec", "get_robot", "actuator_indices"]


def actuator_indices(model, spec: RobotSpec) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the left and right wheel actuators of ``spec`` in a compiled MuJoCo model."""
    import mujoco

    def ids(names):
        out = []
        for n in names:
            i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, n)
            if i < 0:
                raise ValueError(f"MJCF for robot {spec.name!r} has no actuator named {n!r}")
            out.append(i)
        return np.array(out, dtype=int)

    return ids(spec.left_actuators), ids(spec.right_actuators)
