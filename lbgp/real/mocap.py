"""Motion-capture pose source through the ``motioncapture`` library (Vicon, OptiTrack, Qualisys,
VRPN, ...): ``pip install -e '.[mocap]'``. Two rigid bodies, the robot and the person, are read
from every frame; a background thread waits for frames so the loop never blocks on the network.
Yaw is the rotation about the vertical (z) axis of the mocap frame; set the system up with z up.
"""

from __future__ import annotations

import queue
import threading
import time

import numpy as np

from lbgp.geometry import yaw_from_quaternion
from lbgp.real.frames import PoseFrame

SYSTEMS = ("vicon", "optitrack", "optitrack_closed_source", "qualisys", "nokov", "vrpn", "motionanalysis")


class MocapPoseSource:
    def __init__(self, system: str, host: str, robot_body: str = "robot", person_body: str = "person", clock=None):
        try:
            import motioncapture
        except ImportError:
            raise ImportError(f"the {system}:// pose source needs the motioncapture package: pip install -e '.[mocap]'") from None
        if system not in SYSTEMS:
            raise ValueError(f"unknown motion capture system {system!r}; use one of {', '.join(SYSTEMS)}")
        self.mc = motioncapture.connect(system, {"hostname": host})
        self.bodies = (robot_body, person_body)
        self.clock = clock
        self.queue: queue.Queue = queue.Queue(maxsize=256)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="lbgp-mocap", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        t0 = time.monotonic()
        while not self._stop.is_set():
            self.mc.waitForNextFrame()
            bodies = self.mc.rigidBodies
            poses = []
            for name in self.bodies:
                body = bodies.get(name)
                if body is None:  # not seen in this frame: send NaN, the safety monitor rejects it
                    poses.append(np.full(3, np.nan))
                    continue
                q = body.rotation
                poses.append(np.array([body.position[0], body.position[1], yaw_from_quaternion(q.x, q.y, q.z, q.w)]))
            try:
                self.queue.put_nowait(PoseFrame(time.monotonic() - t0, poses[0], poses[1]))
            except queue.Full:  # the loop is not reading: keep the newest frames
                self.queue.get_nowait()

    def poll(self, now: float, timeout: float = 0.0) -> list[PoseFrame]:
        out = []
        while True:
            try:
                frame = self.queue.get_nowait()
            except queue.Empty:
                return out
            frame.received = now
            out.append(frame)

    def close(self) -> None:
        self._stop.set()
