"""Training throughput: env steps/s collected by the actors and learner updates/s, over a 60 s run.

    python benchmarks/bench_train.py --json results/bench_train.json [--seconds 60] [--method lbgp] \
        [--batch-sizes 256,128]

Runs the real training loop (learner here, actor processes beside it) with the default
configuration for ``--seconds`` of wall time (after start-up), once per batch size (default: the
configuration's), then reports the rates measured from each run's summary. The learner is capped
at ``max_updates_per_step`` updates per env step and shares the cores with the actors, so a cheaper
update leaves the actors more CPU: more env steps too. Run it on an otherwise idle machine: it
uses every core.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path


sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402

from lbgp.agent.config import D4PGConfig  # noqa: E402
from lbgp.agent.train import train  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", required=True)
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--method", default="lbgp", choices=["lbgp", "e2e"])
    parser.add_argument("--batch-sizes", default=str(D4PGConfig().batch_size), help="comma-separated, one run each")
    args = parser.parse_args()
    try:
        batch_sizes = [int(b) for b in args.batch_sizes.split(",")]
    except ValueError:
        parser.error(f"--batch-sizes takes comma-separated integers, got {args.batch_sizes!r}")
    runs = []
    for batch_size in batch_sizes:
        with tempfile.TemporaryDirectory() as tmp:
            cfg = D4PGConfig(method=args.method, total_steps=10**9, time_limit_s=args.seconds, min_replay=1000,
                             batch_size=batch_size)
            t0 = time.monotonic()
            summary = train(cfg, os.path.join(tmp, "run"), progress=False)
            elapsed = time.monotonic() - t0
        runs.append({
            "batch_size": cfg.batch_size,
            "num_actors": cfg.num_actors,
            "max_updates_per_step": cfg.max_updates_per_step,
            "train_wall_time_s": summary["wall_time_s"],
            "total_elapsed_s_with_startup": round(elapsed, 1),
            "env_steps": summary["env_steps"],
            "env_steps_per_s": round(summary["env_steps"] / summary["wall_time_s"], 1),
            "learner_updates": summary["learner_updates"],
            "learner_updates_per_s": round(summary["learner_updates"] / summary["wall_time_s"], 1),
        })
    command = command_line("bench_train.py")
    write_result(args.json, {"command": command, "method": args.method, "cpu_count": os.cpu_count(), "runs": runs})


if __name__ == "__main__":
    main()
