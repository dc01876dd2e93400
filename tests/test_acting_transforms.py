"""benchmarks/acting_transforms.py: a trained goal policy acting through a gain on its residual, a
lead on its goal sequence or smoothed over noisy copies of its input, and Policy.base_goal that the
gain scales around."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from acting_transforms import InputSmoothedPolicy, TransformedGoalPolicy, main, smoothing_name, variant_name  # noqa: E402
from ablation_scenarios import scenario_seed  # noqa: E402

from lbgp.actions import DESIRED_GOAL, action_from_goal, goal_from_action  # noqa: E402
from lbgp.agent.config import D4PGConfig  # noqa: E402
from lbgp.agent.learner import make_actor  # noqa: E402
from lbgp.agent.networks import Actor  # noqa: E402
from lbgp.agent.policy import GOAL_DEADBAND_M, load_policy, save_policy, shrink_residual  # noqa: E402
from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.sim import observation as obs_lib  # noqa: E402


def _constant_residual_policy(tmp_path, residual, turn_lead=0.0):
    torch.manual_seed(0)
    actor = make_actor(D4PGConfig(hidden=(8,), turn_lead=turn_lead), obs_lib.SIZE, 2)
    with torch.no_grad():  # residual_scale 0.375 of the action = 0.75 m of goal: b = atanh(r / 0.75)
        actor.net[-1].weight.zero_()
        actor.net[-1].bias.copy_(torch.tensor([math.atanh(r / 0.75) for r in residual]))
    save_policy(tmp_path / "r.pt", actor, "lbgp", "jackal", (8,), residual_scale=actor.residual_scale)
    return load_policy(tmp_path / "r.pt", goal_deadband=0.0, mirror_average=False)


class ScriptedGoals:
    control = "goal"

    def __init__(self, goals):
        self.goals, self.k = [np.asarray(g, float) for g in goals], 0

    def reset(self):
        self.k = 0

    def act(self, observation):
        self.k += 1
        return action_from_goal(self.goals[self.k - 1]).astype(np.float32)


def test_a_gain_scales_the_residual_around_the_base_goal(tmp_path):
    obs = np.zeros(obs_lib.SIZE, np.float32)
    policy = _constant_residual_policy(tmp_path, (0.3, 0.4))
    assert np.allclose(goal_from_action(policy.act(obs)), np.add(DESIRED_GOAL, [0.3, 0.4]), atol=1e-5)
    assert np.allclose(policy.base_goal(obs), DESIRED_GOAL, atol=1e-6)
    assert np.array_equal(TransformedGoalPolicy(policy).act(obs), policy.act(obs))  # gain 1, lead 0: the policy
    for gain, expected in ((2.0, [0.6, 0.8]), (0.5, [0.15, 0.2]), (0.0, [0.0, 0.0])):
        sent = goal_from_action(TransformedGoalPolicy(policy, gain=gain).act(obs))
        assert np.allclose(sent, np.add(DESIRED_GOAL, expected), atol=1e-5), gain


def test_a_lateral_gain_scales_only_the_residual_s_lateral_part(tmp_path):
    obs = np.zeros(obs_lib.SIZE, np.float32)
    policy = _constant_residual_policy(tmp_path, (0.3, 0.4))
    for lateral, gain, expected in ((2.0, 1.0, [0.3, 0.8]), (0.5, 1.0, [0.3, 0.2]), (1.5, 2.0, [0.6, 1.2])):
        sent = goal_from_action(TransformedGoalPolicy(policy, gain=gain, lateral_gain=lateral).act(obs))
        assert np.allclose(sent, np.add(DESIRED_GOAL, expected), atol=1e-5), (lateral, gain)
    assert variant_name(1, 0, 1.5) == "gain1_lead0_lateral1.5" and variant_name(1.5, 0) == "gain1.5_lead0"
    with pytest.raises(ValueError, match="finite"):
        TransformedGoalPolicy(policy, lateral_gain=float("inf"))


def test_a_gain_scales_around_a_turn_aware_base_not_the_goal_ahead(tmp_path):
    from test_goal_policy import _turning_observation

    obs = _turning_observation(0.3)
    policy = _constant_residual_policy(tmp_path, (0.1, 0.0), turn_lead=0.4)
    base = policy.base_goal(obs)
    assert np.allclose(base, [1.62, 0.0], atol=1e-3)  # 1.5 m + 0.4 m per rad/s * 0.3 rad/s
    sent = goal_from_action(TransformedGoalPolicy(policy, gain=3.0).act(obs))
    assert np.allclose(sent, base + [0.3, 0.0], atol=1e-4)


def test_a_lead_extrapolates_the_goal_sequence_and_forgets_it_on_reset():
    goals = [(1.5, 0.0), (1.6, 0.1), (1.6, 0.3), (1.5, 0.3)]
    led = TransformedGoalPolicy(ScriptedGoals(goals), lead=0.5)
    sent = [goal_from_action(led.act(None)) for _ in goals]
    assert np.allclose(sent, [(1.5, 0.0), (1.65, 0.15), (1.6, 0.4), (1.45, 0.3)], atol=1e-6)
    led.reset()
    assert np.allclose(goal_from_action(led.act(None)), goals[0], atol=1e-6)  # no previous goal after reset


def test_only_residual_goal_policies_can_be_transformed(tmp_path):
    plain = Actor(obs_lib.SIZE, 2, (8,))
    save_policy(tmp_path / "plain.pt", plain, "lbgp", "jackal", (8,))
    with pytest.raises(ValueError, match="residual goal policy"):
        TransformedGoalPolicy(load_policy(tmp_path / "plain.pt"), gain=2.0).act(np.zeros(obs_lib.SIZE, np.float32))
    save_policy(tmp_path / "e2e.pt", plain, "e2e", "jackal", (8,))
    with pytest.raises(ValueError, match="velocities"):
        TransformedGoalPolicy(load_policy(tmp_path / "e2e.pt"))
    with pytest.raises(ValueError, match="finite"):
        TransformedGoalPolicy(ScriptedGoals([]), gain=float("nan"))


def test_the_benchmark_scores_the_untransformed_policy_as_the_shipped_one_and_names_bad_input(tmp_path):
    out = main(["--gains", "1.5", "--leads", "0.5", "--scenarios", "turning_ahead", "--episodes", "1", "--seed", "7",
                "--json", str(tmp_path / "a.json")])
    assert set(out["variants"]) == {variant_name(1, 0), variant_name(1.5, 0), variant_name(1, 0.5)}
    own = evaluate(make_policy("lbgp", robot="jackal"), "lbgp", ["turning_ahead"], robot="jackal", episodes=1,
                   seed=scenario_seed(7, "turning_ahead"), obs_noise=True)[0]["reward"]
    plain = out["variants"]["gain1_lead0"]
    assert plain["per_scenario"]["turning_ahead"] == pytest.approx(own, abs=1e-3)
    assert plain["turning_minus_hc"] == pytest.approx(own - out["hc"]["per_scenario"]["turning_ahead"], abs=2e-3)
    assert plain["trajectories_minus_hc"] is None  # no trajectory row scored
    assert (tmp_path / "a.json").is_file()
    with pytest.raises(SystemExit, match="--gains"):
        main(["--gains", "1,x", "--json", str(tmp_path / "b.json")])
    with pytest.raises(SystemExit, match="--lateral-gains"):
        main(["--lateral-gains", "nan", "--json", str(tmp_path / "b.json")])
    with pytest.raises(SystemExit):
        main(["--scenarios", "nowhere", "--json", str(tmp_path / "b.json")])
    assert not (tmp_path / "b.json").exists()


def _observations(n):
    """A few real observations of the shipped policy's Jackal on turning_ahead, with the observation noise on."""
    from lbgp.sim import make_env

    env = make_env("turning_ahead", robot="jackal", seed=3, obs_noise=True)
    step, policy, out = env.reset(), make_policy("lbgp", robot="jackal"), []
    for _ in range(n):
        out.append(np.asarray(step.observation, np.float32))
        step = env.step(policy.act(step.observation))
    return out


def test_input_smoothing_without_noise_is_the_policy_and_with_noise_the_mean_over_seeded_copies():
    observations = _observations(6)
    shipped = make_policy("lbgp", robot="jackal")
    one = InputSmoothedPolicy(None, 0.0, 1)
    for obs in observations:  # one noiseless copy, the dead band once: exactly the policy as shipped
        assert np.array_equal(one.act(obs), shipped.act(obs))
    smoothed = InputSmoothedPolicy(None, 2.0, 4, seed=9)
    sent = [smoothed.act(obs) for obs in observations]
    # the same by hand: the seeded draws, the mean goal of the undamped policy, the dead band on it
    plain, rng = make_policy("lbgp", robot="jackal", goal_deadband=0.0), np.random.default_rng(9)
    std = obs_lib.scale(np.tile([0.03, 0.03, 0.03], obs_lib.SIZE // 3))
    for obs, got in zip(observations, sent):
        copies = np.clip(obs + 2.0 * std * rng.standard_normal((4, obs.size)).astype(np.float32), -1.0, 1.0)
        goal = np.mean([goal_from_action(plain.act(c)) for c in copies], axis=0)
        base = plain.actor.base_action(torch.from_numpy(obs)[None])[0].numpy()
        assert np.allclose(got, shrink_residual(action_from_goal(goal).astype(np.float32), base, GOAL_DEADBAND_M), atol=1e-6)
    assert not all(np.array_equal(a, shipped.act(o)) for a, o in zip(sent, observations))  # the noise does move the goal
    smoothed.reset()  # the same draws again, episode after episode
    assert all(np.array_equal(smoothed.act(o), a) for o, a in zip(observations, sent))


def test_input_smoothing_names_bad_settings(tmp_path):
    with pytest.raises(ValueError, match="noise multiple"):
        InputSmoothedPolicy(None, -1.0, 4)
    with pytest.raises(ValueError, match="copies"):
        InputSmoothedPolicy(None, 1.0, 0)
    plain = Actor(obs_lib.SIZE, 2, (8,))
    save_policy(tmp_path / "plain.pt", plain, "lbgp", "jackal", (8,))
    with pytest.raises(ValueError, match="residual goal policy"):
        InputSmoothedPolicy(tmp_path / "plain.pt", 1.0, 4)
    with pytest.raises(SystemExit):
        main(["--input-noise", "-1", "--json", str(tmp_path / "c.json")])
    assert not (tmp_path / "c.json").exists()


def test_the_benchmark_scores_input_smoothing_beside_the_policy(tmp_path):
    out = main(["--input-noise", "0", "--copies", "1", "--scenarios", "straight_ahead", "--episodes", "1", "--seed", "3",
                "--json", str(tmp_path / "s.json")])
    row = out["variants"][smoothing_name(0, 1)]
    assert (row["input_noise"], row["copies"]) == (0.0, 1)
    assert row["per_scenario"] == out["variants"][variant_name(1, 0)]["per_scenario"]  # no noise, one copy: the policy
