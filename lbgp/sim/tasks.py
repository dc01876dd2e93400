"""Follow-ahead tasks in the dm_control style. Read top to bottom: physics, task (levels and
scenarios), observations, reward.

A robot (Jackal or TurtleBot 2) tries to stay 1.5 m straight in front of a walking person. The
person is a mocap body moved along its motion model; the robot is driven through its wheel
actuators by a controller (goal -> planner -> (v, w), or (v, w) directly).
"""

from __future__ import annotations

import collections
import dataclasses
import math
from typing import Callable

import numpy as np
from dm_control import mujoco as dm_mujoco
from dm_control.rl import control
from dm_env import specs

from lbgp import stack
from lbgp.calibration import load_calibration
from lbgp.drive_model import load_drive_model
from lbgp.control import Command
from lbgp.conventions import AGENT_PERIOD, DESIRED_DISTANCE, PLANNER_PERIOD
from lbgp.geometry import distance_and_alpha, integrate_unicycle, pose_from_polar, yaw_from_quaternion
from lbgp.dynamics import Dynamics, Randomization, load_dynamics, load_randomization
from lbgp.sim import observation as obs_lib
from lbgp.drive_train import DriveTrain
from lbgp.sim.drive import ModelDynamics
from lbgp.sim import paths as path_lib
from lbgp.sim.person import CircleMotion, DrawnPathMotion, PathMotion, PersonMotion, SmoothedMotion, StraightMotion
from lbgp.sim.rewards import follow_ahead_reward, out_of_range
from lbgp.robots import DiffDrive, RobotSpec
from lbgp.sim.robots import actuator_indices
from lbgp.world import WorldState

CONTROL_PERIOD = AGENT_PERIOD  # s, one agent step = one observation frame
DEFAULT_HORIZON = 35  # agent steps (the authors' configuration; the paper does not state it)
SPAWN_DISTANCE = (1.0, 2.5)  # m: training levels start the robot this far from the person (paper)


# ============================================================================ physics
class Physics(dm_mujoco.Physics):
    """MuJoCo physics of one scene (robot + person + floor) with planar accessors."""

    def setup_robot(self, spec: RobotSpec) -> None:
        import mujoco

        model = self.model.ptr
        self.spec = spec
        self.left, self.right = actuator_indices(model, spec)
        self.robot_body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "robot")
        joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "robot_root")
        person = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "person")
        if min(self.robot_body, joint, person) < 0:
            raise ValueError(f"scene {spec.scene_path} lacks the body 'robot', joint 'robot_root' or body 'person'")
        self.qpos_adr = int(model.jnt_qposadr[joint])
        self.qvel_adr = int(model.jnt_dofadr[joint])
        self.mocap_id = int(model.body_mocapid[person])
        robot_geoms = model.body_rootid[model.geom_bodyid] == self.robot_body
        person_geoms = (model.geom_bodyid == person) & (model.geom_contype != 0)
        # contact_pair[g1, g2]: a contact between these two geoms is a robot-person contact
        self.contact_pair = np.outer(robot_geoms, person_geoms) | np.outer(person_geoms, robot_geoms)
        self.drive = spec.drive
        self._raw_model, self._raw_data = model, self.data.ptr
        self._pose_cache, self._pose_time = None, None
        # how far (horizontally) any robot / person collision geom reaches from its body's centre;
        # beyond the sum of both no contact is possible, and the contact scan is skipped
        data = self._raw_data
        mujoco.mj_forward(model, data)

        def reach(body, geoms):
            ids = np.flatnonzero(geoms)
            offsets = np.linalg.norm(data.geom_xpos[ids, :2] - data.xpos[body, :2], axis=1)
            return float(np.max(offsets + model.geom_rbound[ids]))

        self.contact_range = reach(self.robot_body, robot_geoms) + reach(person, person_geoms) + 0.05
        self.model_dynamics = ModelDynamics(model, self.robot_body, self.left, self.right)
        self.dynamics = Dynamics()
        self.drivetrain: DriveTrain | None = None  # None: ideal drive, commands reach the servos at once
        self._timestep = float(model.opt.timestep)

    def set_dynamics(self, dynamics: Dynamics, rng: np.random.Generator | None = None) -> None:
        """Apply a robot ``Dynamics`` (model parameters, firmware latency / limiter / lag); also
        resets the drive train's state (call at an episode's start)."""
        dynamics = dynamics.validate()
        self.model_dynamics.apply(dynamics, self._raw_data)
        self.dynamics = dynamics
        self.drive = DiffDrive(self.spec.wheel_radius, self.spec.effective_track * dynamics.track_scale)
        self.drivetrain = None if dynamics.is_ideal_drive else DriveTrain(dynamics, rng)
        self.restart_drive(rng)

    def restart_drive(self, rng: np.random.Generator | None = None) -> None:
        """Empty the drive train's command queue and state at an episode's start (the model keeps
        its dynamics); ``rng`` draws the latency jitter from now on."""
        if self.drivetrain is not None:
            if rng is not None:
                self.drivetrain.rng = rng
            self.drivetrain.reset(float(self._raw_data.time))

    # -- robot
    def robot_pose(self) -> np.ndarray:
        data = self._raw_data
        if self._pose_time == data.time and self._pose_cache is not None:
            return self._pose_cache.copy()  # already computed for this physics state
        q = data.qpos[self.qpos_adr : self.qpos_adr + 7]
        yaw = yaw_from_quaternion(q[4], q[5], q[6], q[3])  # MuJoCo stores (w, x, y, z)
        self._pose_cache, self._pose_time = np.array([q[0], q[1], yaw]), data.time
        return self._pose_cache.copy()

    def robot_velocity(self) -> np.ndarray:
        """(v, w): forward speed in the robot frame and yaw rate."""
        qv = self._raw_data.qvel[self.qvel_adr : self.qvel_adr + 6]
        yaw = self.robot_pose()[2]
        return np.array([qv[0] * math.cos(yaw) + qv[1] * math.sin(yaw), qv[5]])

    def set_robot_pose(self, pose) -> None:
        x, y, yaw = (float(p) for p in pose)
        self._pose_cache = None
        adr = self.qpos_adr
        z = self.model.body_pos[self.robot_body][2]
        self.data.qpos[adr : adr + 7] = [x, y, z, math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]
        self.data.qvel[self.qvel_adr : self.qvel_adr + 6] = 0.0
        self.forward()

    def drive_wheels(self, v: float, w: float) -> None:
        """Send a (v, w) command to the base: straight to the servos with an ideal drive, else
        through the drive train (latency, acceleration limiter, lag)."""
        if self.drivetrain is not None:
            self.drivetrain.command(float(self._raw_data.time), v, w)
            return
        self._set_wheels(v, w)

    def _set_wheels(self, v: float, w: float) -> None:
        left, right = self.drive.wheel_speeds(v, w)
        ctrl = self._raw_data.ctrl
        ctrl[self.left] = left
        ctrl[self.right] = right

    # -- person
    def set_person_pose(self, pose) -> None:
        x, y, yaw = pose[0], pose[1], pose[2]
        data = self._raw_data
        data.mocap_pos[self.mocap_id] = (x, y, 0.0)
        data.mocap_quat[self.mocap_id] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))

    def step_physics(self, nstep: int) -> None:
        """``nstep`` raw MuJoCo steps (dm_control's ``step`` adds per-call work we do not need)."""
        import mujoco

        if self.drivetrain is None:
            mujoco.mj_step(self._raw_model, self._raw_data, nstep)
            return
        for _ in range(nstep):
            self._set_wheels(*self.drivetrain.advance(self._timestep))
            mujoco.mj_step(self._raw_model, self._raw_data, 1)

    def robot_person_contact(self) -> bool:
        data = self._raw_data
        if data.ncon == 0:
            return False
        robot = self.robot_pose()
        person = data.mocap_pos[self.mocap_id]
        if math.hypot(robot[0] - person[0], robot[1] - person[1]) > self.contact_range:
            return False
        geoms = data.contact.geom
        return bool(self.contact_pair[geoms[:, 0], geoms[:, 1]].any())


def load_physics(spec: RobotSpec) -> Physics:
    """Compile the robot's scene; a malformed MJCF raises a ValueError naming the file."""
    try:
        physics = Physics.from_xml_path(str(spec.scene_path))
    except Exception as exc:  # dm_control raises several error types for bad XML
        raise ValueError(f"cannot load MJCF scene {spec.scene_path}: {exc}") from exc
    physics.setup_robot(spec)
    return physics


# ============================================================================ task: levels and scenarios
@dataclasses.dataclass(frozen=True)
class Setting:
    """How an episode starts and how the person walks.

    ``spawn`` is None for the training levels (robot 1-2.5 m away in a uniformly random direction,
    with a uniformly random heading) or (D, alpha_deg) for the paper's fixed initial settings
    (robot heading = person heading). ``noise`` is the default for observation noise.
    """

    name: str
    motion: Callable[[], PersonMotion]
    spawn: tuple[float, float] | None = None
    noise: bool = True
    random_person_heading: bool = True


LIBRARY_START_FRACTION = 0.3  # a trajectories-level episode starts in the first 30 % of its path


def _library_motion() -> PersonMotion:
    return PathMotion(path_lib.training_library(), speed=None, start_fraction=LIBRARY_START_FRACTION)


def _eval_path_motion(name: str) -> Callable[[], PersonMotion]:
    return lambda: PathMotion(path_lib.evaluation_path(name), speed=0.5)


LEVELS: dict[str, Setting] = {
    "straight": Setting("straight", lambda: StraightMotion()),
    "circles": Setting("circles", lambda: CircleMotion()),
    "smoothed": Setting("smoothed", lambda: SmoothedMotion()),
    "trajectories": Setting("trajectories", _library_motion),
}
CURRICULUM = tuple(LEVELS)

# The paper's evaluation settings. alpha = 0 is "robot straight in front" everywhere (as in the
# reward); the paper's turning text swaps the ahead/behind angles, we do not. Inside the turn is
# on the person's left for a left (w > 0) turn, hence +45 deg.
_eval = dict(noise=False, random_person_heading=False)
_D = DESIRED_DISTANCE  # the paper's settings start the robot at the desired distance
SCENARIOS: dict[str, Setting] = {
    "straight_ahead": Setting("straight_ahead", lambda: StraightMotion(0.6), (_D, 0.0), **_eval),
    "straight_behind": Setting("straight_behind", lambda: StraightMotion(0.6), (_D, 180.0), **_eval),
    "turning_ahead": Setting("turning_ahead", lambda: CircleMotion(0.3, 0.3), (_D, 0.0), **_eval),
    "turning_behind": Setting("turning_behind", lambda: CircleMotion(0.3, 0.3), (_D, 180.0), **_eval),
    "turning_inside": Setting("turning_inside", lambda: CircleMotion(0.3, 0.3), (_D, 45.0), **_eval),
    "turning_outside": Setting("turning_outside", lambda: CircleMotion(0.3, 0.3), (_D, -45.0), **_eval),
    "trajectory_one": Setting("trajectory_one", _eval_path_motion("one"), (_D, 0.0), **_eval),
    "trajectory_two": Setting("trajectory_two", _eval_path_motion("two"), (_D, 0.0), **_eval),
    "trajectory_three": Setting("trajectory_three", _eval_path_motion("three"), (_D, 0.0), **_eval),
}

# Settings for tools, not for training or the paper's tables: `lbgp sysid --excite` records with the
# person standing 6 m ahead of the robot (out of its way).
TOOL_SETTINGS: dict[str, Setting] = {
    "standing_person": Setting("standing_person", lambda: StraightMotion(0.0), (6.0, 180.0), **_eval),
}

ALL_SETTINGS = {**LEVELS, **SCENARIOS, **TOOL_SETTINGS}


def get_setting(name: str) -> Setting:
    try:
        return ALL_SETTINGS[name]
    except KeyError:
        raise ValueError(
            f"unknown level or scenario {name!r}; levels: {', '.join(LEVELS)}; scenarios: {', '.join(SCENARIOS)}"
        ) from None


DRAWN_PATHS_LEVEL = "trajectories"


def drawn_paths_setting(setting: Setting) -> Setting:
    """The trajectories level with a freshly drawn path every episode (``DrawnPathMotion``: same
    length, start share and speeds as the library's) instead of one of the library's 20."""
    if setting.name != DRAWN_PATHS_LEVEL:
        raise ValueError(f"drawn paths replace the {DRAWN_PATHS_LEVEL} level's library; {setting.name!r} walks no library")
    return dataclasses.replace(setting, motion=lambda: DrawnPathMotion(path_lib.TRAIN_LENGTH,
                                                                    start_fraction=LIBRARY_START_FRACTION))


def path_setting(path, spawn=(DESIRED_DISTANCE, 0.0), speed: float = 0.5) -> Setting:
    """A scenario whose person walks a user-given path (array or CSV file of x,y waypoints)."""
    points = path if isinstance(path, np.ndarray) else path_lib.load_path_csv(path)
    points = path_lib.validate_path(points)
    return Setting("custom_path", lambda: PathMotion(points, speed=speed), spawn, noise=False, random_person_heading=False)


# ============================================================================ task
class FollowAheadTask(control.Task):
    """Stay 1.5 m in front of the person. One instance per (robot, setting, control mode)."""

    def __init__(
        self,
        spec: RobotSpec,
        setting: Setting,
        control_mode: str = "goal",
        obs_noise: bool | None = None,
        noise_std=obs_lib.DEFAULT_NOISE_STD,
        planner_config=None,
        random: np.random.Generator | int | None = None,
        planner_period: float = PLANNER_PERIOD,
        spawn_front_share: float = 0.5,
        dynamics: Dynamics | str | None = None,
        randomize: Randomization | str | dict | None = None,
        calibration=None,
        drive_model=None,
    ):
        self.spec = spec
        # what leaves the controller is scaled to what this robot must be told (lbgp.calibration)
        self.calibration = load_calibration(calibration, spec.name)
        # the robot base's response (lbgp.dynamics): fixed, or drawn per episode around it
        self.dynamics = load_dynamics(dynamics or "nominal", spec.name)
        if isinstance(randomize, dict):
            randomize = Randomization.from_dict(randomize)
        self.randomization = None if randomize in (None, "none") else load_randomization(randomize)
        self.episode_dynamics = self.dynamics
        if not 0.0 <= spawn_front_share <= 1.0:
            raise ValueError(f"spawn_front_share must be in [0, 1], got {spawn_front_share}")
        self.spawn_front_share = float(spawn_front_share)  # training levels: share of spawns with |alpha| < 90 deg
        self.setting = setting
        self.motion = setting.motion()
        self.limits = stack.planner_limits(spec, planner_period, planner_config)
        # the planner's model of the drive (lbgp.drive_model): None, it assumes the ideal drive
        self.drive_model = load_drive_model(drive_model, spec.name)
        self.controller = stack.make_controller(control_mode, self.limits, self.drive_model, self.calibration)
        self.control_mode = control_mode
        noise_on = setting.noise if obs_noise is None else obs_noise
        self.stack = obs_lib.ObservationStack(noise_std=noise_std if noise_on else None)
        self._noise_std = noise_std if noise_on else None
        self.rng = random if isinstance(random, np.random.Generator) else np.random.default_rng(random)
        self.person_pose = np.zeros(3)
        self.person_cmd = (0.0, 0.0)
        self._person_track: collections.deque = collections.deque(maxlen=16)  # (t, person pose) as moved
        self.time = 0.0
        self.contact = False
        self.last_command = Command(0.0, 0.0)

    # -- episode start
    def initialize_episode(self, physics: Physics) -> None:
        yaw = float(self.rng.uniform(-math.pi, math.pi)) if self.setting.random_person_heading else 0.0
        self.person_pose = self.motion.reset(self.rng, np.array([0.0, 0.0, yaw]))
        self._person_track.clear()
        self._person_track.append((0.0, self.person_pose.copy()))
        if self.setting.spawn is None:
            distance = float(self.rng.uniform(*SPAWN_DISTANCE))
            alpha = float(self.rng.uniform(-math.pi / 2, math.pi / 2))  # in front of the person ...
            if self.rng.uniform() >= self.spawn_front_share:
                alpha = math.remainder(alpha + math.pi, 2 * math.pi)  # ... or behind
            robot = pose_from_polar(self.person_pose, distance, alpha)
            robot[2] = float(self.rng.uniform(-math.pi, math.pi))
        else:
            distance, alpha_deg = self.setting.spawn
            robot = pose_from_polar(self.person_pose, distance, math.radians(alpha_deg))
        self._apply_dynamics(physics)
        physics.set_person_pose(self.person_pose)
        physics.set_robot_pose(robot)
        physics.drive_wheels(0.0, 0.0)
        self.time = 0.0
        self.contact = False
        self.controller.reset()
        self.calibration.reset()
        self.last_command = Command(0.0, 0.0)
        self.stack.reset(physics.robot_pose(), self.person_pose)
        self.person_cmd = self.motion.command(self.person_pose, CONTROL_PERIOD)

    def _apply_dynamics(self, physics: Physics) -> None:
        """This episode's robot dynamics: the fixed set, or a draw from the randomisation ranges
        (and with it the observation noise's scale)."""
        noise_scale = 1.0
        if self.randomization is not None:
            accel = (self.limits.acc_lim_x, self.limits.acc_lim_theta)
            self.episode_dynamics, noise_scale = self.randomization.sample(
                self.dynamics, self.rng, accel, physics.model_dynamics.nominal_sliding_friction)
        if self.episode_dynamics is not physics.dynamics:
            physics.set_dynamics(self.episode_dynamics, self.rng)
        else:
            physics.restart_drive(self.rng)
        if self._noise_std is not None:
            self.stack.noise_std = tuple(noise_scale * s for s in self._noise_std)

    def place_robot(self, physics: Physics, distance: float, alpha: float, relative_yaw: float = 0.0) -> None:
        """Teleport the robot to (D, alpha) from the person (alpha in radians); for tests and tools."""
        physics.set_robot_pose(pose_from_polar(self.person_pose, distance, alpha, relative_yaw))

    # -- world state (what the observation and the controller see)
    def person_motion(self) -> tuple[np.ndarray, float]:
        """The person's velocity and turn rate over one agent period, by the deploy loop's rule
        (``obs_lib.estimate_person_motion``). Planner calls fall at the start and in the middle of
        an agent step; both see a 0.2 s window."""
        t_now, now = self._person_track[-1]
        return obs_lib.estimate_person_motion(self._person_track, t_now, now, CONTROL_PERIOD)

    def world_state(self, physics: Physics) -> WorldState:
        person_velocity, turn_rate = self.person_motion()
        # the robot's velocity is the last command, as on the real robot (lbgp.real.loop): the
        # planner's acceleration limits chain from command to command, not from the measured
        # velocity (a skid-steer base overshoots its yaw rate at speed; chaining from that
        # measurement forced ever harder turns)
        commanded = np.array([self.last_command.v, self.last_command.w])
        # the physics clock (restarted each episode): the planner ticks twice per agent step
        return WorldState(float(physics.data.time), physics.robot_pose(), commanded, self.person_pose.copy(), person_velocity, turn_rate)

    # -- stepping (called by lbgp.sim.env.FollowAheadEnv)
    def before_step(self, action, physics: Physics) -> None:
        self.contact = False
        self.controller.set_action(action, self.world_state(physics))

    def apply_command(self, physics: Physics) -> Command:
        """One controller tick: (v, w) from the controller, to wheel speeds."""
        self.last_command = self.controller.command(self.world_state(physics))
        self.calibration.observe(float(physics.data.time), physics.robot_pose())  # an online calibration learns from it
        physics.drive_wheels(*self.calibration.apply(self.last_command.v, self.last_command.w))
        return self.last_command

    def person_pose_at(self, dt) -> np.ndarray:
        """The person's pose(s) ``dt`` seconds into the current step (exact arc of its command)."""
        return integrate_unicycle(self._step_start_pose, self.person_cmd[0], self.person_cmd[1], dt)

    def begin_person_step(self) -> None:
        self._step_start_pose = self.person_pose.copy()

    def move_person(self, physics: Physics, pose) -> None:
        self.person_pose = np.asarray(pose, dtype=float)
        physics.set_person_pose(self.person_pose)

    def advance(self, physics: Physics, phase: float, substeps: int) -> bool:
        """The one stepping sequence of the simulator (used by ``FollowAheadEnv`` and by the
        simulated deploy world alike): the person to where its motion puts it ``phase`` seconds
        into the current agent step, then ``substeps`` physics steps; returns whether robot and
        person touched."""
        self.move_person(physics, self.person_pose_at(phase))
        self._person_track.append((self.time + phase, self.person_pose.copy()))
        physics.step_physics(substeps)
        return physics.robot_person_contact()

    def end_agent_step(self, physics: Physics) -> None:
        """Close an agent step (observation frame, the person's next command) and open the next."""
        self.after_step(physics)
        self.begin_person_step()

    def after_step(self, physics: Physics) -> None:
        self.time += CONTROL_PERIOD
        self.stack.push(physics.robot_pose(), self.person_pose)
        self.person_cmd = self.motion.command(self.person_pose, CONTROL_PERIOD)

    # ======================================================================== observations
    def observation_spec(self, physics=None):
        return specs.BoundedArray((self.stack.size,), np.float32, -1.0, 1.0, name="observation")

    def get_observation(self, physics: Physics) -> np.ndarray:
        return self.stack.vector(self.rng)

    def action_spec(self, physics=None):
        return specs.BoundedArray((2,), np.float32, -1.0, 1.0, name=f"{self.control_mode}_action")

    # ======================================================================== reward and termination
    def distance_alpha(self, physics: Physics) -> tuple[float, float]:
        return distance_and_alpha(physics.robot_pose(), self.person_pose)

    def get_reward(self, physics: Physics) -> float:
        return follow_ahead_reward(*self.distance_alpha(physics))

    def get_termination(self, physics: Physics):
        """0.0 (terminal) when D < 0.5 m, D > 5 m or the robot touches the person, else None."""
        distance, _ = self.distance_alpha(physics)
        if out_of_range(distance) or self.contact:
            return 0.0
        return None

    def info(self, physics: Physics) -> dict:
        """Everything that is not for the policy: metrics and raw poses for logging and plots."""
        distance, alpha = self.distance_alpha(physics)
        cmd = self.last_command
        return {
            "time": self.time,
            "distance": distance,
            "alpha": alpha,
            "robot_pose": physics.robot_pose(),
            "robot_velocity": physics.robot_velocity(),
            "person_pose": self.person_pose.copy(),
            "command": np.array([cmd.v, cmd.w]),
            "planner_status": cmd.status,
            "goal": None if cmd.goal is None else cmd.goal.copy(),
            "band": None if cmd.plan is None else cmd.plan.poses.copy(),
            "person_prediction": None if cmd.plan is None else cmd.plan.person_prediction.copy(),
            "contact": self.contact,
            "setting": self.setting.name,
        }

