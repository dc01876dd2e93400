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

# One BLAS thread per process: the planner's small dense products gain nothing from threads, and
# several lbgp processes (actors, learner) on a few cores would oversubscribe them (a planner call
# took 3x longer beside one busy process). The environment covers numpy loaded after this line
# (and the actor processes, which inherit it); threadpoolctl covers a numpy loaded before lbgp.
# Set LBGP_BLAS_THREADS to allow more.
_BLAS_THREADS = os.environ.get("LBGP_BLAS_THREADS", "1")
for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, _BLAS_THREADS)
try:
    from threadpoolctl import threadpool_limits as _threadpool_limits

    _threadpool_limits(int(_BLAS_THREADS), user_api="blas")
except (ImportError, ValueError):  # pragma: no cover - threadpoolctl is a dependency; a bad value keeps the default
    pass

__version__ = "0.1.0"
