"""Rerun recordings of follow-ahead episodes (live viewer or .rrd file).

Entity paths (all world-frame, metres, top-down 2-D):

    world/robot, world/person            current pose (point + heading arrow)
    world/robot/trail, world/person/trail   path so far in this episode
    world/goal                           the policy's goal
    world/band                           the planner's band
    world/person/prediction              the person's predicted path used by the planner
    metrics/distance, metrics/alpha_deg, metrics/reward   scalar plots
    episode                              a text log line per episode (scenario name, index)

Timeline ``sim_time`` (seconds since the episode started) plus ``step`` (agent steps overall).
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import rerun as rr

VIEWER_PORT = 9876  # rerun's default gRPC port, served on 127.0.0.1 by the viewer lbgp spawns
ENTITY_PATHS = (
    "world/robot",
    "world/robot/trail",
    "world/person",
    "world/person/trail",
    "world/goal",
    "world/band",
    "world/person/prediction",
    "metrics/distance",
    "metrics/alpha_deg",
    "metrics/reward",
    "episode",
)


def _arrow(pose, length: float = 0.4):
    return [pose[0], pose[1]], [length * math.cos(pose[2]), length * math.sin(pose[2])]


class EpisodeRecorder:
    """Log episodes to a .rrd file (written atomically on ``close``) and/or a spawned viewer."""

    def __init__(self, path: str | os.PathLike | None = None, spawn: bool = False, application_id: str = "lbgp"):
        if path is None and not spawn:
            raise ValueError("EpisodeRecorder needs a file path, spawn=True, or both")
        self.rec = rr.RecordingStream(application_id)
        self.path = Path(path) if path is not None else None
        self._tmp = None
        if spawn:
            try:
                self._spawn_viewer()
            except Exception as exc:  # no viewer installed or no display: keep recording to the file
                import warnings

                warnings.warn(f"could not open a live rerun viewer ({exc}); recording continues", stacklevel=2)
        if self.path is not None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._tmp = self.path.with_name(self.path.name + ".partial")
            self.rec.save(str(self._tmp))
        self._step = 0
        self._episode_start = 0.0
        self._robot_trail: list = []
        self._person_trail: list = []

    def _spawn_viewer(self, port: int = VIEWER_PORT) -> None:
        """Start a rerun viewer that listens on the loopback address only (``rerun`` binds
        0.0.0.0 by default, and the SDK's own spawn cannot change that), then stream to it."""
        exe = shutil.which("rerun") or str(Path(sys.executable).with_name("rerun"))
        if not Path(exe).exists():
            raise FileNotFoundError("no rerun viewer executable found")
        subprocess.Popen([exe, "--bind", "127.0.0.1", "--port", str(port)], stdin=subprocess.DEVNULL,
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        self.rec.connect_grpc(f"rerun+http://127.0.0.1:{port}/proxy")

    def begin_episode(self, name: str, index: int = 0) -> None:
        self._robot_trail, self._person_trail = [], []
        self.rec.set_time("step", sequence=self._step)
        self.rec.set_time("sim_time", duration=0.0)
        self.rec.log("episode", rr.TextLog(f"episode {index}: {name}"))

    def log_step(self, info: dict, reward: float | None = None) -> None:
        rec = self.rec
        self._step += 1
        rec.set_time("step", sequence=self._step)
        rec.set_time("sim_time", duration=float(info.get("time", 0.0)))
        robot, person = np.asarray(info["robot_pose"]), np.asarray(info["person_pose"])
        self._robot_trail.append(robot[:2].tolist())
        self._person_trail.append(person[:2].tolist())
        for name, pose, color, trail in (
            ("world/robot", robot, (240, 180, 20), self._robot_trail),
            ("world/person", person, (40, 100, 230), self._person_trail),
        ):
            origin, vector = _arrow(pose)
            rec.log(name, rr.Arrows2D(origins=[origin], vectors=[vector], colors=[color], radii=0.03))
            rec.log(f"{name}/trail", rr.LineStrips2D([trail], colors=[color], radii=0.01))
        goal = info.get("goal")
        if goal is not None:
            rec.log("world/goal", rr.Points2D([np.asarray(goal)[:2]], colors=[(30, 200, 60)], radii=0.06))
        band = info.get("band")
        if band is not None and len(band):
            rec.log("world/band", rr.LineStrips2D([np.asarray(band)[:, :2]], colors=[(30, 200, 60)], radii=0.015))
        prediction = info.get("person_prediction")
        if prediction is not None and len(prediction):
            rec.log("world/person/prediction", rr.LineStrips2D([np.asarray(prediction)], colors=[(120, 160, 255)], radii=0.01))
        rec.log("metrics/distance", rr.Scalars(float(info["distance"])))
        rec.log("metrics/alpha_deg", rr.Scalars(math.degrees(float(info["alpha"]))))
        if reward is not None:
            rec.log("metrics/reward", rr.Scalars(float(reward)))

    def close(self) -> None:
        self.rec.flush()
        self.rec.disconnect()
        if self._tmp is not None and self._tmp.exists():
            os.replace(self._tmp, self.path)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def entity_paths_in(path: str | os.PathLike) -> set[str]:
    """Entity paths stored in a .rrd file, read back with rerun's own reader."""
    from rerun.chunk import RrdReader

    paths = set()
    for chunk in RrdReader(path).stream():
        paths.add(str(chunk.entity_path).lstrip("/"))
    return paths
