"""lbgp: Learning Based Goal Planning for a robot that walks in front of a person.

Data flows one way::

    person trajectory -> world state -> observation -> policy -> goal -> planner -> (v, w) -> wheels

Simulation (``lbgp.sim``) and the real robot (``lbgp.real``) share everything between the
world state and the (v, w) command; they differ only in where poses come from and where
commands go.
"""

import os

# Rollouts never render. Unless the user picked a backend (e.g. MUJOCO_GL=egl to render), keep
# dm_control from probing for a display (GLFW) at import time.
os.environ.setdefault("MUJOCO_GL", "disable")

__version__ = "0.1.0"
