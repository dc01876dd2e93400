"""MCAP logs of deployment runs, with ROS 2 message schemas so that Foxglove opens them.

Topics (frame_id "world"; times are the loop clock added to the wall-clock time at the start):

    /robot/pose, /person/pose   geometry_msgs/PoseStamped   poses the tick used (every tick with good data)
    /mocap/robot, /mocap/person geometry_msgs/PoseStamped   every frame the safety checks accepted (all of the
                                                             mocap rate); log time: the tick that read it,
                                                             header stamp: the pose source's own clock
    /cmd_vel                    geometry_msgs/Twist          the command sent (every tick)
    /lbgp/goal                  geometry_msgs/PoseStamped   the goal the planner drives to
    /lbgp/plan                  nav_msgs/Path                the planner's band
    /lbgp/observation           std_msgs/Float32MultiArray   the policy's input (agent steps only)
    /lbgp/status                std_msgs/String              JSON: safety status, planner status, agent step

Chunks are small (16 KiB) and flushed to disk as they are written, so a killed process leaves a
file that reads up to its last complete chunk (``read_log`` reads such files). The file's
metadata record "lbgp" (robot, policy, version) marks it as an lbgp log.
"""

from __future__ import annotations

import json
import math
import os
import time
import warnings
from pathlib import Path

import numpy as np

from lbgp.geometry import yaw_from_quaternion
from lbgp.real.frames import PoseFrame

LOG_METADATA = "lbgp"
POSE_TOPICS = ("/robot/pose", "/person/pose")
_SEP = "\n" + "=" * 80 + "\n"

_HEADER_DEPS = _SEP.join([
    "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id",
    "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec",
])
_POSE_DEPS = _SEP.join([
    "MSG: geometry_msgs/Pose\nPoint position\nQuaternion orientation",
    "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z",
    "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w",
])
SCHEMAS = {
    "geometry_msgs/PoseStamped": "std_msgs/Header header\nPose pose" + _SEP + _HEADER_DEPS + _SEP + _POSE_DEPS,
    "geometry_msgs/Twist": "Vector3 linear\nVector3 angular" + _SEP + "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z",
    "nav_msgs/Path": "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses" + _SEP + _HEADER_DEPS + _SEP
    + "MSG: geometry_msgs/PoseStamped\nstd_msgs/Header header\nPose pose" + _SEP + _POSE_DEPS,
    "std_msgs/Float32MultiArray": "MultiArrayLayout layout\nfloat32[] data" + _SEP
    + "MSG: std_msgs/MultiArrayLayout\nMultiArrayDimension[] dim\nuint32 data_offset" + _SEP
    + "MSG: std_msgs/MultiArrayDimension\nstring label\nuint32 size\nuint32 stride",
    "std_msgs/String": "string data",
}
TOPICS = {
    "/robot/pose": "geometry_msgs/PoseStamped",
    "/person/pose": "geometry_msgs/PoseStamped",
    "/mocap/robot": "geometry_msgs/PoseStamped",
    "/mocap/person": "geometry_msgs/PoseStamped",
    "/cmd_vel": "geometry_msgs/Twist",
    "/lbgp/goal": "geometry_msgs/PoseStamped",
    "/lbgp/plan": "nav_msgs/Path",
    "/lbgp/observation": "std_msgs/Float32MultiArray",
    "/lbgp/status": "std_msgs/String",
}


class LogError(ValueError):
    """A file that is not a readable lbgp MCAP log."""


# What the mcap reader and the ROS 2 decoder raise on a cut or corrupted file: their own errors, and
# those of the bytes underneath (struct unpacking, zstd/lz4 frames, absurd lengths, bad UTF-8,
# CDR decoding). A damaged log is data, not a bug: it reads up to the damage or gives a LogError.
_DAMAGED = (Exception,)


def _stamp(ns: int) -> dict:
    return {"sec": int(ns // 1_000_000_000), "nanosec": int(ns % 1_000_000_000)}


def _pose_msg(pose, ns: int) -> dict:
    x, y, yaw = (float(v) for v in pose)
    return {"header": {"stamp": _stamp(ns), "frame_id": "world"},
            "pose": {"position": {"x": x, "y": y, "z": 0.0},
                     "orientation": {"x": 0.0, "y": 0.0, "z": math.sin(yaw / 2), "w": math.cos(yaw / 2)}}}


class McapLogger:
    """Write ``TickRecord``s of the deployment loop to an MCAP file."""

    def __init__(self, path: str | os.PathLike, metadata: dict | None = None, chunk_size: int = 16 * 1024):
        from mcap.writer import CompressionType
        from mcap_ros2.writer import Writer

        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file = self.path.open("wb")
        self._writer = Writer(self._file, chunk_size=chunk_size, compression=CompressionType.ZSTD)
        self._schemas = {name: self._writer.register_msgdef(name, text) for name, text in SCHEMAS.items()}
        meta = {"format_version": "1", **{k: str(v) for k, v in (metadata or {}).items()}}
        self._writer._writer.add_metadata(LOG_METADATA, meta)
        self._t0_ns = time.time_ns()
        self._closed = False
        self.failed: OSError | None = None  # the error that stopped logging, if one did

    def _write(self, topic: str, msg: dict, ns: int) -> None:
        self._writer.write_message(topic, self._schemas[TOPICS[topic]], msg, log_time=ns, publish_time=ns)

    def log_tick(self, record) -> None:
        """Log one tick. A failing disk (full, removed) never stops the robot's loop: the log stops
        with a warning, and what was flushed before stays readable."""
        if self.failed is not None or self._closed:
            return
        try:
            self._log_tick(record)
        except OSError as exc:
            self.failed = exc
            warnings.warn(f"{self.path}: logging stopped ({exc.strerror or exc}); the file reads up to its last flushed chunk",
                          RuntimeWarning, stacklevel=2)

    def _log_tick(self, record) -> None:
        ns = self._t0_ns + int(round(record.t * 1e9))
        if record.robot is not None:
            self._write("/robot/pose", _pose_msg(record.robot, ns), ns)
            self._write("/person/pose", _pose_msg(record.person, ns), ns)
        for frame in record.frames:  # stamped with the source's clock: its spacing is the capture's, not the ticks'
            stamp = max(int(round(frame.t * 1e9)), 0)
            self._write("/mocap/robot", _pose_msg(frame.robot, stamp), ns)
            self._write("/mocap/person", _pose_msg(frame.person, stamp), ns)
        self._write("/cmd_vel", {"linear": {"x": record.v, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": record.w}}, ns)
        if record.goal is not None:
            self._write("/lbgp/goal", _pose_msg(record.goal, ns), ns)
        if record.band is not None and len(record.band):
            self._write("/lbgp/plan", {"header": {"stamp": _stamp(ns), "frame_id": "world"},
                                        "poses": [_pose_msg(p, ns) for p in record.band]}, ns)
        if record.observation is not None:
            data = [float(v) for v in record.observation]
            self._write("/lbgp/observation", {"layout": {"dim": [{"label": "observation", "size": len(data), "stride": len(data)}],
                                                          "data_offset": 0}, "data": data}, ns)
        status = {"t": record.t, "status": record.status, "planner": record.planner_status, "agent_step": record.agent_step}
        if tuple(record.command_scale) != (1.0, 1.0):  # a calibration scaled this tick's command (--calibration)
            status["command_scale"] = [float(x) for x in record.command_scale]
        self._write("/lbgp/status", {"data": json.dumps(status)}, ns)
        self._file.flush()  # complete chunks reach the disk as soon as they are written

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            try:
                if self.failed is None:
                    self._writer.finish()
            except OSError as exc:
                self.failed = exc
            finally:
                try:
                    self._file.close()
                except OSError:
                    pass


def read_log(path: str | os.PathLike) -> dict:
    """Messages of an lbgp log by topic, as (t seconds from the first message, decoded message)
    pairs, plus ``metadata`` and ``truncated`` (the file ended inside a chunk: a killed run)."""
    from mcap.reader import NonSeekingReader
    from mcap_ros2.decoder import DecoderFactory

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such log file")
    out: dict = {topic: [] for topic in TOPICS}
    metadata, truncated, t0 = None, False, None
    with path.open("rb") as f:
        if f.read(8) != b"\x89MCAP0\r\n":
            raise LogError(f"{path}: not an MCAP file (bad magic bytes)")
        f.seek(0)
        try:  # the metadata record comes first, so even a truncated log has it
            for record in NonSeekingReader(f).iter_metadata():
                if record.name == LOG_METADATA:
                    metadata = dict(record.metadata)
                    break
        except _DAMAGED:
            pass
        if metadata is None:
            raise LogError(f"{path}: not an lbgp log (no '{LOG_METADATA}' metadata record; was it written by lbgp deploy --log?)")
        f.seek(0)
        reader = NonSeekingReader(f, decoder_factories=[DecoderFactory()])
        try:
            for schema, channel, message, decoded in reader.iter_decoded_messages(topics=list(TOPICS), log_time_order=False):
                t0 = message.log_time if t0 is None else t0
                out[channel.topic].append(((message.log_time - t0) / 1e9, decoded))
        except _DAMAGED as exc:
            if not any(out.values()):
                raise LogError(f"{path}: cannot read MCAP records ({type(exc).__name__}: {exc})") from None
            truncated = True
    if not out["/robot/pose"]:
        raise LogError(f"{path}: an lbgp log without any pose messages" + (" (damaged after its metadata)" if truncated else ""))
    out["metadata"] = metadata
    out["truncated"] = truncated
    return out


def pose_of(msg) -> np.ndarray:
    q = msg.pose.orientation
    return np.array([msg.pose.position.x, msg.pose.position.y, yaw_from_quaternion(q.x, q.y, q.z, q.w)])


def stamp_of(msg) -> float:
    """A stamped message's header time in seconds (for /mocap/*: the pose source's own clock)."""
    return msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec


def frames_of(log: dict) -> list[PoseFrame]:
    """The (robot, person) frames of a log, paired by time."""
    people = {round(t, 6): pose_of(m) for t, m in log["/person/pose"]}
    frames = []
    for t, m in log["/robot/pose"]:
        person = people.get(round(t, 6))
        if person is not None:
            frames.append(PoseFrame(t, pose_of(m), person))
    return frames
