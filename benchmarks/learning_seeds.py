"""The learning test's run for other seeds: does 10,000 steps of training on the straight level
beat a random policy and the untrained network on straight_ahead for every seed, not just one?

    python benchmarks/learning_seeds.py --seeds 0,1,2,3 --json results/learning_seeds.json

Same configuration and judgement as tests/test_learning.py (inline backend, so each seed's run is
reproducible); about 3 minutes per seed on 2 cores.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import torch

ROOT = Path(__file__).resolve().parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT.parent / "tests"))
from _common import write_result  # noqa: E402
from test_learning import NetworkPolicy, RandomPolicy, straight_ahead_return, straight_level_config  # noqa: E402

from lbgp.agent import load_policy  # noqa: E402
from lbgp.agent.learner import make_actor  # noqa: E402
from lbgp.agent.train import train  # noqa: E402
from lbgp.sim import observation as obs_lib  # noqa: E402


def one_seed(seed: int) -> dict:
    cfg = straight_level_config(seed=seed, total_steps=10_000)
    torch.manual_seed(seed)
    untrained = make_actor(cfg, obs_lib.SIZE, 2)
    with tempfile.TemporaryDirectory() as tmp:
        train(cfg, Path(tmp) / "run", backend="inline", progress=False)
        trained = straight_ahead_return(load_policy(Path(tmp) / "run" / "policy.pt"))
    return {"seed": seed, "trained": trained, "untrained": straight_ahead_return(NetworkPolicy(untrained)),
            "random": straight_ahead_return(RandomPolicy(0))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="0,1,2,3")
    parser.add_argument("--json", default="results/learning_seeds.json")
    args = parser.parse_args()
    results = [one_seed(int(s)) for s in args.seeds.split(",")]
    write_result(args.json, {"benchmark": "learning_test_across_seeds", "env_steps": 10_000, "judged_on": "straight_ahead",
                             "results": results})


if __name__ == "__main__":
    main()
