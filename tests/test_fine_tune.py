"""Starting a run from a trained policy (lbgp.agent.fine_tune, `lbgp train --init-policy`)."""

from __future__ import annotations

import json

import numpy as np
import pytest
import torch

from lbgp.agent.config import D4PGConfig
from lbgp.agent.policy import load_policy
from lbgp.agent.train import Trainer
from lbgp.cli import main
from lbgp.sim import observation as obs_lib

SHIPPED = "lbgp/agent/pretrained/lbgp_jackal.pt"


def tiny(**changes) -> D4PGConfig:
    # the shipped actor's architecture (128-128 residual), a run too short to leave the actor warm-up
    return D4PGConfig(total_steps=120, min_replay=40, horizon=10, batch_size=16, seed=3, init_policy=SHIPPED, **changes)


def observations(n: int = 64) -> np.ndarray:
    return np.random.default_rng(0).uniform(-1.0, 1.0, (n, obs_lib.SIZE)).astype(np.float32)


def test_the_actor_starts_as_the_policy_and_keeps_its_standardisation(tmp_path):
    trainer = Trainer(tiny(actor_warmup_updates=10_000), tmp_path / "run", backend="inline", progress=False)
    summary = trainer.run()
    assert summary["learner_updates"] > 0  # the critic learned; the actor is still in its warm-up
    shipped, tuned = load_policy(SHIPPED), load_policy(tmp_path / "run" / "policy.pt")
    for name, value in shipped.actor.state_dict().items():  # weights and input standardisation alike
        assert torch.equal(tuned.actor.state_dict()[name], value), name
    assert np.array_equal(np.stack([tuned.act(o) for o in observations()]), np.stack([shipped.act(o) for o in observations()]))
    assert json.loads((tmp_path / "run" / "config.json").read_text())["init_policy"] == SHIPPED
    assert summary["init_policy"] == SHIPPED


def test_after_the_warm_up_the_actor_learns_from_where_the_policy_was(tmp_path):
    trainer = Trainer(tiny(actor_warmup_updates=0), tmp_path / "run", backend="inline", progress=False)
    trainer.run()
    shipped, tuned = load_policy(SHIPPED), load_policy(tmp_path / "run" / "policy.pt")
    state = shipped.actor.state_dict()
    changed = [n for n, v in state.items() if not torch.equal(tuned.actor.state_dict()[n], v)]
    standardisation = [n for n in state if "obs_mean" in n or "obs_std" in n]
    assert standardisation and changed  # the actor learned ...
    assert not set(changed) & set(standardisation)  # ... with the policy's standardisation, not one set from the replay


@pytest.mark.parametrize("changes, named", [
    (dict(hidden=(64, 64)), "layers differ"),
    (dict(method="e2e"), "method lbgp"),
    (dict(residual_scale=0.5), "residual_scale"),
    (dict(motion_features=True), "motion_features"),
    (dict(previous_goal=True), "layers differ"),
])
def test_a_policy_that_does_not_fit_the_run_is_refused_before_anything_is_written(tmp_path, changes, named):
    with pytest.raises(ValueError, match=named):
        Trainer(tiny(**changes), tmp_path / "run", backend="inline", progress=False)
    assert not (tmp_path / "run").exists()


def test_the_cli_option_names_a_missing_or_corrupt_file(tmp_path, capsys):
    assert main(["train", "--init-policy", str(tmp_path / "nothing.pt"), "--out", str(tmp_path / "a")]) == 2
    assert "no such file" in capsys.readouterr().err
    corrupt = tmp_path / "corrupt.pt"
    corrupt.write_bytes(b"not a policy")
    assert main(["train", "--init-policy", str(corrupt), "--out", str(tmp_path / "b"), "--steps", "50"]) == 2
    assert "corrupt.pt" in capsys.readouterr().err
    assert not (tmp_path / "b").exists()


def test_a_resumed_run_keeps_its_own_actor_not_the_policy_it_started_from(tmp_path):
    Trainer(tiny(actor_warmup_updates=0), tmp_path / "run", backend="inline", progress=False).run()
    saved = D4PGConfig.from_dict(json.loads((tmp_path / "run" / "config.json").read_text()))
    resumed = Trainer(saved, tmp_path / "run", resume=True, backend="inline", progress=False)
    try:
        ended = load_policy(tmp_path / "run" / "policy.pt").actor.state_dict()
        assert all(torch.equal(resumed.learner.actor.state_dict()[n], v) for n, v in ended.items())
        assert resumed.learner.actor_stats_fixed  # the replay will not restandardise its inputs either
    finally:
        resumed.close()
