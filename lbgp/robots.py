"""The robots lbgp knows: where their MJCF lives, their physical numbers, and the one place where a
body velocity (v, w) becomes wheel speeds and back.

The bottom layer of lbgp (see docs/architecture.md): the planner, the simulator and the real robot
all read their robot from here, and this module imports none of them. Every part of lbgp that
commands a robot goes through :class:`DiffDrive`, in simulation and on the real robot alike.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

ASSETS = Path(__file__).resolve().parents[1] / "assets" / "mjcf"


def _assets_dir() -> Path:
    """The MJCF folder: next to the package in a source checkout, else shipped inside it."""
    if ASSETS.is_dir():
        return ASSETS
    return Path(__file__).resolve().parent / "sim" / "assets" / "mjcf"  # pragma: no cover - wheel installs


@dataclasses.dataclass(frozen=True)
class RobotSpec:
    """Physical description of a wheeled robot.

    ``effective_track`` is the track used by the kinematic (v, w) <-> wheel-speed mapping. For the
    differential-drive TurtleBot 2 it is the wheel separation; for the skid-steer Jackal the wheels
    slip sideways when turning, so the effective track is larger than the geometric one (the
    instantaneous-centre-of-rotation model). The Jackal number was calibrated in this simulator by
    commanding in-place turns of 0.5-2 rad/s and fitting the measured yaw rate
    (``tests/test_robots.py`` checks the fit still holds).
    """

    name: str
    wheel_radius: float  # m
    track: float  # m, geometric distance between left and right wheels
    effective_track: float  # m, used by the kinematic mapping (see above)
    wheelbase: float  # m, front-rear wheel distance (0 for a single-axle robot)
    left_actuators: tuple[str, ...]
    right_actuators: tuple[str, ...]
    max_speed: float  # m/s, top linear speed
    max_yaw_rate: float  # rad/s
    footprint_radius: float  # m, radius of a circle that covers the robot seen from above
    mass: float  # kg, approximate total

    @property
    def scene_path(self) -> Path:
        return _assets_dir() / self.name / "scene.xml"

    @property
    def robot_path(self) -> Path:
        return _assets_dir() / self.name / f"{self.name}.xml"

    @property
    def drive(self) -> "DiffDrive":
        return DiffDrive(self.wheel_radius, self.effective_track)


JACKAL = RobotSpec(
    name="jackal",
    wheel_radius=0.098,
    track=0.376,
    effective_track=0.85,
    wheelbase=0.262,
    left_actuators=("left_front_wheel", "left_rear_wheel"),
    right_actuators=("right_front_wheel", "right_rear_wheel"),
    max_speed=2.0,
    max_yaw_rate=2.0,
    footprint_radius=0.27,
    mass=16.5,
)

TURTLEBOT2 = RobotSpec(
    name="turtlebot2",
    wheel_radius=0.035,
    track=0.23,
    effective_track=0.23,
    wheelbase=0.0,
    left_actuators=("left_wheel",),
    right_actuators=("right_wheel",),
    max_speed=0.7,
    max_yaw_rate=3.0,
    footprint_radius=0.176,
    mass=5.9,
)

ROBOTS: dict[str, RobotSpec] = {spec.name: spec for spec in (JACKAL, TURTLEBOT2)}


def get_robot(name: str) -> RobotSpec:
    """Look a robot up by name; an unknown name raises a ValueError listing the known ones."""
    try:
        return ROBOTS[name]
    except KeyError:
        raise ValueError(f"unknown robot {name!r}; known robots: {', '.join(sorted(ROBOTS))}") from None


@dataclasses.dataclass(frozen=True)
class DiffDrive:
    """(v, w) <-> (left, right) wheel angular speeds for a differential or skid-steer base."""

    wheel_radius: float
    track: float

    def wheel_speeds(self, v: float, w: float) -> tuple[float, float]:
        """Body velocity (m/s, rad/s) to left and right wheel speeds (rad/s)."""
        half = 0.5 * self.track
        return (v - w * half) / self.wheel_radius, (v + w * half) / self.wheel_radius

    def body_velocity(self, left: float, right: float) -> tuple[float, float]:
        """Left and right wheel speeds (rad/s) to body velocity (m/s, rad/s)."""
        v = 0.5 * self.wheel_radius * (left + right)
        w = self.wheel_radius * (right - left) / self.track
        return v, w
