"""Command calibration: make a robot answer a (v, w) command the way the simulated robot does.

Policies and planner limits were made on the simulated robots. A real base can turn less than it
is told (a skid-steer Jackal on a slippery floor, a miscalibrated wheel separation: what ROS's
``wheel_separation_multiplier`` fixes on the robot's side) or drive slower. ``lbgp sysid``
identifies a robot's gains (achieved / commanded forward speed and yaw rate over an excitation
run); the same identification on the nominal simulated robot gives the reference gains below. The
calibration divides every command that leaves lbgp by the robot's gains relative to that reference,
so that the robot does what the planner (or an E2E policy) asked of the simulated one.

It acts at the one place where commands go out (the simulated task's wheels, the deploy loop's
command sink): the planner still chains its acceleration limits from its own command, and the log
records what was sent, so that identifying a calibrated run still sees the raw base.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

from lbgp.files import read_json

# Gains ``lbgp sysid`` identifies on the nominal simulated robots from ``lbgp sysid --excite`` (sim
# source, seed 1): achieved / commanded (v, w). tests/test_sysid.py re-identifies them.
SIM_REFERENCE_GAINS: dict[str, tuple[float, float]] = {"jackal": (0.992, 0.867), "turtlebot2": (0.972, 0.927)}
MAX_CORRECTION = 3.0  # a calibration that multiplies a command by more than this (or less than its inverse) is refused


@dataclasses.dataclass(frozen=True)
class CommandCalibration:
    """Multiply sent commands by ``scale_v`` and ``scale_w`` (1, 1: the identity)."""

    scale_v: float = 1.0
    scale_w: float = 1.0
    source: str = "none"  # where the numbers came from (a sysid file, or "none")

    def __post_init__(self):
        for name in ("scale_v", "scale_w"):
            value = getattr(self, name)
            if not (math.isfinite(value) and 1.0 / MAX_CORRECTION <= value <= MAX_CORRECTION):
                raise ValueError(f"calibration {name} must be within [{1 / MAX_CORRECTION:.3g}, {MAX_CORRECTION:g}], got {value}")

    @property
    def is_identity(self) -> bool:
        return self.scale_v == 1.0 and self.scale_w == 1.0

    def reset(self) -> None:
        """Nothing to forget (``lbgp.online_calibration.OnlineCalibration`` has the same calls)."""

    def observe(self, t: float, pose) -> None:
        """A fixed calibration does not learn from the robot's measured poses."""

    def apply(self, v: float, w: float) -> tuple[float, float]:
        """The command to send for the wanted (v, w)."""
        return v * self.scale_v, w * self.scale_w

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)

    @classmethod
    def from_gains(cls, robot: str, gain_v: float, gain_w: float, source: str = "") -> "CommandCalibration":
        """From a robot's identified gains (achieved / commanded), relative to the simulated robot's."""
        if robot not in SIM_REFERENCE_GAINS:
            raise ValueError(f"no reference gains for robot {robot!r}; use one of {', '.join(SIM_REFERENCE_GAINS)}")
        ref_v, ref_w = SIM_REFERENCE_GAINS[robot]
        for name, gain in (("gain_v", gain_v), ("gain_w", gain_w)):
            if not (isinstance(gain, (int, float)) and math.isfinite(gain) and gain > 0):
                raise ValueError(f"{source or 'calibration'}: {name} must be a positive number, got {gain!r}")
        return cls(ref_v / gain_v, ref_w / gain_w, source or "gains")


def load_calibration(spec, robot: str):
    """``None`` or ``"none"``: the identity; ``"online"``: a fresh ``OnlineCalibration`` (gains
    estimated while driving, ``lbgp.online_calibration``); a ``CommandCalibration`` or an
    ``OnlineCalibration`` as it is; or a JSON file: the output of
    ``lbgp sysid --out`` (its ``fit.gain_v`` / ``fit.gain_w``, taken relative to the simulated
    robot's) or ``{"scale_v": ..., "scale_w": ...}`` (multipliers as they are)."""
    if spec is None or spec == "none":
        return CommandCalibration()
    if spec == "online":
        from lbgp.online_calibration import OnlineCalibration

        return OnlineCalibration(robot)
    if hasattr(spec, "observe"):  # a CommandCalibration or an OnlineCalibration: used as it is
        return spec
    path = Path(spec)
    data = read_json(path, "calibration")
    if not isinstance(data, dict):
        raise ValueError(f"calibration file {path}: expected a JSON object")
    if isinstance(data.get("fit"), dict):
        fit = data["fit"]
        if data.get("robot") not in (None, robot):
            raise ValueError(f"calibration file {path} was identified on {data['robot']}, not {robot}")
        return CommandCalibration.from_gains(robot, fit.get("gain_v"), fit.get("gain_w"), str(path))
    if "scale_v" in data or "scale_w" in data:
        try:
            return CommandCalibration(float(data.get("scale_v", 1.0)), float(data.get("scale_w", 1.0)), str(path))
        except (TypeError, ValueError) as exc:
            raise ValueError(f"calibration file {path}: {exc}") from None
    raise ValueError(f"calibration file {path}: expected lbgp sysid's output (a 'fit' with gain_v and gain_w) "
                     "or scale_v / scale_w")
