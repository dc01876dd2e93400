"""Atomic file writes, the one way lbgp writes a result: into a temporary file in the same folder,
flushed to disk, then renamed over the target. A crash, a full disk or Ctrl-C leaves the previous
file (or none), never a half-written one, and no temporary file behind. And reading a user's JSON
file with an error that names it."""

from __future__ import annotations

import contextlib
import json
import os
from pathlib import Path


@contextlib.contextmanager
def atomic_file(path, mode: str = "w", **open_kwargs):
    """``with atomic_file(path) as f: f.write(...)``: the file appears complete or not at all.
    Folders are created; the temporary file is ``.NAME.PID.tmp`` beside the target."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, mode, **open_kwargs) as f:
            yield f
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_text(path, text: str) -> None:
    with atomic_file(path) as f:
        f.write(text)


def write_json(path, data) -> None:
    write_text(path, json.dumps(data, indent=2) + "\n")


def read_json(path, what: str):
    """The parsed contents of the JSON file ``path``; a missing or unreadable file is a ValueError
    that says which ``what`` file (e.g. "dynamics") and why."""
    path = Path(path)
    try:
        return json.loads(path.read_text())
    except FileNotFoundError:
        raise ValueError(f"{what} file {path} does not exist") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"{what} file {path} is not readable JSON ({type(exc).__name__}: {exc})") from None
