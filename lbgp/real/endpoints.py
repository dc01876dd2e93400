"""Pose sources and command sinks by URL, as ``lbgp deploy --source/--sink`` takes them.

Sources:
    vicon://HOST (also optitrack://, qualisys://, vrpn://, ...)   motion capture (extra ``mocap``);
        ?robot=BODY&person=BODY name the rigid bodies (default robot, person)
    udp://[HOST:]PORT[?from=IP[:PORT],...]   JSON frames; binds HOST (default 127.0.0.1) and accepts
        only the listed senders (default 127.0.0.1)
    mcap://FILE                              the frames of an lbgp log, on a virtual clock
    sim[://SCENARIO]                         the MuJoCo world (default straight_ahead), lock-step
Sinks:
    udp://HOST:PORT      JSON commands       ros2[:///TOPIC]   geometry_msgs/Twist (default /cmd_vel)
    sim                  the simulated robot (only with a sim source)
    none                 send nothing (replaying a log, dry runs)
"""

from __future__ import annotations

import urllib.parse

from lbgp.real.mocap import SYSTEMS


def _split(url: str):
    if "://" not in url:
        return url, "", {}
    scheme, rest = url.split("://", 1)
    target, _, query = rest.partition("?")
    return scheme, target, {k: v[-1] for k, v in urllib.parse.parse_qs(query).items()}


def open_source(url: str, robot: str = "turtlebot2", seed: int = 0, person_path=None, disturbance=None, dynamics=None):
    """(source, world): ``world`` is the SimWorld for sim sources, else None."""
    from lbgp.real.udp import UdpPoseSource, parse_address

    scheme, target, query = _split(url)
    if scheme in SYSTEMS:
        from lbgp.real.mocap import MocapPoseSource

        if not target:
            raise ValueError(f"{url!r}: name the mocap host, e.g. {scheme}://192.168.1.10")
        return MocapPoseSource(scheme, target, query.get("robot", "robot"), query.get("person", "person")), None
    if scheme == "udp":
        senders = [s for s in query.get("from", "127.0.0.1").split(",") if s]
        return UdpPoseSource(parse_address(target), allowed_senders=senders), None
    if scheme == "mcap":
        from lbgp.real.replay import McapPoseSource

        return McapPoseSource(target), None
    if scheme == "sim":
        from lbgp.real.sim_world import SimPoseSource, SimWorld

        world = SimWorld(target or "straight_ahead", robot=robot, seed=seed, person_path=person_path, dynamics=dynamics)
        return SimPoseSource(world, disturbance, seed=seed), world
    raise ValueError(f"unknown pose source {url!r}; use vicon://HOST (or another mocap system), udp://PORT, mcap://FILE or sim")


class NullSink:
    def send(self, t: float, v: float, w: float, status: str = "ok") -> None:
        pass

    def close(self) -> None:
        pass


def open_sink(url: str, world=None):
    from lbgp.real.udp import UdpCommandSink, parse_address

    scheme, target, _ = _split(url)
    if scheme == "udp":
        host, port = parse_address(target)
        return UdpCommandSink((host, port))
    if scheme == "ros2":
        from lbgp.real.ros2 import Ros2TwistSink

        return Ros2TwistSink(target or "/cmd_vel")
    if scheme == "sim":
        if world is None:
            raise ValueError("the sim sink drives the simulated robot: use it with --source sim")
        from lbgp.real.sim_world import SimCommandSink

        return SimCommandSink(world)
    if scheme == "none":
        return NullSink()
    raise ValueError(f"unknown command sink {url!r}; use udp://HOST:PORT, ros2, sim or none")
