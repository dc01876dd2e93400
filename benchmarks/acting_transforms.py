"""A trained LBGP policy acting through a transform of its goals: a gain on its residual (all of it or
its lateral part), a lead on its goal, input smoothing.

    python benchmarks/acting_transforms.py --gains 0.75,1,1.25,1.5 --leads 0.5 --seed 500 --jobs 2 \
        --json results/acting_transforms_seed500.json
    python benchmarks/acting_transforms.py --lateral-gains 1.25,1.5,1.75,2 --seed 500 --jobs 2 \
        --json results/lateral_gain_seed500.json
    python benchmarks/acting_transforms.py --input-noise 1,2 --copies 16 --seed 500 --jobs 2 \
        --json results/input_smoothing_seed500.json

Asks, without training, whether the shipped policy's goals are the right size and come at the right
time. Each transform wraps the policy as a user gets it (``lbgp.policies.make_policy``: goal dead
band and mirror-averaged acting included) and changes only the goal it sends to the planner:

* ``gain k``: goal = base + k * (goal - base), the residual around the actor's base goal scaled
  (k = 1: the policy itself). The goal prior pulls the residual toward zero in training, and the
  searched goals that react after a turn shows swing wider than LBGP's (docs/ceilings.md), so a
  larger residual might pay.
* ``lateral gain k``: only the residual's lateral part (y, the person frame's left) scaled by k, its
  part along the person's heading kept: the searched goals swing wider, not farther ahead.
* ``lead b``: goal_t + b * (goal_t - goal_{t-1}), a first-order lead on the goal sequence (b = 0: the
  policy itself). The searched goals on trajectory_three move two to three steps before LBGP's.
* ``--input-noise m --copies K``: the mean goal over K copies of the observation, each with extra
  Gaussian noise of m times the observation noise (0.03 m, 0.03 rad; seeded, the same draws every
  episode), the dead band once on the mean: the policy smoothed over its input (randomised
  smoothing), which might steady its answer to the observation noise.

Every variant and HC are scored on the same sim-table episodes as ``benchmarks/ablation_scenarios.py``
scores runs (20 noisy episodes per scenario, Jackal, ``--seed``): use a seed other than the sim
table's 0 to judge on held-out episodes. Reported per variant: each row, the 9-row sum and the
turning and trajectory rows' sums minus HC's.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, write_result  # noqa: E402

import numpy as np  # noqa: E402
import torch  # noqa: E402

from ablation_scenarios import sim_table_rewards  # noqa: E402
from policy_ensemble import deadband_once  # noqa: E402
from lbgp.actions import action_from_goal, goal_from_action  # noqa: E402
from lbgp.agent.policy import GOAL_DEADBAND_M  # noqa: E402
from lbgp.experiments.sim_table import LEAD_ROWS  # noqa: E402
from lbgp.parallel import process_pool  # noqa: E402
from lbgp.planner import planner_config_for  # noqa: E402
from lbgp.policies import default_policy_path, make_policy  # noqa: E402
from lbgp.sim import observation as obs_lib  # noqa: E402
from lbgp.sim import scenario_names  # noqa: E402


class TransformedGoalPolicy:
    """``policy``'s goals with its residual scaled by ``gain`` (its lateral part by ``gain * lateral_gain``)
    and a lead ``lead`` on their sequence."""

    control = "goal"

    def __init__(self, policy, gain: float = 1.0, lead: float = 0.0, lateral_gain: float = 1.0):
        if getattr(policy, "control", None) != "goal":
            raise ValueError("acting transforms change a goal policy's goals; this policy sends velocities")
        if not (np.isfinite(gain) and np.isfinite(lead) and np.isfinite(lateral_gain)):
            raise ValueError(f"gains and lead must be finite, got {gain!r}, {lateral_gain!r} and {lead!r}")
        self.policy, self.gain, self.lead = policy, float(gain), float(lead)
        self.scale = np.array([1.0, float(lateral_gain)]) * self.gain  # on the residual's (x, y)
        self._scaled = bool(np.any(self.scale != 1.0))
        self._previous = None

    def reset(self) -> None:
        self._previous = None
        self.policy.reset()

    def act(self, observation) -> np.ndarray:
        base = self.policy.base_goal(observation) if self._scaled else None  # before act: it reads the previous goal
        goal = goal_from_action(self.policy.act(observation))
        if base is not None:
            goal = base + self.scale * (goal - base)
        sent = goal if self._previous is None else goal + self.lead * (goal - self._previous)
        self._previous = goal
        return action_from_goal(sent).astype(np.float32)


# one standard deviation of the observation noise, per entry of the scaled observation
_OBSERVATION_NOISE = obs_lib.scale(np.tile([obs_lib.DEFAULT_NOISE_STD[0]] * 2 + [obs_lib.DEFAULT_NOISE_STD[1]], obs_lib.SIZE // 3))


class InputSmoothedPolicy:
    """A residual goal policy (``policy_file``, mirror-averaged as shipped) acting on its mean goal over
    ``copies`` copies of the observation, each with extra Gaussian noise of ``multiple`` times the
    observation noise (drawn from ``seed`` afresh at every ``reset``), the dead band once on the mean."""

    control = "goal"

    def __init__(self, policy_file, multiple: float, copies: int, seed: int = 12345, robot: str = "jackal"):
        if not (np.isfinite(multiple) and multiple >= 0.0) or copies < 1:
            raise ValueError(f"input smoothing needs a finite noise multiple >= 0 and copies >= 1, got {multiple!r}, {copies!r}")
        self.policy = make_policy("lbgp", policy_file, robot=robot, goal_deadband=0.0)
        if self.policy.actor.residual_scale <= 0:
            raise ValueError("input smoothing applies the dead band around the base goal of a residual goal policy")
        self.multiple, self.copies, self.seed = float(multiple), int(copies), int(seed)
        self.reset()

    def reset(self) -> None:
        self._rng = np.random.default_rng(self.seed)
        self.policy.reset()

    @torch.no_grad()
    def act(self, observation) -> np.ndarray:
        obs = np.asarray(observation, np.float32)
        noise = self._rng.standard_normal((self.copies, obs.size)).astype(np.float32)
        copies = np.clip(obs + self.multiple * _OBSERVATION_NOISE * noise, -1.0, 1.0)
        goal = np.mean([goal_from_action(self.policy.act(c)) for c in copies], axis=0)
        return deadband_once(self.policy, obs, goal, GOAL_DEADBAND_M)


def variant_name(gain: float, lead: float, lateral_gain: float = 1.0) -> str:
    return f"gain{gain:g}_lead{lead:g}" + (f"_lateral{lateral_gain:g}" if lateral_gain != 1.0 else "")


def smoothing_name(multiple: float, copies: int) -> str:
    return f"input_noise{multiple:g}_copies{copies}"


def numbers(text: str, flag: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise SystemExit(f"{flag} takes comma-separated numbers, got {text!r}") from None
    if not values or not all(np.isfinite(values)):
        raise SystemExit(f"{flag} takes comma-separated finite numbers, got {text!r}")
    return values


def score(job: tuple) -> tuple[str, dict]:
    """job: (name, method, policy_file, (gain, lead, lateral gain), scenarios, episodes, seed[, (noise multiple,
    copies)]); method hc scores HC."""
    name, method, policy_file, (gain, lead, lateral_gain), scenarios, episodes, seed, *smoothing = job
    if smoothing:
        policy = InputSmoothedPolicy(policy_file, *smoothing[0])
    else:
        policy = make_policy(method, policy_file, robot="jackal")
        if method == "lbgp":
            policy = TransformedGoalPolicy(policy, gain, lead, lateral_gain)
    per_scenario = sim_table_rewards(policy, method, scenarios, episodes, seed, planner_config_for("jackal", None))
    row = {"gain": gain, "lead": lead, "per_scenario": per_scenario, "sum": round(sum(per_scenario.values()), 3)}
    if lateral_gain != 1.0:
        row["lateral_gain"] = lateral_gain
    if smoothing:
        row["input_noise"], row["copies"] = smoothing[0]
    return name, row


def rows_minus(per_scenario: dict, hc: dict, rows) -> float | None:
    names = [r for r in rows if r in per_scenario]
    return round(sum(per_scenario[r] - hc[r] for r in names), 3) if names else None


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--policy", help="an LBGP policy file (default: the shipped Jackal policy)")
    ap.add_argument("--gains", default="1", help="comma-separated gains on the residual (1: none)")
    ap.add_argument("--leads", default="0", help="comma-separated leads on the goal sequence (0: none)")
    ap.add_argument("--lateral-gains", default="1", help="comma-separated gains on the residual's lateral part alone (1: none)")
    ap.add_argument("--input-noise", default="", metavar="M",
                    help="comma-separated multiples of the observation noise: act on the mean goal over --copies noisy copies")
    ap.add_argument("--copies", type=int, default=16, help="observation copies per step with --input-noise (default 16)")
    ap.add_argument("--scenarios", default=",".join(scenario_names()), help="comma-separated (default: the 9 paper scenarios)")
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--json", default="results/acting_transforms.json")
    args = ap.parse_args(argv)
    gains, leads = numbers(args.gains, "--gains"), numbers(args.leads, "--leads")
    lateral_gains = numbers(args.lateral_gains, "--lateral-gains")
    multiples = numbers(args.input_noise, "--input-noise") if args.input_noise else []
    if any(m < 0 for m in multiples) or args.copies < 1:
        ap.error(f"--input-noise takes multiples >= 0 and --copies at least 1, got {args.input_noise!r} and {args.copies}")
    scenarios = args.scenarios.split(",")
    unknown = sorted(set(scenarios) - set(scenario_names()))
    if unknown:
        ap.error(f"unknown scenarios {unknown}; known: {', '.join(scenario_names())}")
    if args.episodes < 1:
        ap.error(f"--episodes must be at least 1, got {args.episodes}")
    policy_file = args.policy or os.path.relpath(default_policy_path("lbgp", "jackal"))
    # the policy itself (gain 1, lead 0) always; then each gain, each lead and each lateral gain alone
    none = (1.0, 0.0, 1.0)
    transforms = dict.fromkeys([none] + [(g, 0.0, 1.0) for g in gains] + [(1.0, b, 1.0) for b in leads]
                               + [(1.0, 0.0, k) for k in lateral_gains])
    jobs = [("HC", "hc", None, none, scenarios, args.episodes, args.seed)]
    jobs += [(variant_name(*t), "lbgp", policy_file, t, scenarios, args.episodes, args.seed) for t in transforms]
    jobs += [(smoothing_name(m, args.copies), "lbgp", policy_file, none, scenarios, args.episodes, args.seed, (m, args.copies))
             for m in dict.fromkeys(multiples)]
    with process_pool(args.jobs) as pool:
        scored = dict(pool.map(score, jobs))
    hc = scored.pop("HC")["per_scenario"]
    for row in scored.values():
        row["turning_minus_hc"] = rows_minus(row["per_scenario"], hc, LEAD_ROWS["turning"])
        row["trajectories_minus_hc"] = rows_minus(row["per_scenario"], hc, LEAD_ROWS["trajectory"])
    result = {"command": command_line("acting_transforms.py", argv), "policy": policy_file,
              "episodes_per_scenario": args.episodes, "seed": args.seed, "scenarios": scenarios,
              "hc": {"per_scenario": hc, "sum": round(sum(hc.values()), 3)}, "variants": scored}
    write_result(args.json, result)
    return result


if __name__ == "__main__":
    main()
