"""Training throughput: env steps/s collected by the actors and learner updates/s, over a 60 s run.

    python benchmarks/bench_train.py --json results/bench_train.json [--seconds 60] [--method lbgp]

Runs the real training loop (learner here, actor processes beside it) with the default
configuration for ``--seconds`` of wall time (after start-up), then reports the rates measured
from the run's summary. Run it on an otherwise idle machine: it uses every core.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path


sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_result  # noqa: E402

from lbgp.agent.config import D4PGConfig  # noqa: E402
from lbgp.agent.train import train  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", required=True)
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--method", default="lbgp", choices=["lbgp", "e2e"])
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        cfg = D4PGConfig(method=args.method, total_steps=10**9, time_limit_s=args.seconds, min_replay=1000)
        t0 = time.monotonic()
        summary = train(cfg, os.path.join(tmp, "run"), progress=False)
        elapsed = time.monotonic() - t0
    result = {
        "method": args.method,
        "cpu_count": os.cpu_count(),
        "num_actors": cfg.num_actors,
        "train_wall_time_s": summary["wall_time_s"],
        "total_elapsed_s_with_startup": round(elapsed, 1),
        "env_steps": summary["env_steps"],
        "env_steps_per_s": summary["env_steps"] / summary["wall_time_s"],
        "learner_updates": summary["learner_updates"],
        "learner_updates_per_s": summary["learner_updates"] / summary["wall_time_s"],
        "batch_size": cfg.batch_size,
    }
    write_result(args.json, result)


if __name__ == "__main__":
    main()
