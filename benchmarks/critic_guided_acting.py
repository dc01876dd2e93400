"""Acting with the critic: does picking the critic's best goal near the actor's beat the actor's goal?

    python benchmarks/critic_guided_acting.py --runs runs/no-warmup,runs/prior3,runs/smoother --radii 0.05,0.15 \
        --json results/critic_guided_acting.json --jobs 2

A D4PG actor only follows the critic's gradient, a few hundred thousand small steps on a CPU budget:
where the critic already ranks a nearby goal higher, the actor may not have got there yet. This
asks the critic at acting time. Each step the policy's own action (its policy file, acting as
shipped: mirror-averaged, with the goal dead band) is the centre of a 5 x 5 grid of candidate
actions spaced ``radius / 2`` apart (``radius`` in action units: 0.1 = 0.2 m of goal); each is
scored by the critic's expected value, averaged with the mirror image's (so the choice stays
mirror-equivariant), and the best is sent. The critic is the run's own, from its checkpoint.pt
(runs keep it under runs/, not in results/: the files are large).

Scored as benchmarks/ablation_scenarios.py scores a run (the 9 paper scenarios, Jackal, 20 seeded
noisy episodes each, the sim table's episodes): per run the plain policy and each radius; per
radius the paired difference to the plain policy over the runs (mean and 95 % t interval).
Only runs whose critic reads the plain observation are taken (no ``critic_future``, no previous goal).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402
from ablation_scenarios import paired_difference, sim_table_rewards  # noqa: E402

import numpy as np  # noqa: E402
import torch  # noqa: E402

from lbgp.actions import mirror_actions  # noqa: E402
from lbgp.agent.checkpoint import load_checked  # noqa: E402
from lbgp.agent.config import D4PGConfig  # noqa: E402
from lbgp.agent.learner import D4PGLearner  # noqa: E402
from lbgp.agent.policy import load_policy  # noqa: E402
from lbgp.agent.train import CHECKPOINT_FORMAT  # noqa: E402
from lbgp.sim import observation as obs_lib  # noqa: E402
from lbgp.sim import scenario_names  # noqa: E402
from lbgp.sim.observation import mirror  # noqa: E402
from lbgp.parallel import process_pool  # noqa: E402

GRID = 5  # candidates per axis


class CriticGuidedPolicy:
    """``policy``'s action, replaced by the candidate near it that ``critic`` values highest."""

    def __init__(self, policy, critic, radius: float):
        self.policy, self.critic, self.control = policy, critic.eval(), policy.control
        axis = np.linspace(-radius, radius, GRID)
        self.offsets = np.stack(np.meshgrid(axis, axis, indexing="ij"), -1).reshape(-1, 2).astype(np.float32)

    def reset(self) -> None:
        self.policy.reset()

    @torch.no_grad()
    def act(self, observation) -> np.ndarray:
        action = self.policy.act(observation)
        candidates = np.clip(action[None] + self.offsets, -1.0, 1.0).astype(np.float32)
        obs = np.asarray(observation, np.float32)
        n = len(candidates)
        q = self.critic.q_value(torch.from_numpy(np.repeat(obs[None], n, 0)), torch.from_numpy(candidates))
        q_mirror = self.critic.q_value(torch.from_numpy(np.repeat(mirror(obs)[None], n, 0)),
                                       torch.from_numpy(mirror_actions(candidates)))
        return candidates[int(torch.argmax(q + q_mirror))]


def load_critic(run: Path):
    """The run's critic from its checkpoint (ValueError if the run's critic reads more than the observation)."""
    data = load_checked(run / "checkpoint.pt", CHECKPOINT_FORMAT)
    cfg = D4PGConfig.from_dict(data["config"])
    if cfg.critic_future or cfg.previous_goal:
        raise ValueError(f"{run}: its critic reads more than the observation (critic_future or previous_goal)")
    learner = D4PGLearner(cfg, obs_lib.SIZE, 2)
    learner.load_state_dict(data["learner"])
    return learner.critic


def score(job: tuple) -> tuple[str, dict]:
    """job: (name, run folder, radius or None for the plain policy, scenarios, episodes, seed)."""
    name, run, radius, scenarios, episodes, seed = job
    torch.set_num_threads(1)
    policy = load_policy(Path(run) / "policy.pt")
    if radius is not None:
        policy = CriticGuidedPolicy(policy, load_critic(Path(run)), radius)
    per_scenario = sim_table_rewards(policy, "lbgp", scenarios, episodes, seed)
    return name, {"run": str(run), "radius": radius, "per_scenario": per_scenario, "sum": round(float(sum(per_scenario.values())), 3)}


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", required=True, help="comma-separated folders of run folders (<run>/checkpoint.pt and policy.pt)")
    ap.add_argument("--radii", default="0.05,0.1", help="comma-separated grid half-widths in action units")
    ap.add_argument("--scenarios", default=",".join(scenario_names()))
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--json", default="results/critic_guided_acting.json")
    args = ap.parse_args(argv)
    radii = [float(r) for r in args.radii.split(",")]
    if any(not (0.0 < r <= 1.0) for r in radii):
        ap.error(f"--radii takes half-widths in (0, 1] action units, got {args.radii!r}")
    runs = [p.parent for d in args.runs.split(",") for p in sorted(Path(d).glob("*/checkpoint.pt"))
            if (p.parent / "policy.pt").is_file()]
    if not runs:
        sys.exit(f"no <run>/checkpoint.pt with a policy.pt under {args.runs}")
    scenarios = args.scenarios.split(",")
    jobs = [(f"{run.name}{'' if r is None else f'@critic{r:g}'}", str(run), r, scenarios, args.episodes, args.seed)
            for run in runs for r in [None, *radii]]
    with process_pool(args.jobs) as pool:
        scored = dict(pool.map(score, jobs))
    plain = {run.name: scored[run.name]["sum"] for run in runs}
    by_radius = {}
    for r in radii:
        # paired by run: keyed x_s<index of the run>, so every run pairs with its own plain policy
        guided = {f"x_s{i}": scored[f"{run.name}@critic{r:g}"]["sum"] for i, run in enumerate(runs)}
        by_radius[f"{r:g}"] = paired_difference(guided, {f"x_s{i}": plain[run.name] for i, run in enumerate(runs)})
    result = {"command": command_line("critic_guided_acting.py", argv),
              "episodes_per_scenario": args.episodes, "seed": args.seed, "scenarios": scenarios, "grid": GRID,
              "guided_minus_plain": by_radius, "runs": scored}
    write_result(args.json, result)
    return result


if __name__ == "__main__":
    main()
