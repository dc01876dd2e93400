"""Training on a planner variant: ``lbgp train --set planner_sqp_iterations=K``."""

import numpy as np
import pytest

from lbgp.actions import action_from_goal
from lbgp.agent.actors import EnvCache
from lbgp.agent.config import D4PGConfig
from lbgp.planner import planner_config_for


def _planner(cfg: D4PGConfig, level: str = "circles"):
    return EnvCache(cfg, np.random.default_rng(0))(level).task.controller.planner


def test_the_actors_envs_drive_with_the_configured_sqp_cap():
    """0 keeps the robot's preset; K gives every level's env a planner that stops each band after
    K SQP iterations (so one step's calls solve at most one QP per candidate band at K = 1)."""
    preset = planner_config_for("jackal").sqp_iterations
    assert preset > 1
    assert _planner(D4PGConfig()).cfg.sqp_iterations == preset
    envs = EnvCache(D4PGConfig(planner_sqp_iterations=1), np.random.default_rng(0))
    for level in ("straight", "trajectories"):
        env = envs(level)
        planner = env.task.controller.planner
        assert planner.cfg.sqp_iterations == 1
        env.reset()
        for _ in range(5):
            env.step(action_from_goal([1.5, 0.0]))
        plans = planner.stats["solves"]
        assert plans > 0
    # the rest of the preset is unchanged
    assert _planner(D4PGConfig(planner_sqp_iterations=1)).cfg == planner_config_for("jackal").with_(
        sqp_iterations=1, control_period=_planner(D4PGConfig()).cfg.control_period)


def test_one_sqp_iteration_solves_one_qp_per_band():
    """With the cap at 1, a call's QP solves equal its candidate bands (a cap of 3 solves more)."""
    counts = {}
    for cap in (1, 0):
        env = EnvCache(D4PGConfig(planner_sqp_iterations=cap), np.random.default_rng(0))("circles")
        planner = env.task.controller.planner
        calls = bands = 0
        original = planner.plan

        def counting(*args, **kwargs):
            nonlocal calls, bands
            plan = original(*args, **kwargs)
            calls += 1
            bands += len(plan.tried)
            return plan

        planner.plan = counting
        env.reset()
        for _ in range(10):
            env.step(action_from_goal([1.5, 0.0]))
        counts[cap] = (planner.stats["solves"], bands, calls)
    solves, bands, calls = counts[1]
    assert calls > 0 and solves == bands
    assert counts[0][0] > counts[0][1]


@pytest.mark.parametrize("text", ["planner_sqp_iterations=-1", "planner_sqp_iterations=51", "planner_sqp_iterations=x"])
def test_a_bad_sqp_cap_is_refused_with_its_name(text):
    with pytest.raises(ValueError, match="planner_sqp_iterations"):
        D4PGConfig.parse_setting(text)


def test_the_sqp_cap_is_settable_from_the_command_line():
    assert D4PGConfig.parse_setting("planner_sqp_iterations=1") == ("planner_sqp_iterations", 1)


def test_training_only_planner_changes_reach_the_actors_planners_and_nothing_else(tmp_path):
    """``train_planner_changes`` changes the planner the actors' environments drive with (the rest of
    the preset kept); the policy file the run writes does not record them, so the policy acts on the preset."""
    from lbgp.agent.policy import load_policy
    from lbgp.agent.train import Trainer

    shipped_run = "weight_turn=0.05,lateral_acc_limit_clear=none"
    preset = _planner(D4PGConfig()).cfg
    assert preset.weight_turn != 0.05 and preset.lateral_acc_limit_clear is not None
    trained_on = _planner(D4PGConfig(train_planner_changes=shipped_run), "trajectories").cfg
    assert trained_on == preset.with_(weight_turn=0.05, lateral_acc_limit_clear=None)
    cfg = D4PGConfig(total_steps=100, min_replay=50, num_actors=1, hidden=(16, 16), batch_size=16,
                     train_planner_changes=shipped_run, planner_sqp_iterations=1)
    assert cfg.training_planner_changes() == {"sqp_iterations": 1, "weight_turn": 0.05, "lateral_acc_limit_clear": None}
    trainer = Trainer(cfg, tmp_path / "run", progress=False)
    try:
        path = trainer.snapshot()
    finally:
        trainer.close()
    assert load_policy(path).planner_changes == {"sqp_iterations": 1}


@pytest.mark.parametrize("text, problem", [
    ("train_planner_changes=weight_tur=0.05", "weight_tur"),
    ("train_planner_changes=weight_turn=x", "weight_turn"),
    ("train_planner_changes=weight_turn", "NAME=VALUE"),
    ("train_planner_changes=sqp_iterations=1.5", "sqp_iterations"),
    ("train_planner_changes=weight_turn=0.05,sqp_iterations=1", "planner_sqp_iterations"),
])
def test_bad_training_planner_changes_are_refused_with_their_names(text, problem):
    with pytest.raises(ValueError, match=f"train_planner_changes.*{problem}"):
        D4PGConfig.parse_setting(text)
