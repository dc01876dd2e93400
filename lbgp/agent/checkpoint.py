"""Atomic torch files: write to a temporary file in the same folder, fsync, then rename."""

from __future__ import annotations

import os
from pathlib import Path

import torch


def save_atomic(obj, path: str | os.PathLike) -> None:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "wb") as f:
            torch.save(obj, f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)  # e.g. a full disk: the previous file stays, no half-written one
        raise


def load_checked(path: str | os.PathLike, expected_format: str) -> dict:
    """torch.load(weights_only=True) with clear errors for missing, corrupt or foreign files."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
    try:
        data = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:  # truncated zip, wrong magic, disallowed pickle content, ...
        raise ValueError(f"{path} is not a readable {expected_format} file (corrupt or truncated?): {exc}") from exc
    if not isinstance(data, dict) or data.get("format") != expected_format:
        found = data.get("format") if isinstance(data, dict) else type(data).__name__
        raise ValueError(f"{path} is not a {expected_format} file (found format {found!r})")
    return data
