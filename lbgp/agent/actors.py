"""Actor processes: play episodes with the latest weights, send n-step transitions to the learner.

Weights travel through one shared float32 array plus a version counter (the learner writes, the
actors copy when the version changed); experience and episode results travel through one queue.
Each actor process runs torch with one thread, so the learner and the actors share the cores
without oversubscribing them, and at a lower scheduling priority (``actor_niceness``), so that on a
small machine the learner keeps about one core and the actors share the rest.
"""

from __future__ import annotations

import dataclasses
import multiprocessing as mp
import os

import numpy as np
import torch

from lbgp.agent.config import D4PGConfig
from lbgp.agent.critic_future import hindsight_features
from lbgp.agent.learner import make_actor
from lbgp.agent.networks import Actor
from lbgp.agent.nstep import NStepAccumulator
from lbgp.agent.previous_goal import agent_input, agent_input_size, first_previous_action
from lbgp.sim.tasks import CURRICULUM, DRAWN_PATHS_LEVEL

ACTION_SIZE = 2


def flat_parameters(module: torch.nn.Module) -> np.ndarray:
    return torch.cat([p.detach().reshape(-1) for p in module.state_dict().values()]).numpy().astype(np.float32)


def load_flat_parameters(module: torch.nn.Module, flat: np.ndarray) -> None:
    state = module.state_dict()
    i = 0
    for k, v in state.items():
        n = v.numel()
        state[k] = torch.from_numpy(flat[i : i + n].copy()).reshape(v.shape).to(v.dtype)
        i += n
    module.load_state_dict(state)


class WeightBoard:
    """Shared flat actor weights with a version number."""

    def __init__(self, ctx, size: int):
        self.array = ctx.Array("f", size, lock=True)
        self.version = ctx.Value("l", -1, lock=True)

    def publish(self, flat: np.ndarray) -> None:
        with self.array.get_lock():
            np.frombuffer(self.array.get_obj(), np.float32)[:] = flat
            with self.version.get_lock():
                self.version.value += 1

    def fetch(self, known_version: int):
        """(version, flat weights) if newer than ``known_version``, else (known_version, None)."""
        if self.version.value == known_version:
            return known_version, None
        with self.array.get_lock():
            flat = np.frombuffer(self.array.get_obj(), np.float32).copy()
            return self.version.value, flat


@dataclasses.dataclass
class ActorSpec:
    actor_id: int
    exploring: bool
    seed: int


def choose_level(spec: ActorSpec, cfg: D4PGConfig, current: int, rng: np.random.Generator) -> str:
    """The curriculum level of the next episode: the current one, or for exploring actors now and
    then an earlier one (``earlier_level_share``) so that nothing learnt is forgotten."""
    if spec.exploring and current > 0 and cfg.curriculum and rng.uniform() < cfg.earlier_level_share:
        return CURRICULUM[int(rng.integers(0, current))]
    return CURRICULUM[current]


class ExplorationNoise:
    """Gaussian exploration noise, white (``correlation`` 0, the paper) or AR(1) in time: n_t =
    c n_{t-1} + sqrt(1 - c^2) sigma e_t, whose stationary std is sigma whatever c. Starts stationary."""

    def __init__(self, sigma: float, correlation: float, rng: np.random.Generator):
        self.sigma, self.c, self.rng = float(sigma), float(correlation), rng
        self.value = self.sigma * rng.normal(size=ACTION_SIZE)

    def sample(self) -> np.ndarray:
        out = self.value
        innovation = self.sigma * self.rng.normal(size=ACTION_SIZE)
        self.value = self.c * self.value + np.sqrt(1.0 - self.c**2) * innovation
        return out


def play_episode(env, actor: Actor, exploring: bool, cfg: D4PGConfig, rng: np.random.Generator, nstep: NStepAccumulator, refresh=None):
    """One episode; returns (n-step transition batch, return, steps). ``refresh()`` is called every
    ``weight_sync_steps`` steps so that long episodes pick up new weights. With
    ``cfg.previous_goal`` the transitions hold agent inputs (observation + the action sent before);
    with ``cfg.critic_future`` the critic's hindsight features follow them (``lbgp.agent.critic_future``),
    which is why the n-step transitions are formed once the episode is over."""
    steps_taken, episode_return, steps = [], 0.0, 0
    timestep = env.reset()
    noise = ExplorationNoise(cfg.sigma, cfg.noise_correlation, rng)
    sent = first_previous_action(actor)
    poses = [_true_poses(env)] if cfg.critic_future else None

    def inputs(observation):
        return agent_input(observation, sent) if cfg.previous_goal else observation

    obs = inputs(timestep.observation)
    while not timestep.last():
        with torch.no_grad():
            action = actor(torch.from_numpy(obs)[None])[0].numpy()
        if exploring:
            action = np.clip(action + noise.sample(), -1.0, 1.0).astype(np.float32)
        timestep = env.step(action)
        sent = np.asarray(action, np.float32)
        episode_return += timestep.reward
        steps += 1
        if poses is not None:
            poses.append(_true_poses(env))
        terminal = timestep.last() and timestep.discount == 0.0
        truncated = timestep.last() and not terminal
        next_obs = inputs(timestep.observation)
        steps_taken.append((obs, action, timestep.reward, next_obs, terminal, truncated))
        obs = next_obs
        if refresh is not None and steps % cfg.weight_sync_steps == 0:
            refresh()
    if poses is not None:
        robots, persons = (np.array(p) for p in zip(*poses))
        future = hindsight_features(robots, persons)
        steps_taken = [(np.concatenate([o, future[t]]), a, r, np.concatenate([n, future[t + 1]]), term, trunc)
                       for t, (o, a, r, n, term, trunc) in enumerate(steps_taken)]
    nstep.reset()
    transitions = [tr for step in steps_taken for tr in nstep.step(*step)]
    batch = tuple(np.array([t[i] for t in transitions], np.float32) for i in range(5))
    return batch, float(episode_return), steps


def _true_poses(env) -> tuple[np.ndarray, np.ndarray]:
    """The robot's and the person's true world poses now (for the critic's hindsight only)."""
    info = env.info()
    return info["robot_pose"], info["person_pose"]


def training_planner(cfg: D4PGConfig):
    """The planner configuration the actors' environments drive with: the robot's preset with
    ``cfg.training_planner_changes()`` (the preset itself where there are none)."""
    from lbgp.planner import planner_config_for

    return planner_config_for(cfg.robot, cfg.training_planner_changes())


class EnvCache:
    """One environment per curriculum level, created on first use with a seed from ``rng``."""

    def __init__(self, cfg: D4PGConfig, rng: np.random.Generator):
        self.cfg, self.rng, self.envs = cfg, rng, {}

    def __call__(self, level: str):
        if level not in self.envs:
            from lbgp.sim import make_env

            cfg = self.cfg
            self.envs[level] = make_env(level, robot=cfg.robot, seed=int(self.rng.integers(2**31)), control=cfg.control,
                                        horizon=cfg.horizon, spawn_front_share=cfg.spawn_front_share,
                                        planner_config=training_planner(cfg),
                                        randomize=cfg.randomize or None,
                                        drawn_paths=cfg.drawn_paths and level == DRAWN_PATHS_LEVEL)
        return self.envs[level]


def run_actor(spec: ActorSpec, cfg_dict: dict, board: WeightBoard, level_index, queue, stop) -> None:
    """The actor loop (runs in its own process until ``stop`` is set)."""
    torch.set_num_threads(1)
    if cfg_dict.get("actor_niceness"):
        os.nice(int(cfg_dict["actor_niceness"]))  # the learner gets the CPU it needs first
    cfg = D4PGConfig.from_dict(cfg_dict)
    if hasattr(queue, "cancel_join_thread"):
        queue.cancel_join_thread()  # never hang at exit on a queue nobody reads any more
    parent = mp.parent_process()
    rng = np.random.default_rng(spec.seed)
    actor = make_actor(cfg, agent_input_size(cfg.previous_goal), ACTION_SIZE)
    version = -1
    envs = EnvCache(cfg, rng)
    nstep = NStepAccumulator(cfg.n_step, cfg.discount)

    def refresh():
        nonlocal version
        version, flat = board.fetch(version)
        if flat is not None:
            load_flat_parameters(actor, flat)

    try:
        while not stop.is_set():
            if parent is not None and not parent.is_alive():
                return  # the learner died (e.g. killed): do not linger as an orphan
            refresh()
            level = choose_level(spec, cfg, int(level_index.value), rng)
            batch, ret, steps = play_episode(envs(level), actor, spec.exploring, cfg, rng, nstep, refresh)
            queue.put(("episode", spec.actor_id, spec.exploring, level, ret, steps, batch))
    except KeyboardInterrupt:  # the learner handles Ctrl-C; actors just stop
        pass
    finally:
        if parent is None or parent.is_alive():
            queue.put(("exit", spec.actor_id))


def actor_specs(cfg: D4PGConfig, restart: int = 0) -> list[ActorSpec]:
    """The paper's setup: exploring actors first, then the exploiting one(s)."""
    specs = []
    for i in range(cfg.num_actors):
        exploring = i < cfg.num_actors - cfg.num_exploit
        specs.append(ActorSpec(i, exploring, seed=cfg.seed * 10_000 + restart * 100 + i))
    return specs


class ProcessActors:
    """Actors as local processes (the default backend)."""

    def __init__(self, cfg: D4PGConfig, flat_size: int, restart: int = 0):
        self.ctx = mp.get_context("spawn")
        self.board = WeightBoard(self.ctx, flat_size)
        self.level_index = self.ctx.Value("i", 0)
        self.queue = self.ctx.Queue()
        self.stop_event = self.ctx.Event()
        self.cfg_dict = dataclasses.asdict(cfg)
        self.specs = actor_specs(cfg, restart)
        self.procs: list = []

    def start(self) -> None:
        for spec in self.specs:
            p = self.ctx.Process(
                target=run_actor,
                args=(spec, self.cfg_dict, self.board, self.level_index, self.queue, self.stop_event),
                daemon=True,
                name=f"lbgp-actor-{spec.actor_id}",
            )
            p.start()
            self.procs.append(p)

    def set_level(self, index: int) -> None:
        self.level_index.value = index

    def poll(self, timeout: float = 0.0) -> list:
        """Messages that arrived (waits up to ``timeout`` for the first one)."""
        import queue as queue_lib

        out = []
        try:
            out.append(self.queue.get(timeout=timeout) if timeout > 0 else self.queue.get_nowait())
            while True:
                out.append(self.queue.get_nowait())
        except queue_lib.Empty:
            pass
        return out

    def alive(self) -> bool:
        return any(p.is_alive() for p in self.procs)

    def stop(self, timeout: float = 20.0) -> list:
        """Stop the actors; returns the messages still in flight (so that the queue is drained)."""
        self.stop_event.set()
        leftover = drain_until_exited(self.poll, len(self.procs), timeout)
        for p in self.procs:
            p.join(timeout=2.0)
            if p.is_alive():
                p.terminate()
        return leftover


def drain_until_exited(poll, count: int, timeout: float) -> list:
    """Read messages until ``count`` actors said "exit" (or ``timeout``); returns the others."""
    import time

    leftover, exited = [], set()
    deadline = time.monotonic() + timeout
    while len(exited) < count and time.monotonic() < deadline:
        for msg in poll(timeout=0.2):
            if msg[0] == "exit":
                exited.add(msg[1])
            else:
                leftover.append(msg)
    return leftover


class InlineActors:
    """All actors in the learner's own process, one episode per ``poll`` in turn (backend
    ``inline``). Slower on a multi-core machine but fully reproducible for a seed: the learner runs
    ``max_updates_per_step`` updates per collected step between episodes. For tests and debugging."""

    synchronous = True

    def __init__(self, cfg: D4PGConfig, actor: Actor, restart: int = 0):
        self.cfg = cfg
        self.actor = actor  # the learner's own network: always the latest weights
        self.specs = actor_specs(cfg, restart)
        self.rngs = [np.random.default_rng(spec.seed) for spec in self.specs]
        self.envs = [EnvCache(cfg, rng) for rng in self.rngs]
        self.nstep = NStepAccumulator(cfg.n_step, cfg.discount)
        self.level = 0
        self.turn = 0
        self.board = self  # publishing is a no-op: the actors use the learner's network

    def publish(self, flat) -> None:
        pass

    def start(self) -> None:
        pass

    def set_level(self, index: int) -> None:
        self.level = index

    def poll(self, timeout: float = 0.0) -> list:
        i = self.turn % len(self.specs)
        self.turn += 1
        spec, rng = self.specs[i], self.rngs[i]
        level = choose_level(spec, self.cfg, self.level, rng)
        batch, ret, steps = play_episode(self.envs[i](level), self.actor, spec.exploring, self.cfg, rng, self.nstep)
        return [("episode", spec.actor_id, spec.exploring, level, ret, steps, batch)]

    def alive(self) -> bool:
        return True

    def stop(self, timeout: float = 0.0) -> list:
        return []
