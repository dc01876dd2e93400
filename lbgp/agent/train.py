"""Training: the learner loop in this process, actors in others, curriculum, files, resume.

A run directory holds:

    config.json       the D4PGConfig of the run
    curve.csv         learning curve: env_steps, wall_time_s, level, exploit_return (one row per
                      exploiting episode)
    checkpoint.pt     learner, replay, counters, curriculum and RNG state (atomic; every
                      ``checkpoint_every_s`` and at the end or on Ctrl-C / SIGTERM)
    policy.pt         the final policy file (see lbgp.agent.policy): the last actor, or with
                      ``policy_average`` the moving average of its weights
    policy_last.pt    with ``policy_average`` only: the last actor
    snapshots/        with ``snapshot_every_s`` > 0: ``policy_<seconds>s.pt``, the policy file as it
                      was at that wall time of the run (its meta: env steps, updates, level), for
                      choosing an actor afterwards (benchmarks/snapshot_selection.py)
    summary.json      final counters and returns
    run.lock          held by the training process that uses the folder (a second one is refused)

``--resume DIR`` removes temporary files a killed run left (``*.tmp``), reloads checkpoint.pt,
drops curve rows newer than it, and continues.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import os
import signal
import time
from pathlib import Path

import numpy as np
import torch

from lbgp.agent.actors import InlineActors, ProcessActors, flat_parameters
from lbgp.agent.checkpoint import load_checked, save_atomic
from lbgp.files import atomic_file, write_json
from lbgp.agent.config import D4PGConfig
from lbgp.agent.curriculum import Curriculum
from lbgp.agent.fine_tune import start_from_policy
from lbgp.agent.learner import D4PGLearner
from lbgp.agent.policy import save_policy
from lbgp.agent.previous_goal import agent_input_size
from lbgp.agent.prioritized_replay import PrioritizedReplayBuffer
from lbgp.agent.replay import ReplayBuffer, mirrored

CHECKPOINT_FORMAT = "lbgp-checkpoint"
CURVE_HEADER = ["env_steps", "wall_time_s", "level", "exploit_return"]


class Stop(Exception):
    """Raised by the SIGTERM handler so that the run checkpoints and stops cleanly."""


def read_curve(path: str | os.PathLike) -> list[dict]:
    """Rows of a curve.csv; a half-written last line (killed run) is ignored."""
    rows = []
    path = Path(path)
    if not path.is_file():
        return rows
    with path.open(newline="") as f:
        for row in csv.DictReader(f):
            try:
                rows.append({"env_steps": int(row["env_steps"]), "wall_time_s": float(row["wall_time_s"]),
                             "level": row["level"], "exploit_return": float(row["exploit_return"])})
            except (TypeError, ValueError, KeyError):
                continue
    return rows


class RunLock:
    """``run.lock`` in the run folder, held (flock) for as long as a training process uses the
    folder: a second ``lbgp train`` on the same folder is refused from the first moment, and a lock
    left by a killed run (no process holds it any more) is taken over."""

    def __init__(self, run_dir: Path):
        import fcntl

        self.path = Path(run_dir) / "run.lock"
        if not self.path.parent.is_dir():
            raise FileNotFoundError(f"{self.path.parent}: no such run folder")
        self._file = self.path.open("a+")
        try:
            fcntl.flock(self._file, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            self._file.seek(0)
            holder = self._file.read().strip() or "?"
            self._file.close()
            raise ValueError(f"{self.path.parent} is in use by another lbgp train (pid {holder}); wait for it or pick another --out") from None
        self._file.seek(0)
        self._file.truncate()
        self._file.write(f"{os.getpid()}\n")
        self._file.flush()

    def release(self) -> None:
        if not self._file.closed:
            self._file.close()  # closing drops the flock; the file stays (harmless, reused next time)


def remove_stale_temporaries(run_dir: Path) -> list[Path]:
    """Temporary files a killed or disk-full run left behind (atomic writes that never finished)."""
    stale = [p for p in Path(run_dir).iterdir() if p.is_file() and p.name.endswith(".tmp")]
    for p in stale:
        p.unlink()
    return stale


class Trainer:
    def __init__(self, cfg: D4PGConfig, run_dir: str | os.PathLike, resume: bool = False, backend: str = "processes", progress: bool = True):
        self.cfg = cfg.validate()
        self.dir = Path(run_dir)
        self.backend = backend
        self.progress = progress
        torch.set_num_threads(cfg.torch_threads)
        torch.manual_seed(cfg.seed)
        self.rng = np.random.default_rng(cfg.seed)
        self.learner = D4PGLearner(cfg, agent_input_size(cfg.previous_goal), 2)
        if cfg.init_policy and not resume:  # before anything is written: a policy that does not fit leaves no run behind
            start_from_policy(self.learner, cfg.init_policy)
        if cfg.priority_exponent > 0:
            self.replay = PrioritizedReplayBuffer(cfg.replay_capacity, self.learner.critic_inputs, 2,
                                                  cfg.priority_exponent, cfg.priority_correction)
        else:
            self.replay = ReplayBuffer(cfg.replay_capacity, self.learner.critic_inputs, 2)
        self.curriculum = Curriculum(cfg.curriculum, cfg.level_thresholds, cfg.level_budget_fraction, cfg.total_steps,
                                     cfg.curriculum_window, cfg.time_limit_s)
        self.env_steps = 0
        self.episodes = 0
        self.wall_time = 0.0
        self.restarts = 0
        self.level_times: dict[str, float] = {}
        self.recent_exploit: list[float] = []
        if not resume:
            self.dir.mkdir(parents=True, exist_ok=True)
        self.lock = RunLock(self.dir)  # before anything in the folder is read or written
        if resume:
            remove_stale_temporaries(self.dir)
            try:
                self.load_checkpoint()
            except BaseException:
                self.lock.release()
                raise
        else:
            if any((self.dir / name).exists() for name in ("checkpoint.pt", "config.json", "curve.csv")):
                self.lock.release()
                raise ValueError(f"{self.dir} already holds a run; use --resume {self.dir} to continue it or pick another --out")
            (self.dir / "config.json").write_text(cfg.to_json() + "\n")
            with (self.dir / "curve.csv").open("w", newline="") as f:
                csv.writer(f).writerow(CURVE_HEADER)

    # ------------------------------------------------------------------ checkpoints
    def checkpoint(self) -> None:
        save_atomic(
            {
                "format": CHECKPOINT_FORMAT,
                "version": 1,
                "config": dataclasses.asdict(self.cfg),
                "learner": self.learner.state_dict(),
                "replay": self.replay.state_dict(),
                "env_steps": self.env_steps,
                "episodes": self.episodes,
                "wall_time": self.wall_time,
                "restarts": self.restarts,
                "curriculum": self.curriculum.state(),
                "level_times": dict(self.level_times),
                "torch_rng": torch.get_rng_state(),
                "numpy_rng": json.dumps(self.rng.bit_generator.state),
            },
            self.dir / "checkpoint.pt",
        )

    def load_checkpoint(self) -> None:
        data = load_checked(self.dir / "checkpoint.pt", CHECKPOINT_FORMAT)
        saved = D4PGConfig.from_dict(data["config"])
        for key in ("method", "robot", "hidden", "num_atoms", "v_min", "v_max"):
            if getattr(saved, key) != getattr(self.cfg, key):
                raise ValueError(f"{self.dir}: checkpoint was trained with {key}={getattr(saved, key)!r}, not {getattr(self.cfg, key)!r}")
        self.learner.load_state_dict(data["learner"])
        self.replay.load_state_dict(data["replay"])
        self.env_steps = int(data["env_steps"])
        self.episodes = int(data["episodes"])
        self.wall_time = float(data["wall_time"])
        self.restarts = int(data["restarts"]) + 1
        self.curriculum.load_state(data["curriculum"])
        self.level_times = dict(data["level_times"])
        torch.set_rng_state(data["torch_rng"])
        self.rng.bit_generator.state = json.loads(data["numpy_rng"])
        # curve rows newer than the checkpoint belong to lost work: drop them
        rows = [r for r in read_curve(self.dir / "curve.csv") if r["env_steps"] <= self.env_steps]
        with atomic_file(self.dir / "curve.csv", newline="") as f:
            w = csv.writer(f)
            w.writerow(CURVE_HEADER)
            for r in rows:
                w.writerow([r["env_steps"], f"{r['wall_time_s']:.2f}", r["level"], f"{r['exploit_return']:.4f}"])

    # ------------------------------------------------------------------ the loop
    def _make_actors(self):
        flat_size = flat_parameters(self.learner.actor).size
        if self.backend == "ray":
            from lbgp.agent.ray_backend import RayActors

            return RayActors(self.cfg, flat_size, self.restarts)
        if self.backend == "inline":
            return InlineActors(self.cfg, self.learner.actor, self.restarts)
        if self.backend != "processes":
            raise ValueError(f"unknown backend {self.backend!r}; use 'processes', 'inline' or 'ray'")
        return ProcessActors(self.cfg, flat_size, self.restarts)

    def _handle(self, msg, curve_writer) -> None:
        if msg[0] != "episode":
            return
        _, actor_id, exploring, level, ret, steps, batch = msg
        if len(batch[0]):
            self.replay.add_batch(*batch)
            if self.cfg.mirror_augment:
                self.replay.add_batch(*mirrored(batch))
        self.env_steps += steps
        self.episodes += 1
        if not exploring:
            curve_writer.writerow([self.env_steps, f"{self.wall_time:.2f}", level, f"{ret:.4f}"])
            self.recent_exploit = (self.recent_exploit + [ret])[-10:]
            if self.curriculum.record(level, ret, self.env_steps, self.wall_time):
                self.level_times[self.curriculum.level] = self.wall_time

    def _learn_once(self) -> None:
        """One learner update from the replay (prioritised: the critic's batch by priority, the
        actor's uniform, and the critic's batch gets new priorities)."""
        batch = self.replay.sample(self.cfg.batch_size, self.rng)
        if not isinstance(self.replay, PrioritizedReplayBuffer):
            self.learner.update(batch)
            return
        self.learner.update(batch, self.replay.sample_uniform(self.cfg.batch_size, self.rng))
        self.replay.update_priorities(batch["index"].numpy(), self.learner.sample_losses)

    def run(self) -> dict:
        cfg = self.cfg
        actors = self._make_actors()
        actors.board.publish(flat_parameters(self.learner.actor))
        actors.set_level(self.curriculum.index)
        published_level = self.curriculum.index
        self.level_times.setdefault(self.curriculum.level, self.wall_time)
        previous = signal.signal(signal.SIGTERM, self._on_sigterm)
        bar = None
        if self.progress:
            from tqdm import tqdm

            bar = tqdm(total=cfg.total_steps, initial=self.env_steps, unit="step", dynamic_ncols=True)
        interrupted = False
        t_start = time.monotonic() - self.wall_time
        last_ckpt = time.monotonic()
        every = cfg.snapshot_every_s
        next_snapshot = (self.wall_time // every + 1) * every if every else float("inf")
        update_clock = (time.monotonic(), self.learner.updates)
        ups = 0.0
        actors.start()
        try:
            with (self.dir / "curve.csv").open("a", newline="") as curve_file:
                curve = csv.writer(curve_file)
                while self.env_steps < cfg.total_steps and not (cfg.time_limit_s and self.wall_time >= cfg.time_limit_s):
                    can_learn = len(self.replay) >= cfg.min_replay and self.learner.updates < cfg.max_updates_per_step * self.env_steps
                    before = self.env_steps
                    for msg in actors.poll(timeout=0.0 if can_learn else 0.2):
                        self._handle(msg, curve)
                    curve_file.flush()
                    if self.curriculum.index != published_level:
                        actors.set_level(self.curriculum.index)
                        published_level = self.curriculum.index
                    if can_learn:
                        # asynchronous actors: a few updates between polls; inline actors: catch up
                        # with the collected steps, so that a seeded run is reproducible
                        if not self.learner.obs_stats_set:
                            self.learner.set_obs_stats(self.replay.obs[: len(self.replay)])
                        due = int(cfg.max_updates_per_step * self.env_steps) - self.learner.updates
                        for _ in range(max(due, 0) if getattr(actors, "synchronous", False) else 10):
                            self._learn_once()
                        if self.learner.updates % 50 == 0:
                            actors.board.publish(flat_parameters(self.learner.actor))
                    self.wall_time = time.monotonic() - t_start
                    if bar is not None and (self.env_steps != before or can_learn):
                        now = time.monotonic()
                        if now - update_clock[0] > 2.0:
                            ups = (self.learner.updates - update_clock[1]) / (now - update_clock[0])
                            update_clock = (now, self.learner.updates)
                        recent = f"{np.mean(self.recent_exploit):.1f}" if self.recent_exploit else "-"
                        bar.set_postfix_str(f"level={self.curriculum.level} return={recent} updates/s={ups:.0f}", refresh=False)
                        bar.update(self.env_steps - bar.n)
                    if time.monotonic() - last_ckpt > cfg.checkpoint_every_s:
                        self.checkpoint()
                        last_ckpt = time.monotonic()
                    if self.wall_time >= next_snapshot:
                        self.snapshot()
                        next_snapshot = (self.wall_time // every + 1) * every
                    if not actors.alive():
                        raise RuntimeError("all actor processes died; see their error output above")
        except (KeyboardInterrupt, Stop):
            interrupted = True
        finally:
            signal.signal(signal.SIGTERM, previous)
            actors.stop()  # transitions still in flight are dropped: the checkpoint below is the state
            if bar is not None:
                bar.close()
        try:
            self.checkpoint()
            return self._finish(interrupted)
        finally:
            self.lock.release()

    def snapshot(self) -> Path:
        """Write the policy file as it is now to ``snapshots/policy_<wall seconds>s.pt``."""
        cfg = self.cfg
        path = self.dir / "snapshots" / f"policy_{int(self.wall_time):06d}s.pt"
        path.parent.mkdir(exist_ok=True)
        meta = {"method": cfg.method, "robot": cfg.robot, "seed": cfg.seed, "env_steps": self.env_steps,
                "learner_updates": self.learner.updates, "wall_time_s": round(self.wall_time, 1),
                "level": self.curriculum.level}
        self._save_policy(path, self.learner.policy_actor, meta)
        return path

    def _save_policy(self, path: Path, actor, extra: dict) -> None:
        cfg = self.cfg
        save_policy(path, actor, cfg.method, cfg.robot, cfg.hidden, extra=extra, residual_scale=cfg.actor_residual_scale,
                    planner_changes=cfg.planner_changes())

    def close(self) -> None:
        """Give the run folder back (its lock) without running: ``run`` does this itself."""
        self.lock.release()

    def _on_sigterm(self, signum, frame):
        raise Stop()

    def _finish(self, interrupted: bool) -> dict:
        cfg = self.cfg
        rows = read_curve(self.dir / "curve.csv")
        final_level = [r["exploit_return"] for r in rows if r["level"] == self.curriculum.level][-20:]
        summary = {
            "method": cfg.method,
            "robot": cfg.robot,
            "curriculum": cfg.curriculum,
            "seed": cfg.seed,
            "env_steps": self.env_steps,
            "episodes": self.episodes,
            "learner_updates": self.learner.updates,
            "wall_time_s": round(self.wall_time, 1),
            "final_level": self.curriculum.level,
            "curriculum_history": [list(h) for h in self.curriculum.history],
            "wall_time_to_level_s": {k: round(v, 1) for k, v in self.level_times.items()},
            "final_exploit_return_mean_last20": float(np.mean(final_level)) if final_level else None,
            "interrupted": interrupted,
        }
        if cfg.init_policy:
            summary["init_policy"] = cfg.init_policy  # the actor started as this file's (lbgp.agent.fine_tune)
        if self.learner.average_actor is not None:  # the last raw actor too, beside the average
            summary["policy_average"] = cfg.policy_average
            self._save_policy(self.dir / "policy_last.pt", self.learner.actor, {**summary, "policy_average": 0.0})
        self._save_policy(self.dir / "policy.pt", self.learner.policy_actor, summary)
        write_json(self.dir / "summary.json", summary)
        return summary


def train(cfg: D4PGConfig, out: str | os.PathLike, resume: bool = False, backend: str = "processes", progress: bool = True) -> dict:
    """Train (or continue) a run in ``out``; returns the summary."""
    if resume:
        data = json.loads((Path(out) / "config.json").read_text())
        saved = D4PGConfig.from_dict(data)
        # a resumed run keeps its configuration; only the budget (steps, time) may be given anew
        cfg = dataclasses.replace(saved, total_steps=cfg.total_steps or saved.total_steps, time_limit_s=cfg.time_limit_s or saved.time_limit_s)
    return Trainer(cfg, out, resume=resume, backend=backend, progress=progress).run()
