"""Atomic torch files: write to a temporary file in the same folder, fsync, then rename."""

from __future__ import annotations

import os
from pathlib import Path

import torch

from lbgp.files import atomic_file


def save_atomic(obj, path: str | os.PathLike) -> None:
    with atomic_file(path, "wb") as f:  # a full disk leaves the previous file and no temporary one
        torch.save(obj, f)


def load_checked(path: str | os.PathLike, expected_format: str) -> dict:
    """torch.load(weights_only=True) with clear errors for missing, corrupt or foreign files."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
    try:
        data = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:  # truncated zip, wrong magic, disallowed pickle content, ...
        reason = (str(exc).strip().splitlines() or [type(exc).__name__])[0][:120]  # torch's advice runs for lines
        raise ValueError(f"{path} is not a readable {expected_format} file written by lbgp (corrupt, truncated or "
                         f"foreign: {reason})") from None
    if not isinstance(data, dict) or data.get("format") != expected_format:
        found = data.get("format") if isinstance(data, dict) else type(data).__name__
        raise ValueError(f"{path} is not a {expected_format} file (found format {found!r})")
    return data
