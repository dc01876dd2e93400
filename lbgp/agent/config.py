"""D4PG and training configuration, with the reason for each default.

Reference: acme's D4PG defaults (n_step 5, discount 0.99, batch 256, learning rate 1e-4,
sigma 0.3, target update period 100, 51 atoms over [-150, 150]). Where we differ, it is said why.
"""

from __future__ import annotations

import dataclasses
import json


@dataclasses.dataclass
class D4PGConfig:
    # --- what is trained
    method: str = "lbgp"  # lbgp: policy outputs a goal (planner drives); e2e: policy outputs (v, w)
    robot: str = "jackal"
    curriculum: bool = True  # False: train on the final level from the start (the paper's ablation)
    seed: int = 0
    horizon: int = 35  # agent steps per episode

    # --- budget
    total_steps: int = 300_000  # environment (agent) steps collected by all actors together
    time_limit_s: float = 0.0  # stop after this wall time too (0: no limit)

    # --- actors
    num_actors: int = 4  # the paper: 3 exploring + 1 exploiting
    num_exploit: int = 1  # actors without noise; their returns are the learning curve
    sigma: float = 0.3  # Gaussian exploration noise on the [-1, 1] action (acme)
    weight_sync_steps: int = 200  # actors fetch fresh weights at least this often (agent steps)
    earlier_level_share: float = 0.2  # share of exploring episodes on an earlier curriculum level
    actor_niceness: int = 10  # actors run at lower priority: the learner keeps ~1 core on a 2-core box

    # --- learner
    n_step: int = 5  # (acme)
    discount: float = 0.97  # acme 0.99; 0.97 (effective horizon ~33 steps) matches 35-step episodes
    batch_size: int = 128  # acme 256; halves the learner cost on a 2-core CPU
    actor_lr: float = 3e-4  # acme 1e-4; 3e-4 learns faster within the ~100k updates a 2-core budget allows
    critic_lr: float = 3e-4  # (as the actor)
    target_update_period: int = 100  # hard target update every N learner steps (acme)
    target_tau: float = 0.0  # > 0: soft (Polyak) target update by this much every step instead of hard updates
    prior_weight: float = 1.0  # LBGP only (not in the paper): the actor loss adds this * |a - a_ahead|^2,
    # a_ahead = the goal 1.5 m ahead. Keeps goals near the sensible default wherever the critic has no
    # clear preference (without it the goals jump step to step); 0 = plain D4PG. E2E: always 0.
    num_atoms: int = 51  # (acme)
    v_min: float = -30.0  # acme [-150, 150] is for rewards ~1/step over 1000 steps; here rewards are in
    v_max: float = 30.0  # [-1, 1] and 1 / (1 - 0.97) = 33: +-30 covers every discounted return
    hidden: tuple = (128, 128)  # actor and critic MLP sizes (acme: 256-512 wide; CPU budget here)
    grad_clip: float = 40.0  # global-norm clip (acme)
    replay_capacity: int = 500_000
    min_replay: int = 2_000  # learning starts after this many transitions (acme 1,000)
    max_updates_per_step: float = 1.0  # learner never runs more updates than env steps collected

    # --- curriculum (see lbgp/agent/curriculum.py)
    level_thresholds: tuple = (15.0, 12.0, 8.0)  # exploit return (mean over the window) to advance
    level_budget_fraction: tuple = (0.15, 0.2, 0.25)  # ... or after this share of total_steps (and of
    # time_limit_s, if set) per level; the rest goes to the final level
    curriculum_window: int = 10  # exploit episodes averaged

    # --- files
    checkpoint_every_s: float = 120.0
    torch_threads: int = 1  # per process: the learner and each actor

    def validate(self) -> "D4PGConfig":
        if self.method not in ("lbgp", "e2e"):
            raise ValueError(f"method must be 'lbgp' or 'e2e', got {self.method!r}")
        if not 0 <= self.num_exploit <= self.num_actors or self.num_actors < 1:
            raise ValueError(f"need 1+ actors and at most that many exploiting ones, got {self.num_actors}/{self.num_exploit}")
        if self.v_min >= self.v_max or self.num_atoms < 2:
            raise ValueError("the value support needs v_min < v_max and at least 2 atoms")
        if not self.prior_weight >= 0:
            raise ValueError(f"prior_weight must be >= 0, got {self.prior_weight}")
        if self.n_step < 1 or not 0 < self.discount <= 1:
            raise ValueError("n_step must be >= 1 and discount in (0, 1]")
        return self

    @property
    def control(self) -> str:
        return "goal" if self.method == "lbgp" else "velocity"

    def to_json(self) -> str:
        return json.dumps(dataclasses.asdict(self), indent=2)

    @classmethod
    def from_dict(cls, data: dict) -> "D4PGConfig":
        known = {f.name for f in dataclasses.fields(cls)}
        unknown = set(data) - known
        if unknown:
            raise ValueError(f"unknown training config keys: {sorted(unknown)}")
        data = {k: tuple(v) if isinstance(v, list) else v for k, v in data.items()}
        return cls(**data).validate()
