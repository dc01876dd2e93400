"""Optional Ray backend: the same actor loop (``lbgp.agent.actors.run_actor``) as Ray tasks, so
actors can spread over a cluster. Needs ``pip install -e '.[ray]'``; selected with
``lbgp train --backend ray``. Weights, the curriculum level and the stop flag live in one small
Ray actor; experience travels through a ``ray.util.queue.Queue``.
"""

from __future__ import annotations

import dataclasses

try:
    import ray
    from ray.util.queue import Empty, Queue
except ImportError as exc:  # pragma: no cover - exercised only without Ray
    raise ImportError("the Ray backend needs Ray: pip install -e '.[ray]'") from exc

from lbgp.agent.actors import actor_specs, drain_until_exited, run_actor
from lbgp.agent.config import D4PGConfig


class _Store:
    """Ray actor holding the published weights, the curriculum level and the stop flag."""

    def __init__(self):
        self.version, self.flat, self.level, self.stopped = -1, None, 0, False

    def publish(self, flat):
        self.flat = flat
        self.version += 1

    def fetch(self, known: int):
        return (known, None) if self.version == known else (self.version, self.flat)

    def set_level(self, index: int):
        self.level = index

    def get_level(self) -> int:
        return self.level

    def stop(self):
        self.stopped = True

    def is_stopped(self) -> bool:
        return self.stopped


class _Board:
    def __init__(self, store):
        self.store = store

    def publish(self, flat):
        ray.get(self.store.publish.remote(flat))

    def fetch(self, known: int):
        return ray.get(self.store.fetch.remote(known))


class _Level:
    def __init__(self, store):
        self.store = store

    @property
    def value(self) -> int:
        return ray.get(self.store.get_level.remote())

    @value.setter
    def value(self, index: int) -> None:
        ray.get(self.store.set_level.remote(int(index)))


class _StopFlag:
    def __init__(self, store):
        self.store = store

    def is_set(self) -> bool:
        return ray.get(self.store.is_stopped.remote())


@ray.remote(num_cpus=1)
def _actor_task(spec, cfg_dict, store, queue):
    run_actor(spec, cfg_dict, _Board(store), _Level(store), queue, _StopFlag(store))


class RayActors:
    """Same interface as ``lbgp.agent.actors.ProcessActors``."""

    def __init__(self, cfg: D4PGConfig, flat_size: int, restart: int = 0):
        if not ray.is_initialized():
            ray.init(include_dashboard=False, ignore_reinit_error=True, log_to_driver=False)
        self.store = ray.remote(_Store).remote()
        self.queue = Queue()
        self.board = _Board(self.store)
        self.level_index = _Level(self.store)
        self.cfg_dict = dataclasses.asdict(cfg)
        self.specs = actor_specs(cfg, restart)
        self.tasks: list = []

    def start(self) -> None:
        self.tasks = [_actor_task.remote(spec, self.cfg_dict, self.store, self.queue) for spec in self.specs]

    def set_level(self, index: int) -> None:
        self.level_index.value = index

    def poll(self, timeout: float = 0.0) -> list:
        out = []
        try:
            out.append(self.queue.get(block=timeout > 0, timeout=timeout if timeout > 0 else None))
            while True:
                out.append(self.queue.get_nowait())
        except Empty:
            pass
        return out

    def alive(self) -> bool:
        ready, _ = ray.wait(self.tasks, num_returns=len(self.tasks), timeout=0)
        return len(ready) < len(self.tasks)

    def stop(self, timeout: float = 30.0) -> list:
        ray.get(self.store.stop.remote())
        leftover = drain_until_exited(self.poll, len(self.tasks), timeout)
        ray.wait(self.tasks, num_returns=len(self.tasks), timeout=5)
        return leftover
