"""Argument types of the ``lbgp`` command line: every option is checked where it enters, so that a
bad value ends with one line naming the option and the rule (exit 2) before anything is written.

Each function is an argparse ``type=``: it returns the parsed value or raises
``argparse.ArgumentTypeError`` with the rule; argparse adds the option's name.
"""

from __future__ import annotations

import argparse
import math
import os
from pathlib import Path

MAX_COUNT = 10_000_000  # larger counts are typing errors, not experiments


def _number(text: str, kind):
    try:
        value = kind(text)
    except (TypeError, ValueError):
        raise argparse.ArgumentTypeError(f"{text!r} is not {'an integer' if kind is int else 'a number'}") from None
    if kind is float and not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return value


def positive_int(text: str) -> int:
    value = _number(text, int)
    if not 1 <= value <= MAX_COUNT:
        raise argparse.ArgumentTypeError(f"must be an integer from 1 to {MAX_COUNT:,}, got {value}")
    return value


def seed(text: str) -> int:
    value = _number(text, int)
    if not 0 <= value < 2**32:
        raise argparse.ArgumentTypeError(f"must be an integer from 0 to 2^32 - 1, got {value}")
    return value


def _bounded_float(text: str, low: float, high: float, allow_low: bool, rule: str) -> float:
    value = _number(text, float)
    if not ((low <= value) if allow_low else (low < value)) or value > high:
        raise argparse.ArgumentTypeError(f"must be {rule}, got {value:g}")
    return value


def positive_float(text: str) -> float:
    return _bounded_float(text, 0.0, 1e7, False, "a number above 0 (and at most 1e7)")


def nonnegative_float(text: str) -> float:
    """>= 0, where 0 means 'off' (documented per option)."""
    return _bounded_float(text, 0.0, 1e7, True, "a number from 0 to 1e7")


def fraction(text: str) -> float:
    """A rate in [0, 1), where 0 means 'off' (documented per option)."""
    value = _number(text, float)
    if not 0.0 <= value < 1.0:
        raise argparse.ArgumentTypeError(f"must be a number from 0 up to (not including) 1, got {value:g}")
    return value


def distance(text: str) -> float:
    return _bounded_float(text, 0.0, 10.0, False, "a distance above 0 and at most 10 m")


def input_file(text: str) -> str:
    """An existing, readable regular file."""
    if not text:
        raise argparse.ArgumentTypeError("needs a file name")
    path = Path(text)
    if path.is_dir():
        raise argparse.ArgumentTypeError(f"{text} is a directory, not a file")
    if not path.is_file():
        raise argparse.ArgumentTypeError(f"{text}: no such file")
    if not os.access(path, os.R_OK):
        raise argparse.ArgumentTypeError(f"{text} is not readable")
    return text


def dynamics_spec(text: str) -> str:
    """A named dynamics set (nominal, hardware_like) or an existing JSON file of parameters."""
    if text in ("nominal", "hardware_like"):
        return text
    try:
        return input_file(text)
    except argparse.ArgumentTypeError as exc:
        raise argparse.ArgumentTypeError(f"{exc}; use nominal, hardware_like or a JSON file of dynamics parameters") from None


def drive_model_spec(text: str) -> str:
    """``none``, a named dynamics set (nominal, hardware_like) or an existing JSON file of dynamics
    (``lbgp sysid``'s output): the planner's model of the robot's drive."""
    return "none" if text == "none" else dynamics_spec(text)


def calibration_spec(text: str) -> str:
    """``none``, ``online`` (gains estimated while driving) or an existing JSON file (``lbgp sysid``'s
    output, or scale_v / scale_w)."""
    if text in ("none", "online"):
        return text
    try:
        return input_file(text)
    except argparse.ArgumentTypeError as exc:
        raise argparse.ArgumentTypeError(f"{exc}; use none, online or the JSON that lbgp sysid --out wrote") from None


def randomize_spec(text: str) -> str:
    """A domain-randomisation preset name or an existing JSON file of ranges."""
    from lbgp.dynamics import RANDOMIZATION

    if text in RANDOMIZATION:
        return text
    try:
        return input_file(text)
    except argparse.ArgumentTypeError as exc:
        raise argparse.ArgumentTypeError(f"{exc}; use a preset ({', '.join(RANDOMIZATION)}) or a JSON file of ranges") from None


def _check_writable_parent(path: Path, text: str) -> None:
    parent = path.parent
    while not parent.exists():  # folders that will be created: the nearest existing one decides
        if parent.parent == parent:
            break
        parent = parent.parent
    if parent.exists() and not parent.is_dir():
        raise argparse.ArgumentTypeError(f"{text}: {parent} is a file, not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise argparse.ArgumentTypeError(f"{text}: cannot write in {parent}")


def output_file(text: str) -> str:
    """A file to write: not a directory, under a folder that exists or can be created and is writable."""
    if not text:
        raise argparse.ArgumentTypeError("needs a file name")
    path = Path(text)
    if path.is_dir() or text.endswith(("/", os.sep)):
        raise argparse.ArgumentTypeError(f"{text} is a directory; name a file")
    if path.exists() and not os.access(path, os.W_OK):
        raise argparse.ArgumentTypeError(f"{text} is not writable")
    _check_writable_parent(path, text)
    return text


def output_dir(text: str) -> str:
    """A folder to write into: an existing writable folder, or one that can be created."""
    if not text:
        raise argparse.ArgumentTypeError("needs a folder name")
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text} is a file, not a folder")
    if path.is_dir():
        if not os.access(path, os.W_OK | os.X_OK):
            raise argparse.ArgumentTypeError(f"cannot write in {text}")
        return text
    _check_writable_parent(path, text)
    return text


def existing_dir(text: str) -> str:
    if not text or not Path(text).is_dir():
        raise argparse.ArgumentTypeError(f"{text!r}: no such folder")
    return text


class OneLineParser(argparse.ArgumentParser):
    """argparse that reports a bad argument in one line (no usage block): 'lbgp X: error: ...'."""

    def error(self, message):  # noqa: D401 - argparse's API
        self.exit(2, f"{self.prog}: error: {message}\n")
