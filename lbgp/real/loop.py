"""The deployment loop: poses in, the same observation, policy and planner as in simulation,
commands out.

    pose source --frames--> SafetyMonitor --WorldState--> ObservationStack -> policy (5 Hz)
                                                      \\-> controller (planner, 10 Hz) --> command sink

Everything between the source and the sink is the simulator's own code: ``lbgp.world.WorldState``,
``lbgp.sim.observation.ObservationStack``, ``lbgp.control`` (GoalController with the TEB planner,
or VelocityController for E2E) and ``lbgp.metrics``. Only where poses come from and where
commands go differ.

Each tick (every ``planner_period``): read the frames that arrived, check them (see
lbgp.real.safety), and then either compute a command from good data or, on any stop reason,
ramp the command to zero within ``SafetyConfig.stop_time``. Every second tick is an agent step
(policy + observation frame + metrics). The robot's velocity for the planner is the last command
sent (a robot without odometry feedback follows its commands); the person's velocity is a finite
difference of its poses over one agent period, exactly as in simulation. Whatever ends the loop
(its step budget, the source ending, Ctrl-C or a signal, an exception) a zero command is sent last;
Ctrl-C and signals end ``run`` normally (``end_reason`` says which), exceptions propagate.
"""

from __future__ import annotations

import collections
import dataclasses
import math
import time

import numpy as np

from lbgp import stack
from lbgp.calibration import CommandCalibration
from lbgp.dynamics import Dynamics
from lbgp.online_calibration import OnlineCalibration
from lbgp.conventions import PLANNER_PERIOD
from lbgp.geometry import distance_and_alpha
from lbgp.metrics import EpisodeMetrics
from lbgp.planner import clamp_command
from lbgp.real import safety as safety_lib
from lbgp.real.safety import SafetyConfig, SafetyMonitor, too_close_distance
from lbgp.sim import observation as obs_lib
from lbgp.sim.rewards import follow_ahead_reward
from lbgp.world import WorldState

SHUTDOWN = "shutdown"


class StopRequested(KeyboardInterrupt):
    """A signal (SIGTERM from systemd, docker stop or kill; SIGHUP from a dropped SSH session) asked
    the deployment to end: the loop ends as it does on Ctrl-C (zero command, closed log, summary)."""

    def __init__(self, signal_name: str):
        super().__init__(signal_name)
        self.signal_name = signal_name


DEPLOY_DEFAULT_BUDGET = 0.002  # s of SQP per planner call in ``lbgp deploy`` (see docs/deploy.md, "Latency")


class WallClock:
    def __init__(self):
        self._t0 = time.monotonic()

    def now(self) -> float:
        return time.monotonic() - self._t0

    def sleep_until(self, t: float) -> None:
        delay = t - self.now()
        if delay > 0:
            time.sleep(delay)


@dataclasses.dataclass
class DeployConfig:
    robot: str = "turtlebot2"
    planner_period: float = PLANNER_PERIOD  # s between commands
    max_steps: int | None = None  # agent steps (0.2 s) before the loop ends; None: until stopped
    max_duration: float | None = None  # s of loop clock before the loop ends (counts stopped time too)
    planner_time_budget: float | None = None  # s: anytime SQP budget per planner call (None: as in simulation)
    end_distance: float | None = None  # end the run when D exceeds this after having been within it (paper: 3 m)
    first_pose_timeout: float | None = None  # s: end the run ("no_pose") if no valid pose arrived by then
    safety: SafetyConfig = dataclasses.field(default_factory=SafetyConfig)
    # applied to every command sent: fixed (lbgp sysid's gains) or estimated while driving (OnlineCalibration)
    calibration: CommandCalibration | OnlineCalibration = dataclasses.field(default_factory=CommandCalibration)
    drive_model: Dynamics | None = None  # the planner's model of the drive (lbgp.drive_model); None: the ideal drive


@dataclasses.dataclass
class TickRecord:
    """What one tick saw and did (kept in memory for tests and summaries, and logged)."""

    t: float
    status: str
    v: float
    w: float
    agent_step: bool = False
    robot: np.ndarray | None = None
    person: np.ndarray | None = None
    observation: np.ndarray | None = None
    goal: np.ndarray | None = None
    band: np.ndarray | None = None
    planner_status: str = ""
    latency_s: float = math.nan  # from reading the newest frame to sending the command
    reward: float = math.nan  # agent steps only
    distance_alpha: tuple = (math.nan, math.nan)  # whenever the tick had good poses
    command_scale: tuple = (1.0, 1.0)  # the calibration's (scale_v, scale_w) applied to this tick's command
    frames: tuple = ()  # every frame accepted this tick (PoseFrame, source time): logged as /mocap/*


class DeployLoop:
    def __init__(self, source, sink, policy, config: DeployConfig | None = None, clock=None, logger=None,
                 recorder=None, end_condition=None, keep_records: bool = True, name: str = "deploy", on_wait=None):
        self.cfg = config or DeployConfig()
        self.source, self.sink, self.policy = source, sink, policy
        self.clock = clock or getattr(source, "clock", None) or WallClock()
        self.logger, self.recorder = logger, recorder
        self.end_condition = end_condition  # optional callable() -> reason or None (e.g. contact in sim)
        self.limits = stack.planner_limits(self.cfg.robot, self.cfg.planner_period, stack.policy_planner(policy, self.cfg.robot),
                                           time_budget=self.cfg.planner_time_budget)
        self.controller = stack.make_controller(policy.control, self.limits, self.cfg.drive_model, self.cfg.calibration)
        self.cfg.calibration.reset()  # an online calibration starts each run afresh
        self.monitor = SafetyMonitor(self.cfg.safety)
        self.min_distance = self.cfg.safety.min_distance or too_close_distance(self.limits)
        self.stack = obs_lib.ObservationStack()
        self.name = name  # the run's name in the metrics and the recording
        self.metrics = EpisodeMetrics(setting=name)
        self.records: list[TickRecord] | None = [] if keep_records else None
        self.command = (0.0, 0.0)
        self.ticks = 0
        self.agent_steps = 0
        self.end_reason = ""
        self._people: collections.deque = collections.deque(maxlen=64)  # (t, person pose) accepted
        self._last_agent_t = -math.inf
        self._last_good = -math.inf
        self._was_within = False
        self._source_minus_loop = None  # source time - loop time at the last valid frame (commands in source time)
        self.on_wait = on_wait  # optional callable(message): told once a second while no valid pose has arrived
        self._next_wait_note = 0.0

    # ------------------------------------------------------------------ one tick
    def _person_motion(self, frame) -> tuple[np.ndarray, float]:
        """Velocity and turn rate by finite difference over about one agent period of source time,
        by the simulator's rule (``obs_lib.estimate_person_motion``)."""
        return obs_lib.estimate_person_motion(self._people, frame.t, frame.person)

    def _stop_command(self) -> tuple[float, float]:
        """Towards zero at the emergency deceleration (limit -> 0 in ``stop_time``)."""
        dt, stop = self.cfg.planner_period, self.cfg.safety.stop_time
        dv = max(self.limits.max_vel_x, self.limits.max_vel_x_backwards) * dt / stop
        dw = self.limits.max_vel_theta * dt / stop
        v, w = self.command
        return (math.copysign(max(abs(v) - dv, 0.0), v), math.copysign(max(abs(w) - dw, 0.0), w))

    def tick(self) -> TickRecord:
        now = self.clock.now()
        frames = self.source.poll(now)
        t_read = time.perf_counter()
        status = self.monitor.update(frames, now)
        frame = self.monitor.last
        record = TickRecord(now, status, 0.0, 0.0, frames=tuple(self.monitor.accepted))
        # first data, or back after a long gap (the source's clock may have restarted): start afresh
        resumed = now - self._last_good > self.cfg.safety.reanchor_after
        if status == safety_lib.OK:
            if resumed:
                self._people.clear()
            if not self._people or self._people[-1][0] < frame.t:
                self._people.append((frame.t, frame.person.copy()))
            record.robot, record.person = frame.robot.copy(), frame.person.copy()
            self._source_minus_loop = frame.t - now
            distance, alpha = record.distance_alpha = distance_and_alpha(frame.robot, frame.person)
            if distance < self.min_distance:
                status = record.status = safety_lib.TOO_CLOSE
        if status == safety_lib.OK:
            state = WorldState(frame.t, frame.robot.copy(), np.array(self.command), frame.person.copy(), *self._person_motion(frame))
            if resumed:
                self.stack.reset(state.robot_pose, state.person_pose)
                self.controller.reset()
                if hasattr(self.policy, "reset"):
                    self.policy.reset()
                self._last_agent_t = -math.inf
            self._last_good = now
            if now - self._last_agent_t >= obs_lib.FRAME_PERIOD - 1e-6:
                self._agent_step(state, record, distance, alpha)
                self._last_agent_t = now
            cmd = self.controller.command(state)
            v, w = clamp_command(cmd.v, cmd.w, self.command[0], self.command[1], self.limits)
            record.planner_status = cmd.status
            record.goal = None if cmd.goal is None else cmd.goal.copy()
            record.band = None if cmd.plan is None else cmd.plan.poses.copy()
        else:
            v, w = self._stop_command()
            if self._source_minus_loop is not None:  # the drive model must know the stop is in flight
                self.controller.sent(now + self._source_minus_loop, v, w)
        self.command = (v, w)  # the planner's limits chain from its own command, before calibration
        if status == safety_lib.OK:
            self.cfg.calibration.observe(frame.t, frame.robot)  # an online calibration learns from the measured motion
        v, w = self.cfg.calibration.apply(v, w)
        record.command_scale = (float(self.cfg.calibration.scale_v), float(self.cfg.calibration.scale_w))
        # the robot side sees why it is being stopped: a safety reason, or the planner's safe stop
        self.sink.send(now, v, w, status if record.planner_status in ("", safety_lib.OK) else record.planner_status)
        record.v, record.w = v, w  # what was sent (logged as /cmd_vel: identifying a calibrated run sees the raw base)
        if frames:
            record.latency_s = time.perf_counter() - t_read
        self.ticks += 1
        if self.logger is not None:
            self.logger.log_tick(record)
        if self.recorder is not None and record.agent_step:
            distance, alpha = record.distance_alpha
            self.recorder.log_step({"time": record.t, "distance": distance, "alpha": alpha, "robot_pose": record.robot,
                                    "person_pose": record.person, "goal": record.goal, "band": record.band}, record.reward)
        if self.records is not None:
            self.records.append(record)
        return record

    def _agent_step(self, state: WorldState, record: TickRecord, distance: float, alpha: float) -> None:
        self.stack.push(state.robot_pose, state.person_pose)
        observation = self.stack.vector()
        self.controller.set_action(self.policy.act(observation), state)
        reward = follow_ahead_reward(distance, alpha)
        goal = getattr(self.controller, "goal_person", None)  # None: the policy commands (v, w) itself
        self.metrics.add(distance, alpha, reward, state.robot_pose[2], state.person_pose[2], goal is None or goal[0] > 0.0)
        self.agent_steps += 1
        record.agent_step = True
        record.observation = observation
        record.reward = reward

    # ------------------------------------------------------------------ the loop
    def _waiting(self, record: TickRecord) -> str:
        """While no valid pose has arrived: a note every second, and the first-pose timeout."""
        if self._last_good > -math.inf:
            return ""
        waited = record.t - self._start_t
        if self.on_wait is not None and waited >= self._next_wait_note:
            self._next_wait_note = math.floor(waited) + 1.0
            counts = ", ".join(f"{k} {v}" for k, v in self.monitor.counts.items() if v)
            malformed = getattr(self.source, "malformed", 0) + getattr(self.source, "rejected_senders", 0)
            self.on_wait(f"waiting for the first valid pose ({waited:.0f} s, status {record.status}"
                         + (f", rejected frames: {counts}" if counts else "")
                         + (f", dropped datagrams: {malformed}" if malformed else "") + "); the robot is held stopped")
        timeout = self.cfg.first_pose_timeout
        if timeout is not None and waited >= timeout - 1e-9:
            return "no_pose"
        return ""

    def _finished(self, record: TickRecord) -> str:
        cfg = self.cfg
        waiting = self._waiting(record)
        if waiting:
            return waiting
        if cfg.max_steps is not None and self.agent_steps >= cfg.max_steps:
            return "steps"
        if cfg.max_duration is not None and record.t - self._start_t >= cfg.max_duration - 1e-9:
            return "duration"
        if getattr(self.source, "finished", False):
            return "source_ended"
        if cfg.end_distance is not None and record.robot is not None:
            # the rule applies once the robot has been within the distance (a run may start farther)
            distance = record.distance_alpha[0]
            self._was_within = self._was_within or distance <= cfg.end_distance
            if self._was_within and distance > cfg.end_distance:
                return "too_far"
        if self.end_condition is not None:
            return self.end_condition() or ""
        return ""

    def run(self) -> EpisodeMetrics:
        """Tick until the budget, the source or an end condition ends the run; always sends zero last."""
        period = self.cfg.planner_period
        next_tick = self._start_t = self.clock.now()
        if self.recorder is not None:
            self.recorder.begin_episode(self.name)
        try:
            while True:
                self.clock.sleep_until(next_tick)
                record = self.tick()
                self.end_reason = self._finished(record)
                if self.end_reason:
                    break
                next_tick += period
                if self.clock.now() > next_tick + period:  # fell behind (slow machine): do not burst
                    next_tick = self.clock.now()
        except KeyboardInterrupt as exc:  # Ctrl-C, or a signal turned into StopRequested: a normal end
            self.end_reason = f"signal {exc.signal_name}" if isinstance(exc, StopRequested) else "interrupted"
        except BaseException:
            self.end_reason = "error"
            raise
        finally:
            self.command = (0.0, 0.0)
            try:
                self.sink.send(self.clock.now(), 0.0, 0.0, SHUTDOWN)
            finally:
                if self.logger is not None:
                    self.logger.log_tick(TickRecord(self.clock.now(), SHUTDOWN, 0.0, 0.0))
                    self.logger.close()
        self.metrics.contact = self.end_reason == "contact"
        self.metrics.terminated_early = self.end_reason not in ("steps", "duration", "source_ended", "", "no_pose")
        return self.metrics
