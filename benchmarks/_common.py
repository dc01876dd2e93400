"""Shared by the benchmark scripts: write the result as JSON (creating folders) and print it."""

from __future__ import annotations

import json
import os


def write_result(path: str, result: dict) -> None:
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = f"{path}.tmp"
    with open(tmp, "w") as f:
        json.dump(result, f, indent=2)
    os.replace(tmp, path)
    print(json.dumps(result, indent=2))
