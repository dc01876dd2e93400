"""Agent steps per second of the follow-ahead task layer vs the raw MuJoCo step rate.

    python benchmarks/bench_env.py --json results/bench_env.json

For each robot, in one process: (1) the task with a constant (v, w) command (no planner: the
"zero-planner constant command" case), (2) the goal-driven task (planner at 10 Hz), (3) raw
``mj_step`` on the same compiled model, 40 steps (= one 0.2 s agent step) per call and as 40 single
calls. The ratio (1)/(3) is the share of the raw physics rate that the task layer keeps.
"""

from __future__ import annotations

import argparse
import os
import sys
import platform
import time
from pathlib import Path

import mujoco
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_result  # noqa: E402

from lbgp.actions import action_from_goal  # noqa: E402
from lbgp.sim import make_env  # noqa: E402


def rate(fn, seconds: float) -> float:
    n, t0 = 0, time.perf_counter()
    while time.perf_counter() - t0 < seconds:
        fn()
        n += 1
    return n / (time.perf_counter() - t0)


def bench_robot(robot: str, seconds: float) -> dict:
    out = {}
    for control, action in (("velocity", np.array([0.3, 0.0], np.float32)), ("goal", action_from_goal([1.5, 0.0]))):
        env = make_env("straight_ahead", robot=robot, seed=0, control=control, horizon=10**9)
        env.reset()
        for _ in range(10):
            env.step(action)

        def step():
            if env.step(action).last():
                env.reset()

        out[f"task_{control}_steps_per_s"] = rate(step, seconds)
    # raw physics of the same model from the same episode start and the same wheel command,
    # restarting every 35 agent steps like the task's episodes
    env = make_env("straight_ahead", robot=robot, seed=0, control="velocity")
    env.reset()
    env.task.apply_command(env.physics)  # zero command; then the constant one below
    env.physics.drive_wheels(0.3, 0.0)
    model, data = env.physics.model.ptr, env.physics.data.ptr
    start = (data.qpos.copy(), data.qvel.copy(), data.ctrl.copy())
    n = env.n_physics
    counter = [0]

    def restart_every_episode():
        counter[0] += 1
        if counter[0] % 35 == 0:
            mujoco.mj_resetData(model, data)
            data.qpos[:], data.qvel[:], data.ctrl[:] = start

    def batched():
        mujoco.mj_step(model, data, n)
        restart_every_episode()

    def single():
        for _ in range(n):
            mujoco.mj_step(model, data)
        restart_every_episode()

    out["raw_mj_step_agent_steps_per_s"] = rate(batched, seconds)
    out["raw_single_mj_step_agent_steps_per_s"] = rate(single, seconds)
    out["physics_steps_per_agent_step"] = n
    out["task_share_of_raw"] = out["task_velocity_steps_per_s"] / out["raw_mj_step_agent_steps_per_s"]
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", required=True, help="output file")
    parser.add_argument("--seconds", type=float, default=5.0, help="measuring time per figure")
    args = parser.parse_args()
    result = {
        "machine": {"cpu_count": os.cpu_count(), "python": platform.python_version(), "mujoco": mujoco.__version__},
        "robots": {robot: bench_robot(robot, args.seconds) for robot in ("jackal", "turtlebot2")},
    }
    write_result(args.json, result)


if __name__ == "__main__":
    main()
