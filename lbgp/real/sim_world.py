"""The simulated robot for the deployment loop: the MuJoCo world as a pose source and command sink.

``SimWorld`` is the same physics and person motion as ``lbgp.sim`` (it drives a
``FollowAheadTask`` without its controller): the deployment loop's commands go to the wheels,
and the robot's and person's poses come back as motion-capture frames every 20 ms, optionally
with mocap-like disturbances (``MocapDisturbance``: pose noise, latency, dropped frames).

Two ways to run it:

* lock-step (``SimClock``): the loop's clock *is* the simulation time, so an episode runs as fast
  as the CPU allows and is reproducible (``lbgp deploy --source sim --sink sim``, the experiments);
* real time over UDP (``SimRobotServer``): a thread steps the world at wall-clock pace, sends pose
  datagrams and listens for command datagrams, like a robot and a mocap system on the network
  (the hardware-in-the-loop tests).
"""

from __future__ import annotations

import dataclasses
import math
import threading
import time

import numpy as np

from lbgp.conventions import DESIRED_DISTANCE
from lbgp.real.frames import PoseFrame, encode_frame
from lbgp.real.udp import UdpCommandListener, sending_socket
from lbgp.sim import tasks
from lbgp.robots import get_robot

FRAME_PERIOD = 0.02  # s between mocap frames (50 Hz)


@dataclasses.dataclass
class MocapDisturbance:
    """What a motion-capture system adds to the true poses."""

    position_std: float = 0.003  # m
    yaw_std: float = math.radians(0.5)  # rad
    latency: tuple[float, float] = (0.010, 0.030)  # s, drawn once per episode
    jitter: float = 0.002  # s, per frame
    drop_probability: float = 0.02  # per frame


class SimWorld:
    """Robot + walking person in MuJoCo, advanced in steps of ``FRAME_PERIOD``."""

    def __init__(self, setting="straight_ahead", robot: str = "turtlebot2", seed: int = 0, person_path=None, spawn=None,
                 dynamics=None):
        spec = get_robot(robot)
        if person_path is not None:
            setting = tasks.path_setting(person_path, spawn=spawn or (DESIRED_DISTANCE, 0.0))
        elif isinstance(setting, str):
            setting = tasks.get_setting(setting)
        self.spec = spec
        self.physics = tasks.load_physics(spec)
        self.task = tasks.FollowAheadTask(spec, setting, control_mode="velocity", obs_noise=False, random=np.random.default_rng(seed),
                                          dynamics=dynamics)
        self.substeps = int(round(FRAME_PERIOD / float(self.physics.model.opt.timestep)))
        self.listeners: list = []
        self.reset()

    def reset(self) -> None:
        self.physics.reset()
        self.task.initialize_episode(self.physics)
        self.task.begin_person_step()
        self.time = 0.0
        self._phase = 0.0
        self.contact = False
        self.command = (0.0, 0.0)
        for listener in self.listeners:
            listener(self)

    # -- the robot's side
    def set_command(self, v: float, w: float) -> None:
        self.command = (float(v), float(w))
        self.physics.drive_wheels(*self.command)

    def step(self) -> None:
        """Advance one mocap frame period: person along its motion, robot by physics."""
        task, physics = self.task, self.physics
        self._phase += FRAME_PERIOD
        self.contact = task.advance(physics, self._phase, self.substeps) or self.contact
        self.time = round(self.time + FRAME_PERIOD, 9)
        if self._phase >= tasks.CONTROL_PERIOD - 1e-9:  # the person's motion model runs at 5 Hz
            task.end_agent_step(physics)
            self._phase = 0.0
        for listener in self.listeners:
            listener(self)

    def advance_to(self, t: float) -> None:
        while self.time + 1e-9 < t:
            self.step()

    def poses(self) -> tuple[np.ndarray, np.ndarray]:
        return self.physics.robot_pose().copy(), self.task.person_pose.copy()

    def distance_alpha(self) -> tuple[float, float]:
        return self.task.distance_alpha(self.physics)


class SimClock:
    """The loop clock in lock-step with a SimWorld: sleeping advances the simulation."""

    def __init__(self, world: SimWorld):
        self.world = world

    def now(self) -> float:
        return self.world.time

    def sleep_until(self, t: float) -> None:
        self.world.advance_to(t)


class SimPoseSource:
    """Mocap frames of a SimWorld (with disturbances), delivered after their latency."""

    def __init__(self, world: SimWorld, disturbance: MocapDisturbance | None = None, seed: int = 0):
        self.world = world
        self.disturbance = disturbance
        self.rng = np.random.default_rng(seed)
        self.pending: list[tuple[float, PoseFrame]] = []
        self.clock = SimClock(world)
        self._latency = 0.0
        self._last_delivery = -math.inf
        self.dropped = 0
        world.listeners.append(self._on_step)
        self._draw_latency()
        self._on_step(world)

    def _draw_latency(self) -> None:
        d = self.disturbance
        self._latency = float(self.rng.uniform(*d.latency)) if d else 0.0

    def _on_step(self, world: SimWorld) -> None:
        if world.time == 0.0:
            self.pending.clear()
            self._last_delivery = -math.inf
        robot, person = world.poses()
        d = self.disturbance
        delivery = world.time
        if d is not None:
            if self.rng.uniform() < d.drop_probability:
                self.dropped += 1
                return
            noise = self.rng.normal(size=(2, 3)) * np.array([d.position_std, d.position_std, d.yaw_std])
            robot, person = robot + noise[0], person + noise[1]
            delivery = max(world.time + self._latency + abs(self.rng.normal()) * d.jitter, self._last_delivery)
        self._last_delivery = delivery
        self.pending.append((delivery, PoseFrame(world.time, robot, person)))

    def poll(self, now: float, timeout: float = 0.0) -> list[PoseFrame]:
        out = []
        while self.pending and self.pending[0][0] <= now + 1e-9:
            _, frame = self.pending.pop(0)
            frame.received = now
            out.append(frame)
        return out

    def close(self) -> None:
        if self._on_step in self.world.listeners:
            self.world.listeners.remove(self._on_step)


class SimCommandSink:
    """Commands straight to the simulated robot's wheels."""

    def __init__(self, world: SimWorld):
        self.world = world

    def send(self, t: float, v: float, w: float, status: str = "ok") -> None:
        self.world.set_command(v, w)

    def close(self) -> None:
        pass


class SimRobotServer:
    """A SimWorld stepped in real time in a thread: pose frames out over UDP to ``pose_to``, commands
    in on a listener bound to ``command_bind`` that accepts only ``allowed_senders``.
    ``faults(frame_index, frame) -> list[(delay_s, bytes)]`` may replace what is sent (for tests)."""

    def __init__(self, world: SimWorld, pose_to: tuple[str, int], command_bind=("127.0.0.1", 0),
                 allowed_senders=("127.0.0.1",), max_duration: float = 60.0, faults=None):
        self.world = world
        self.pose_to = tuple(pose_to)
        self.commands = UdpCommandListener(command_bind, allowed_senders)
        self.sock = sending_socket(self.pose_to)
        self.max_duration = max_duration
        self.faults = faults
        self.received: list[tuple[float, float, float, str]] = []  # (sim time, v, w, status)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="lbgp-sim-robot", daemon=True)

    @property
    def command_address(self) -> tuple[str, int]:
        return self.commands.address

    def start(self) -> "SimRobotServer":
        self._thread.start()
        return self

    def _run(self) -> None:
        start = time.monotonic()
        delayed: list[tuple[float, bytes]] = []
        index = 0
        while not self._stop.is_set() and time.monotonic() - start < self.max_duration:
            for _, v, w, status in self.commands.poll(timeout=0.0):
                self.received.append((self.world.time, v, w, status))
                self.world.set_command(v, w)
            self.world.step()
            robot, person = self.world.poses()
            frame = PoseFrame(time.monotonic() - start, robot, person)
            out = self.faults(index, frame) if self.faults else [(0.0, encode_frame(frame))]
            index += 1
            now = time.monotonic()
            delayed += [(now + delay, data) for delay, data in out]
            delayed.sort(key=lambda item: item[0])
            while delayed and delayed[0][0] <= now:
                try:
                    self.sock.send(delayed.pop(0)[1])
                except ConnectionRefusedError:  # the loop is not listening (yet, or any more)
                    pass
            next_frame = start + index * FRAME_PERIOD
            time.sleep(max(0.0, next_frame - time.monotonic()))

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5.0)
        self.commands.close()
        self.sock.close()
