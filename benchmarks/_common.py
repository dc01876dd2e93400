"""Shared by the benchmark scripts: the command that made a result; write the result as JSON
(creating folders) and print it."""

from __future__ import annotations

import json
import os
import sys


def command_line(script: str, argv: list[str] | None = None) -> str:
    """The command that made a result, as results/README.md gives it: ``python benchmarks/NAME.py ARGS``
    (``argv``: the arguments main() was given; default: this process's own)."""
    return f"python benchmarks/{script} " + " ".join(sys.argv[1:] if argv is None else argv)


def write_result(path: str, result: dict) -> None:
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = f"{path}.tmp"
    with open(tmp, "w") as f:
        json.dump(result, f, indent=2)
    os.replace(tmp, path)
    print(json.dumps(result, indent=2))
