"""D4PG in torch: networks, learner, replay, actor processes, curriculum, policy files."""

from lbgp.agent.config import D4PGConfig
from lbgp.agent.policy import Policy, load_policy, save_policy

__all__ = ["D4PGConfig", "Policy", "load_policy", "save_policy"]
