"""How a robot's base responds to a velocity command: the named parameters the simulator applies and
system identification fits (one place, beside ``lbgp.robots.RobotSpec``).

The chain from a (v, w) command to the wheels, as simulated (``lbgp.drive_train``, ``lbgp.sim.drive``):

    command --[latency]--> base firmware --[acceleration limiter]--> wheel setpoints
            --[first-order lag, time constant]--> MuJoCo velocity servos (gain, torque limit)
            --> wheels on the floor (friction; mass and inertia of the body)

``NOMINAL`` is today's simulator, calibrated as before (the ideal drive: no latency, lag or
firmware limiter; MJCF gains and friction): the training default.
``HARDWARE_LIKE`` is a fixed, documented set outside the training presets' nominal values, the
"real" robot of ``lbgp experiment real-protocol`` and ``benchmarks/sim2real_gap.py`` (docs/simulation.md
gives the sources and the reasons for each number). ``RANDOMIZATION`` holds the domain
randomisation presets (``lbgp train --randomize PRESET``): each parameter's sampling range.

All numbers are SI: seconds, m/s^2, rad/s^2, N*m; scales and multipliers are plain ratios.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from lbgp.files import read_json, write_json

INF = math.inf


@dataclasses.dataclass(frozen=True)
class Dynamics:
    """One robot base's response to commands. ``None`` leaves the MJCF model's own value."""

    latency: float = 0.0  # s, from the command being sent to the firmware acting on it
    time_constant: float = 0.0  # s, first-order lag of the wheel setpoints (motor + driver); 0: none
    max_linear_accel: float = INF  # m/s^2, the firmware's acceleration limiter on v (inf: none)
    max_angular_accel: float = INF  # rad/s^2, ... on w
    servo_gain_scale: float = 1.0  # multiplies the MJCF wheel velocity servos' gain kv
    torque_limit: float | None = None  # N*m per wheel actuator (None: the MJCF forcerange)
    mass_scale: float = 1.0  # multiplies the mass of every robot body
    inertia_scale: float = 1.0  # multiplies the rotational inertia of every robot body
    sliding_friction: float | None = None  # wheel-floor sliding friction coefficient (None: MJCF)
    torsional_friction: float | None = None  # wheel-floor torsional friction (None: MJCF)
    track_scale: float = 1.0  # skid-steer slip: the firmware's track / the simulator's calibrated
    # effective track (the Jackal's ROS driver calls it wheel_separation_multiplier); > 1 turns faster
    # for a given w command, < 1 slower (more slip). 1 for a differential drive.
    latency_jitter: float = 0.0  # s, each command is delayed by latency + U(0, jitter) (control-period jitter)

    def validate(self) -> "Dynamics":
        for name in ("latency", "time_constant", "latency_jitter"):
            value = getattr(self, name)
            if not (math.isfinite(value) and 0.0 <= value <= 1.0):
                raise ValueError(f"dynamics: {name} must be in [0, 1] s, got {value}")
        for name in ("max_linear_accel", "max_angular_accel"):
            value = getattr(self, name)
            if not value > 0 or math.isnan(value):
                raise ValueError(f"dynamics: {name} must be > 0 (inf: no limit), got {value}")
        for name in ("servo_gain_scale", "mass_scale", "inertia_scale", "track_scale"):
            value = getattr(self, name)
            if not (math.isfinite(value) and 0.05 <= value <= 20.0):
                raise ValueError(f"dynamics: {name} must be a ratio in [0.05, 20], got {value}")
        for name in ("torque_limit", "sliding_friction", "torsional_friction"):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and 0.0 <= value <= 1000.0):
                raise ValueError(f"dynamics: {name} must be in [0, 1000] or null, got {value}")
        return self

    @property
    def is_ideal_drive(self) -> bool:
        """No latency, lag or firmware limiter: commands reach the servos at once (the fast path)."""
        return (self.latency == 0.0 and self.latency_jitter == 0.0 and self.time_constant == 0.0
                and math.isinf(self.max_linear_accel) and math.isinf(self.max_angular_accel))

    def replace(self, **changes) -> "Dynamics":
        return dataclasses.replace(self, **changes).validate()

    def to_dict(self) -> dict:
        return {k: (None if isinstance(v, float) and math.isinf(v) else v) for k, v in dataclasses.asdict(self).items()}

    @classmethod
    def from_dict(cls, data: dict, where: str = "dynamics") -> "Dynamics":
        if not isinstance(data, dict):
            raise ValueError(f"{where}: expected a JSON object of dynamics parameters, got {type(data).__name__}")
        known = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(f"{where}: unknown dynamics parameters {unknown}; known: {sorted(known)}")
        values = {}
        for key, value in data.items():
            if value is None and key in ("max_linear_accel", "max_angular_accel"):
                value = INF
            if value is None and key not in ("torque_limit", "sliding_friction", "torsional_friction"):
                raise ValueError(f"{where}: {key} must be a number, got null")
            if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))):
                raise ValueError(f"{where}: {key} must be a number, got {value!r}")
            values[key] = None if value is None else float(value)
        try:
            return cls(**values).validate()
        except ValueError as exc:
            raise ValueError(f"{where}: {exc}") from None


# --------------------------------------------------------------------------- named sets per robot
# Published numbers (docs/simulation.md cites them): the Jackal's ROS velocity controller limits
# acceleration to 20 m/s^2 and 25 rad/s^2 (jackal_control, control.yaml), never binding under the
# planner's 1.5 m/s^2 and 3 rad/s^2, so the nominal Jackal leaves the limiter out (and keeps the fast,
# bit-identical ideal-drive path); the Kobuki's driver limits them to 0.5 m/s^2 and 3.5 rad/s^2
# (kobuki_driver's acceleration limiter), binding under the planner's 1.0 m/s^2: today's calibrated
# TurtleBot 2 model has no limiter, and the hardware-like set adds it (below).
NOMINAL: dict[str, Dynamics] = {"jackal": Dynamics(), "turtlebot2": Dynamics()}  # the ideal drive: see above

# The held-out "real" robots: latency of a ROS/serial command path (~0.1 s), a motor-driver lag,
# the Kobuki firmware's acceleration limiter, a heavier, less grippy base. Outside every training
# preset's nominal value; not tuned to favour any method (chosen before any method was run on it).
HARDWARE_LIKE: dict[str, Dynamics] = {
    "jackal": Dynamics(latency=0.10, time_constant=0.12, max_linear_accel=2.0, max_angular_accel=4.0,
                       mass_scale=1.3, inertia_scale=1.3, sliding_friction=0.5, track_scale=0.85, latency_jitter=0.02),
    "turtlebot2": Dynamics(latency=0.10, time_constant=0.12, max_linear_accel=0.5, max_angular_accel=3.5,
                           mass_scale=1.3, inertia_scale=1.3, sliding_friction=0.6, latency_jitter=0.02),
}


def nominal(robot: str) -> Dynamics:
    try:
        return NOMINAL[robot]
    except KeyError:
        raise ValueError(f"no dynamics for robot {robot!r}; known: {sorted(NOMINAL)}") from None


def named(name: str, robot: str) -> Dynamics:
    """``nominal`` or ``hardware_like`` for a robot."""
    table = {"nominal": NOMINAL, "hardware_like": HARDWARE_LIKE}.get(name)
    if table is None:
        raise ValueError(f"unknown dynamics set {name!r}; use 'nominal', 'hardware_like' or a JSON file")
    nominal(robot)
    return table[robot]


def load_dynamics(path_or_name, robot: str) -> Dynamics:
    """A named set (nominal, hardware_like) or a JSON file of parameters; parameters a file leaves out
    keep the robot's nominal values. A file may hold ``{"dynamics": {...}}`` (what ``lbgp sysid`` writes)."""
    if isinstance(path_or_name, Dynamics):
        return path_or_name.validate()
    text = str(path_or_name)
    if text in ("nominal", "hardware_like"):
        return named(text, robot)
    path = Path(text)
    data = read_json(path, "dynamics")
    if isinstance(data, dict) and isinstance(data.get("dynamics"), dict):
        data = data["dynamics"]
    if not isinstance(data, dict):
        raise ValueError(f"{path}: expected a JSON object of dynamics parameters")
    return Dynamics.from_dict({**nominal(robot).to_dict(), **data}, where=str(path))


def save_dynamics(path, dynamics: Dynamics, extra: dict | None = None) -> None:
    write_json(path, {"dynamics": dynamics.to_dict(), **(extra or {})})


# --------------------------------------------------------------------------- domain randomisation
@dataclasses.dataclass(frozen=True)
class Randomization:
    """Per-episode sampling ranges (uniform; ``(lo, hi)``), around a robot's nominal dynamics.
    Scales multiply the nominal value; absolute ranges replace it. ``obs_noise_scale`` multiplies the
    observation noise std; ``latency_jitter`` is the control-period jitter."""

    name: str
    latency: tuple[float, float] = (0.0, 0.0)  # s
    latency_jitter: tuple[float, float] = (0.0, 0.0)  # s
    time_constant: tuple[float, float] = (0.0, 0.0)  # s
    linear_accel_scale: tuple[float, float] = (1.0, 1.0)  # times the planner's acc_lim_x (firmware limiter)
    angular_accel_scale: tuple[float, float] = (1.0, 1.0)  # times the planner's acc_lim_theta
    servo_gain_scale: tuple[float, float] = (1.0, 1.0)
    mass_scale: tuple[float, float] = (1.0, 1.0)
    inertia_scale: tuple[float, float] = (1.0, 1.0)
    friction_scale: tuple[float, float] = (1.0, 1.0)  # times the MJCF sliding friction
    track_scale: tuple[float, float] = (1.0, 1.0)
    obs_noise_scale: tuple[float, float] = (1.0, 1.0)

    def validate(self) -> "Randomization":
        for f in dataclasses.fields(self):
            if f.name == "name":
                continue
            lo, hi = getattr(self, f.name)
            if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 <= lo <= hi):
                raise ValueError(f"randomization {self.name!r}: {f.name} must be a range 0 <= lo <= hi, got {(lo, hi)}")
        return self

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, data: dict, where: str = "randomization") -> "Randomization":
        if not isinstance(data, dict):
            raise ValueError(f"{where}: expected a JSON object of ranges")
        known = {f.name for f in dataclasses.fields(cls)} - {"name"}
        unknown = sorted(set(data) - known - {"name"})
        if unknown:
            raise ValueError(f"{where}: unknown ranges {unknown}; known: {sorted(known)}")
        try:
            ranges = {k: (float(v[0]), float(v[1])) for k, v in data.items() if k != "name"}
        except (TypeError, ValueError, IndexError, KeyError):
            raise ValueError(f"{where}: every range must be a pair [lo, hi] of numbers") from None
        return cls(str(data.get("name", "custom")), **ranges).validate()

    def sample(self, base: Dynamics, rng: np.random.Generator, accel_reference: tuple[float, float],
               mjcf_friction: float) -> tuple[Dynamics, float]:
        """(dynamics for one episode, observation-noise scale). ``accel_reference``: the planner's
        (acc_lim_x, acc_lim_theta), which the firmware limiter's sampled values scale."""
        u = lambda r: float(rng.uniform(*r))  # noqa: E731 - one draw per range, in field order

        def limiter(base_limit: float, scale_range, reference: float, scale: float) -> float:
            # an identity range leaves the firmware limiter as it is (none, in the nominal models)
            return base_limit if tuple(scale_range) == (1.0, 1.0) else min(base_limit, scale * reference)

        lin, ang = u(self.linear_accel_scale), u(self.angular_accel_scale)
        friction = mjcf_friction if base.sliding_friction is None else base.sliding_friction
        dyn = base.replace(
            latency=u(self.latency), latency_jitter=u(self.latency_jitter), time_constant=u(self.time_constant),
            max_linear_accel=limiter(base.max_linear_accel, self.linear_accel_scale, accel_reference[0], lin),
            max_angular_accel=limiter(base.max_angular_accel, self.angular_accel_scale, accel_reference[1], ang),
            servo_gain_scale=base.servo_gain_scale * u(self.servo_gain_scale),
            mass_scale=base.mass_scale * u(self.mass_scale), inertia_scale=base.inertia_scale * u(self.inertia_scale),
            sliding_friction=friction * u(self.friction_scale),
            track_scale=base.track_scale * u(self.track_scale),
        )
        return dyn, u(self.obs_noise_scale)


# The training preset: ranges that contain the nominal model and reach towards (not to) the
# hardware-like set, so that a held-out robot stays held out. docs/simulation.md explains each.
RANDOMIZATION: dict[str, Randomization] = {
    "none": Randomization("none"),
    "default": Randomization(
        "default", latency=(0.0, 0.06), latency_jitter=(0.0, 0.02), time_constant=(0.0, 0.08),
        linear_accel_scale=(0.7, 1.3), angular_accel_scale=(0.7, 1.3), servo_gain_scale=(0.7, 1.3),
        mass_scale=(0.85, 1.2), inertia_scale=(0.85, 1.2), friction_scale=(0.7, 1.3), track_scale=(0.9, 1.1),
        obs_noise_scale=(0.5, 2.0),
    ),
}


def load_randomization(preset_or_path) -> Randomization:
    """A preset name (``RANDOMIZATION``) or a JSON file of ranges (missing ranges: no randomisation)."""
    if isinstance(preset_or_path, Randomization):
        return preset_or_path.validate()
    text = str(preset_or_path)
    if text in RANDOMIZATION:
        return RANDOMIZATION[text]
    path = Path(text)
    if not path.suffix == ".json" and not path.exists():
        raise ValueError(f"unknown randomization preset {text!r}; presets: {sorted(RANDOMIZATION)}, or a JSON file")
    data = read_json(path, "randomization")
    return Randomization.from_dict(data, where=f"randomization file {path}")
