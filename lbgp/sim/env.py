"""The dm_env environment around a follow-ahead task, and ``make_env``.

Like dm_control's ``control.Environment``, but with the inner loops this task needs: per agent
step (0.2 s) the controller is ticked every ``planner_period`` (the planner re-solves and sets the
wheel speeds), and the person's mocap body is moved every ``person_substeps`` physics steps (10 x 5 ms = 20 Hz by default) along
the exact arc of its command.
"""

from __future__ import annotations

import dm_env
import numpy as np

from lbgp.conventions import DESIRED_DISTANCE, PLANNER_PERIOD
from lbgp.robots import get_robot
from lbgp.sim import tasks


def _divides(period: float, step: float, what: str) -> int:
    n = period / step
    if abs(n - round(n)) > 1e-6 or round(n) < 1:
        raise ValueError(f"{what}: {period} s is not a whole number of {step} s steps")
    return int(round(n))


class FollowAheadEnv(dm_env.Environment):
    def __init__(
        self,
        physics: tasks.Physics,
        task: tasks.FollowAheadTask,
        horizon: int = tasks.DEFAULT_HORIZON,
        planner_period: float = PLANNER_PERIOD,
        person_substeps: int = 10,
    ):
        self.physics = physics
        self.task = task
        self.horizon = int(horizon)
        if self.horizon < 1:
            raise ValueError(f"horizon must be at least 1 agent step, got {horizon}")
        timestep = float(physics.model.opt.timestep)
        self.n_physics = _divides(tasks.CONTROL_PERIOD, timestep, "control period")
        self.n_plan = _divides(tasks.CONTROL_PERIOD, planner_period, "planner period")
        per_plan = self.n_physics // self.n_plan
        if per_plan * self.n_plan != self.n_physics or per_plan % person_substeps:
            raise ValueError(
                f"planner period {planner_period} s must be a whole number of person updates of "
                f"{person_substeps} x {timestep} s"
            )
        self.person_substeps = person_substeps
        self.n_person = per_plan // person_substeps
        self.planner_period = planner_period
        # times (from the start of an agent step) at which the person's pose is updated
        self._person_times = (np.arange(self.n_plan * self.n_person) + 1) * person_substeps * timestep
        self._steps = 0
        self._reset_next_step = True

    # -- dm_env API
    def reset(self) -> dm_env.TimeStep:
        self.physics.reset()
        self.task.initialize_episode(self.physics)
        self.task.begin_person_step()
        self._steps = 0
        self._reset_next_step = False
        return dm_env.restart(self.task.get_observation(self.physics))

    def step(self, action) -> dm_env.TimeStep:
        if self._reset_next_step:
            return self.reset()
        task, physics = self.task, self.physics
        task.before_step(action, physics)
        contact = False
        k = 0
        for _ in range(self.n_plan):
            task.apply_command(physics)
            for _ in range(self.n_person):
                contact = task.advance(physics, self._person_times[k], self.person_substeps) or contact
                k += 1
        task.contact = contact
        task.end_agent_step(physics)
        self._steps += 1
        reward = task.get_reward(physics)
        observation = task.get_observation(physics)
        discount = task.get_termination(physics)
        if discount is not None:
            self._reset_next_step = True
            return dm_env.TimeStep(dm_env.StepType.LAST, reward, discount, observation)
        if self._steps >= self.horizon:
            self._reset_next_step = True
            return dm_env.truncation(reward, observation)
        return dm_env.transition(reward, observation)

    def observation_spec(self):
        return self.task.observation_spec(self.physics)

    def action_spec(self):
        return self.task.action_spec(self.physics)

    def reward_spec(self):
        return dm_env.specs.BoundedArray((), float, -1.0, 1.0, name="reward")

    def reseed(self, seed) -> None:
        """Seed the next episodes (spawn, person motion, observation noise) afresh: evaluation gives
        every episode its own seed, so that all methods face the same episodes whatever their
        earlier episodes consumed."""
        self.task.rng = np.random.default_rng(seed)

    # -- extras for metrics, plots and tests (not for the policy)
    def info(self) -> dict:
        return self.task.info(self.physics)

    def place_robot(self, distance: float, alpha: float, relative_yaw: float = 0.0) -> None:
        self.task.place_robot(self.physics, distance, alpha, relative_yaw)

    @property
    def steps(self) -> int:
        return self._steps


def make_env(
    level: str,
    robot: str = "jackal",
    seed: int | None = None,
    control: str = "goal",
    horizon: int = tasks.DEFAULT_HORIZON,
    obs_noise: bool | None = None,
    person_path=None,
    planner_config=None,
    planner_period: float = PLANNER_PERIOD,
    spawn_front_share: float = 0.5,
    dynamics=None,
    randomize=None,
    calibration=None,
    drive_model=None,
    drawn_paths: bool = False,
) -> FollowAheadEnv:
    """A follow-ahead environment.

    Args:
      level: a curriculum level (straight, circles, smoothed, trajectories) or a paper scenario
        (see ``lbgp.sim.tasks.SCENARIOS``). With ``person_path`` the person walks that path instead
        (an (N, 2) array or a CSV file with header ``x,y``) and ``level`` only names the spawn:
        a scenario's fixed (D, alpha), else 1.5 m straight ahead.
      robot: jackal or turtlebot2.
      seed: seeds every random choice of the episode sequence.
      control: "goal" (policy gives a goal in the person frame; the TEB planner drives) or
        "velocity" (policy gives (v, w) directly, the E2E baseline).
      horizon: agent steps (0.2 s) per episode; 35 by default.
      obs_noise: Gaussian observation noise on/off; default on for levels, off for scenarios.
      spawn_front_share: training levels only: the share of random spawns in front of the person
        (|alpha| < 90 deg); 0.5, the default, spawns uniformly all around (the paper, and evaluation).
      dynamics: the robot base's response (``lbgp.dynamics``): a ``Dynamics``, ``"nominal"`` (the
        default), ``"hardware_like"`` or a JSON file (e.g. from ``lbgp sysid``).
      randomize: domain randomisation per episode around ``dynamics``: a preset name
        (``lbgp.dynamics.RANDOMIZATION``), a JSON file of ranges or a ``Randomization``; off by default.
      calibration: the command calibration (``lbgp.calibration``) applied where commands reach the
        wheels: ``None`` (the identity), a ``CommandCalibration`` or a JSON file (``lbgp sysid``'s output).
      drive_model: the planner's model of the robot's drive (``lbgp.drive_model``): ``None`` (the
        ideal drive it assumes by default), a ``Dynamics``, a named set or ``lbgp sysid``'s JSON.
      drawn_paths: the trajectories level only (training): the person walks a freshly drawn path
        every episode (``lbgp.sim.tasks.drawn_paths_setting``) instead of one of the library's 20.
    """
    setting = tasks.get_setting(level)
    if drawn_paths:
        setting = tasks.drawn_paths_setting(setting)
    if person_path is not None:
        spawn = setting.spawn if setting.spawn is not None else (DESIRED_DISTANCE, 0.0)
        setting = tasks.path_setting(person_path, spawn=spawn)
    spec = get_robot(robot)
    physics = tasks.load_physics(spec)
    task = tasks.FollowAheadTask(
        spec, setting, control_mode=control, obs_noise=obs_noise, planner_config=planner_config,
        random=np.random.default_rng(seed), planner_period=planner_period, spawn_front_share=spawn_front_share,
        dynamics=dynamics, randomize=randomize, calibration=calibration, drive_model=drive_model,
    )
    return FollowAheadEnv(physics, task, horizon=horizon, planner_period=planner_period)


def level_names() -> list[str]:
    return list(tasks.LEVELS)


def scenario_names() -> list[str]:
    return list(tasks.SCENARIOS)


def all_names() -> list[str]:
    return level_names() + scenario_names()


__all__ = ["FollowAheadEnv", "make_env", "level_names", "scenario_names", "all_names"]
