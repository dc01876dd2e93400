"""D4PG and training configuration, with the reason for each default.

Reference: acme's D4PG defaults (n_step 5, discount 0.99, batch 256, learning rate 1e-4,
sigma 0.3, target update period 100, 51 atoms over [-150, 150]). Where we differ, it is said why.
"""

from __future__ import annotations

import dataclasses
import json
import math

from lbgp.planner.config import changes_from_text


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
    num_actors: int = 2  # the paper: 3 exploring + 1 exploiting; on a 2-core machine the learner takes
    # one core and one exploring + one exploiting actor the other (more actors thrash the caches)
    num_exploit: int = 1  # actors without noise; their returns are the learning curve
    sigma: float = 0.15  # Gaussian exploration noise on the [-1, 1] action (acme and the paper: 0.3, white);
    # 0.15 = 0.3 m of goal: within the residual's +-0.75 m, an exploring goal still lands near a useful one
    noise_correlation: float = 0.8  # AR(1) coefficient of the exploration noise per agent step (0: white,
    # the paper). Correlated noise holds a deviation for ~1 s, long enough for the planner to act on it;
    # white noise of 0.2 s per value mostly averages out in the robot's motion. Stationary std = sigma.
    # Over 3 seeds, white noise with sigma 0.3 scored 10.5 +- 8.6 lower (separated); sigma 0.3 with this
    # correlation 4.2 +- 3.8 lower (separated); white noise of sigma 0.15 4.8 +- 9.7 lower (not separated);
    # sigma 0.1 3.2 +- 3.7 lower and correlation 0.9 0.9 +- 4.7 lower (neither separated).
    weight_sync_steps: int = 200  # actors fetch fresh weights at least this often (agent steps)
    earlier_level_share: float = 0.2  # share of exploring episodes on an earlier curriculum level
    actor_niceness: int = 10  # actors run at lower priority: the learner keeps ~1 core on a 2-core box

    # --- learner
    n_step: int = 5  # (acme); 10 over 3 seeds: 1.2 +- 4.8 lower on the paper scenarios (not separated)
    discount: float = 0.97  # acme 0.99; 0.97 (effective horizon ~33 steps) matches 35-step episodes
    # 0.9 over 3 seeds: 0.2 +- 3.7 lower on the paper scenarios (not separated; docs/ablations.md)
    batch_size: int = 256  # (acme)
    actor_lr: float = 3e-4  # acme 1e-4; 3e-4 learns faster within the ~100k updates a 2-core budget allows
    # (1e-4 for both over 3 seeds: +0.1 +- 3.4 on the paper scenarios, not separated; docs/ablations.md)
    critic_lr: float = 3e-4  # (as the actor)
    target_update_period: int = 100  # hard target update every N learner steps (acme)
    # (soft updates, target_tau 0.005, over 3 seeds: 0.4 +- 3.7 lower on the paper scenarios; a period of 20:
    # 1.7 +- 5.6 lower; neither separated; docs/ablations.md)
    target_tau: float = 0.0  # > 0: soft (Polyak) target update by this much every step instead of hard updates
    policy_average: float = 0.0  # > 0: the policy file holds an exponential moving average of the actor's
    # weights, moved this much toward the actor after every update from the end of the actor warm-up
    # (1e-4: a window of ~10k updates); the run also keeps the last raw actor as policy_last.pt. Training
    # itself (actors, targets, curve) is unchanged. 0: the policy file is the last actor (the paper).
    # Measured at 1e-4 over 3 seeds (docs/ablations.md): the average minus the last actor of the same run
    # -1.5 +- 6.6 summed over the paper scenarios (not separated), so it stays off
    prior_weight: float = 1.0  # LBGP only (not in the paper): the actor loss adds this * |a - a_ahead|^2,
    # a_ahead = the goal 1.5 m ahead. Keeps goals near the sensible default wherever the critic has no
    # clear preference (without it the goals jump step to step); 0 = plain D4PG. E2E: always 0.
    # Over 3 seeds, 0.3 scored 4.8 +- 5.9 and 3 scored 0.9 +- 7.1 lower (neither separated; docs/ablations.md)
    num_atoms: int = 51  # (acme)
    v_min: float = -30.0  # acme [-150, 150] is for rewards ~1/step over 1000 steps; here rewards are in
    v_max: float = 30.0  # [-1, 1] and 1 / (1 - 0.97) = 33: +-30 covers every discounted return
    hidden: tuple = (128, 128)  # actor and critic MLP sizes (acme: 256-512 wide; CPU budget here)
    # (256-256 over 3 seeds at equal wall time, half the updates: 1.0 +- 3.7 lower, not separated; docs/ablations.md)
    grad_clip: float = 40.0  # global-norm clip (acme)
    replay_capacity: int = 500_000
    priority_exponent: float = 0.0  # > 0: prioritised replay for the critic (lbgp.agent.prioritized_replay;
    # Schaul et al.: 0.6), transitions drawn in proportion to (critic loss + 1e-3) ** this; the actor
    # learns from a uniform batch. 0: uniform replay (acme's D4PG, the paper). Off: over 3 seeds 0.6
    # scored 2.0 +- 6.9 lower on the paper scenarios (not separated; docs/ablations.md)
    priority_correction: float = 0.4  # importance-weight exponent of prioritised replay (Schaul et al.: 0.4,
    # held fixed here: a run's length in wall time is not known in advance to anneal it to 1)
    min_replay: int = 2_000  # learning starts after this many transitions (acme 1,000)
    max_updates_per_step: float = 2.0  # the learner runs at most this many updates per env step
    # collected (the actors are planner-bound at ~100 steps/s, the learner does ~240 updates/s at batch 256)

    actor_warmup_updates: int = 5_000  # the actor stays fixed for the critic's first updates: a random
    # critic's gradient would push a residual actor off its base goal before anything was learnt (0: paper)
    # Over 3 seeds, 0 scored 3.6 +- 9.6 lower: not separated, kept as the default (docs/ablations.md).

    # --- LBGP's goal policy (see lbgp/agent/networks.py and docs/training.md)
    residual_scale: float = 0.375  # > 0: the actor outputs the goal 1.5 m ahead plus a residual bounded by
    # this (action units: 0.375 = 0.75 m), its last layer initialised to zero; 0 = the paper's plain actor.
    # E2E: always plain. Over 3 seeds a plain actor trailed by 8.2 +- 16.2 on the paper scenarios (not separated)
    # and a wider residual (0.5: +-1.0 m) by 1.6 +- 3.6 (not separated): docs/ablations.md
    turn_lead: float = 0.0  # m per rad/s: the residual's base goal moves this much farther ahead per
    # rad/s of the person's turn rate seen in the observation (a turn-aware base); 0 = the goal 1.5 m ahead
    motion_features: bool = False  # actor and critic also see the person's velocity and turn rate and the
    # robot's velocity, read linearly off the observation (lbgp.sim.observation.motion_feature_weights);
    # the observation itself, and so the deploy loop, is unchanged. Off: measured over 3 seeds, docs/ablations.md
    previous_goal: bool = False  # actor and critic also see the action sent one step before (the previous
    # goal; lbgp.agent.previous_goal): the policy's only memory, carried by Policy between act calls.
    # Off: over 3 seeds it lost 6.5 +- 5.8 on the paper scenarios (160.3 vs 166.8; docs/ablations.md)
    normalize_obs: bool = True  # standardise the observation (mean/std of the first min_replay transitions);
    # over 3 seeds raw inputs scored 1.0 +- 5.7 higher (not separated): on because the shipped policy has it
    randomize: dict = dataclasses.field(default_factory=dict)  # domain randomisation ranges per episode
    # (lbgp.dynamics.Randomization as a dict; `lbgp train --randomize PRESET|FILE` fills it); {}: none
    mirror_augment: bool = False  # also store every transition's mirror image about the person's heading
    # line in the replay (observation and next observation mirrored, the action's lateral part negated,
    # same return): the task is symmetric, so each episode teaches both turn directions. Off: over 3
    # seeds it did not beat mirror-averaged acting alone (166.1 vs 168.2 on the paper scenarios; docs/ablations.md)
    drawn_paths: bool = False  # the trajectories level draws a fresh person path every episode
    # (lbgp.sim.tasks.drawn_paths_setting) instead of walking one of the library's 20
    # Off: over 3 seeds it scored 0.2 +- 5.4 lower on the paper scenarios (not separated; docs/ablations.md)
    planner_sqp_iterations: int = 0  # the planner's SQP iterations per band in training (0: the robot's
    # preset, 3); 1 is a stateless real-time iteration, ~2x faster (docs/planner.md, "The SQP iteration
    # cap"). The policy file records it (``planner_changes``) and is evaluated, demonstrated and deployed on that planner.
    train_planner_changes: str = ""  # planner settings the actors' planners change in training only, as
    # NAME=VALUE pairs (lbgp.planner.config.changes_from_text), e.g. "weight_turn=0.05,lateral_acc_limit_clear=none":
    # the two Jackal planner settings the shipped policy was trained with (before 2026-12-05's lateral acceleration ramp and
    # 2026-12-06's turn-rate weight). Unlike planner_sqp_iterations the policy file does not record them: the
    # policy acts on the preset. For testing whether a policy gains from training on another planner (docs/ablations.md)
    critic_future: bool = False  # the critic (only) also sees the episode's next second in hindsight: the
    # person's true poses 0.2-1 s later and the robot's true pose, in the person's current frame
    # (lbgp.agent.critic_future, an asymmetric actor-critic); the actor and the policy file are unchanged
    # Off: over 3 seeds it scored 0.8 +- 6.4 lower on the paper scenarios (not separated; docs/ablations.md)
    spawn_front_share: float = 0.75  # share of training spawns in front of the person (|alpha| < 90 deg);
    # 0.5 = uniform all around (the paper). Evaluation always uses the uniform spawn. Over 3 seeds uniform
    # spawns trailed by 3.2 +- 6.1 on the paper scenarios (not separated; docs/ablations.md)

    init_policy: str = ""  # a policy file whose actor (weights and input standardisation) starts the run
    # (fine-tuning, lbgp.agent.fine_tune; `lbgp train --init-policy FILE`); "": a freshly initialised actor

    # --- curriculum (see lbgp/agent/curriculum.py)
    level_thresholds: tuple = (15.0, 12.0, 8.0)  # exploit return (mean over the window) to advance
    level_budget_fraction: tuple = (0.15, 0.2, 0.25)  # ... or after this share of total_steps (and of
    # time_limit_s, if set) per level; the rest goes to the final level
    curriculum_window: int = 10  # exploit episodes averaged

    # --- files
    checkpoint_every_s: float = 120.0
    snapshot_every_s: float = 0.0  # > 0: also write the policy file every this many seconds of the run's
    # wall time to snapshots/policy_<seconds>s.pt (a run's history of actors, for choosing one afterwards:
    # benchmarks/snapshot_selection.py); 0: only the final policy.pt. Training is unchanged either way.
    # Choosing by held-out training-level episodes over 3 runs: +0.17 +- 3.45 vs the last actor (docs/ablations.md)
    torch_threads: int = 1  # per process: the learner and each actor

    def validate(self) -> "D4PGConfig":
        if self.method not in ("lbgp", "e2e"):
            raise ValueError(f"method must be 'lbgp' or 'e2e', got {self.method!r}")
        if not 0 <= self.num_exploit <= self.num_actors or self.num_actors < 1:
            raise ValueError(f"need 1+ actors and at most that many exploiting ones, got {self.num_actors}/{self.num_exploit}")
        if not (math.isfinite(self.v_min) and math.isfinite(self.v_max) and self.v_min < self.v_max):
            raise ValueError(f"the value support needs finite v_min < v_max, got v_min={self.v_min}, v_max={self.v_max}")
        if not 2 <= self.num_atoms <= 1001:
            raise ValueError(f"num_atoms must be from 2 to 1001, got {self.num_atoms}")
        if self.randomize:
            from lbgp.dynamics import Randomization

            Randomization.from_dict(self.randomize, where="training config 'randomize'")
        if not (math.isfinite(self.snapshot_every_s) and (self.snapshot_every_s == 0.0 or self.snapshot_every_s >= 1.0)):
            raise ValueError(f"snapshot_every_s must be 0 (off) or at least 1 s, got {self.snapshot_every_s}")
        if not 0.0 <= self.spawn_front_share <= 1.0:
            raise ValueError(f"spawn_front_share must be in [0, 1], got {self.spawn_front_share}")
        if not 0.0 <= self.noise_correlation < 1.0:
            raise ValueError(f"noise_correlation must be in [0, 1), got {self.noise_correlation}")
        if not 0.0 <= self.residual_scale <= 2.0:
            raise ValueError(f"residual_scale must be in [0, 2], got {self.residual_scale}")
        if not 0.0 <= self.turn_lead <= 5.0:
            raise ValueError(f"turn_lead must be in [0, 5] m per rad/s, got {self.turn_lead}")
        if self.turn_lead > 0 and self.residual_scale == 0:
            raise ValueError("turn_lead moves a residual actor's base goal: it needs residual_scale > 0 (not --paper)")
        if not self.max_updates_per_step > 0:
            raise ValueError(f"max_updates_per_step must be > 0, got {self.max_updates_per_step}")
        if not 0.0 <= self.policy_average < 1.0:
            raise ValueError(f"policy_average must be in [0, 1), got {self.policy_average}")
        if not self.prior_weight >= 0:
            raise ValueError(f"prior_weight must be >= 0, got {self.prior_weight}")
        if self.n_step < 1 or not 0 < self.discount <= 1:
            raise ValueError("n_step must be >= 1 and discount in (0, 1]")
        if not 0.0 <= self.sigma <= 2.0:
            raise ValueError(f"sigma must be in [0, 2] (action units), got {self.sigma}")
        if not 1 <= self.batch_size <= 65_536:
            raise ValueError(f"batch_size must be from 1 to 65536, got {self.batch_size}")
        for name in ("actor_lr", "critic_lr"):
            if not 0.0 < getattr(self, name) < 1.0:
                raise ValueError(f"{name} must be in (0, 1), got {getattr(self, name)}")
        if self.critic_future and self.mirror_augment:
            raise ValueError("critic_future and mirror_augment cannot be combined (the hindsight features are not mirrored)")
        if not (0.0 <= self.priority_exponent <= 1.0 and 0.0 <= self.priority_correction <= 1.0):
            raise ValueError(f"priority_exponent and priority_correction must be in [0, 1], got {self.priority_exponent}, {self.priority_correction}")
        if not (len(self.hidden) >= 1 and all(isinstance(h, int) and 1 <= h <= 4096 for h in self.hidden)):
            raise ValueError(f"hidden must be 1+ layer sizes from 1 to 4096, got {self.hidden}")
        if self.target_update_period < 1 or not 0.0 <= self.target_tau <= 1.0:
            raise ValueError(f"target_update_period must be >= 1 and target_tau in [0, 1], got {self.target_update_period}, {self.target_tau}")
        if not 0 <= self.planner_sqp_iterations <= 50:
            raise ValueError(f"planner_sqp_iterations must be from 0 (the preset) to 50, got {self.planner_sqp_iterations}")
        try:
            training_only = changes_from_text(self.train_planner_changes)
        except ValueError as error:
            raise ValueError(f"train_planner_changes: {error}") from None
        if "sqp_iterations" in training_only:
            raise ValueError("train_planner_changes: sqp_iterations is set with planner_sqp_iterations "
                             "(the policy file records it, so the policy acts with the cap it was trained on)")
        if self.actor_warmup_updates < 0:
            raise ValueError(f"actor_warmup_updates must be >= 0, got {self.actor_warmup_updates}")
        return self

    def planner_changes(self) -> dict:
        """The planner settings the actors' environments change from the robot's preset ({}: none);
        the policy file records them, and evaluation, the demo and deploy drive with them."""
        return {"sqp_iterations": self.planner_sqp_iterations} if self.planner_sqp_iterations else {}

    def training_planner_changes(self) -> dict:
        """The planner settings the actors' environments drive with in training: ``planner_changes()``
        plus the training-only ``train_planner_changes`` (which the policy file does not record)."""
        return {**self.planner_changes(), **changes_from_text(self.train_planner_changes)}

    # the fields `lbgp train --set NAME=VALUE` may change: the design choices of docs/training.md's
    # defaults table that have no option of their own, so that each can be ablated from the command line
    SETTABLE = ("sigma", "noise_correlation", "spawn_front_share", "residual_scale", "normalize_obs",
                "actor_warmup_updates", "drawn_paths", "batch_size", "actor_lr", "critic_lr", "n_step", "discount",
                "critic_future", "snapshot_every_s", "priority_exponent", "priority_correction", "hidden",
                "target_update_period", "target_tau", "num_atoms", "v_min", "v_max", "planner_sqp_iterations",
                "train_planner_changes")

    @classmethod
    def parse_setting(cls, text: str) -> tuple[str, object]:
        """``"sigma=0.3"`` -> ``("sigma", 0.3)``: a field of ``SETTABLE`` and a value of its type that
        passes ``validate`` on its own; ValueError naming the problem otherwise."""
        name, sep, raw = text.partition("=")
        name, raw = name.strip(), raw.strip()
        if not sep or not name or not raw:
            raise ValueError(f"expected NAME=VALUE, got {text!r}")
        if name not in cls.SETTABLE:
            raise ValueError(f"{name!r} cannot be set; one of {', '.join(cls.SETTABLE)}")
        kind = type(getattr(cls(), name))
        if kind is bool:
            words = {"true": True, "on": True, "1": True, "false": False, "off": False, "0": False}
            if raw.lower() not in words:
                raise ValueError(f"{name} takes true or false, got {raw!r}")
            value = words[raw.lower()]
        elif kind is tuple:  # layer sizes: "256,256" (or "256x256")
            try:
                value = tuple(int(part) for part in raw.replace("x", ",").split(","))
            except ValueError:
                raise ValueError(f"{name} takes layer sizes like 256,256, got {raw!r}") from None
        else:
            try:
                value = kind(raw)
            except ValueError:
                raise ValueError(f"{name} takes {'an integer' if kind is int else 'a number'}, got {raw!r}") from None
            if kind is float and not math.isfinite(value):
                raise ValueError(f"{name} takes a finite number, got {raw!r}")
        cls(**{name: value}).validate()
        return name, value

    @classmethod
    def paper(cls, **overrides) -> "D4PGConfig":
        """The paper's plain configuration (`lbgp train --paper`): tanh actor on the raw observation,
        no goal prior, uniform spawns, white exploration noise of 0.3, batch 128, one update per step."""
        plain = dict(residual_scale=0.0, turn_lead=0.0, motion_features=False, previous_goal=False, normalize_obs=False, spawn_front_share=0.5, noise_correlation=0.0,
                     sigma=0.3, prior_weight=0.0, batch_size=128, max_updates_per_step=1.0,
                     actor_warmup_updates=0)
        return cls(**{**plain, **overrides})

    @property
    def actor_residual_scale(self) -> float:
        """The residual bound the actor is built with (E2E acts on velocities: always plain)."""
        return self.residual_scale if self.method == "lbgp" else 0.0

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
