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
from lbgp.agent.networks import Actor
from lbgp.agent.nstep import NStepAccumulator
from lbgp.sim import observation as obs_lib
from lbgp.sim.tasks import CURRICULUM

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


def run_actor(spec: ActorSpec, cfg_dict: dict, board: WeightBoard, level_index, queue, stop) -> None:
    """The actor loop (runs in its own process until ``stop`` is set)."""
    torch.set_num_threads(1)
    if cfg_dict.get("actor_niceness"):
        os.nice(int(cfg_dict["actor_niceness"]))  # the learner gets the CPU it needs first
    from lbgp.sim import make_env

    cfg = D4PGConfig.from_dict(cfg_dict)
    if hasattr(queue, "cancel_join_thread"):
        queue.cancel_join_thread()  # never hang at exit on a queue nobody reads any more
    parent = mp.parent_process()
    rng = np.random.default_rng(spec.seed)
    actor = Actor(obs_lib.SIZE, ACTION_SIZE, cfg.hidden)
    version = -1
    envs: dict = {}
    nstep = NStepAccumulator(cfg.n_step, cfg.discount)
    try:
        while not stop.is_set():
            if parent is not None and not parent.is_alive():
                return  # the learner died (e.g. killed): do not linger as an orphan
            version, flat = board.fetch(version)
            if flat is not None:
                load_flat_parameters(actor, flat)
            current = int(level_index.value)
            level = CURRICULUM[current]
            if spec.exploring and current > 0 and cfg.curriculum and rng.uniform() < cfg.earlier_level_share:
                level = CURRICULUM[int(rng.integers(0, current))]
            if level not in envs:
                envs[level] = make_env(level, robot=cfg.robot, seed=int(rng.integers(2**31)), control=cfg.control, horizon=cfg.horizon)
            env = envs[level]
            transitions, episode_return, steps, since_sync = [], 0.0, 0, 0
            nstep.reset()
            timestep = env.reset()
            while not timestep.last():
                obs = timestep.observation
                with torch.no_grad():
                    action = actor(torch.from_numpy(obs)[None])[0].numpy()
                if spec.exploring:
                    action = np.clip(action + cfg.sigma * rng.normal(size=ACTION_SIZE), -1.0, 1.0).astype(np.float32)
                timestep = env.step(action)
                episode_return += timestep.reward
                steps += 1
                since_sync += 1
                terminal = timestep.last() and timestep.discount == 0.0
                truncated = timestep.last() and not terminal
                transitions += nstep.step(obs, action, timestep.reward, timestep.observation, terminal, truncated)
                if since_sync >= cfg.weight_sync_steps:
                    version, flat = board.fetch(version)
                    if flat is not None:
                        load_flat_parameters(actor, flat)
                    since_sync = 0
            batch = tuple(np.array([t[i] for t in transitions], np.float32) for i in range(5))
            queue.put(("episode", spec.actor_id, spec.exploring, level, float(episode_return), steps, batch))
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
