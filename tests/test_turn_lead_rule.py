"""benchmarks/turn_lead_rule.py: the turn-aware base goal alone, scored as the sim table scores."""

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from turn_lead_rule import main  # noqa: E402

from lbgp.actions import action_from_goal  # noqa: E402
from lbgp.evaluate import evaluate  # noqa: E402
from lbgp.rollout import ConstantGoalPolicy  # noqa: E402
from lbgp.sim import observation as obs_lib  # noqa: E402


class LeadRule:
    """The rule written out by hand: 1.5 m + lead * |turn rate| straight ahead of the person."""

    control = "goal"

    def __init__(self, lead):
        self.lead = lead

    def act(self, observation):
        turn = float(np.asarray(observation, np.float32) @ obs_lib.turn_rate_weights())
        return action_from_goal((1.5 + self.lead * abs(turn), 0.0)).astype(np.float32)


def test_an_untrained_actor_scores_as_its_rule_on_the_sim_tables_episodes(tmp_path):
    result = main(["--leads", "0,0.6", "--scenarios", "turning_inside", "--episodes", "2", "--json", str(tmp_path / "r.json")])
    rows = result["rows"]
    # turning_inside is the sim table's scenario 4: its episodes are seeded 4000
    (constant,) = evaluate(ConstantGoalPolicy((1.5, 0.0)), "lbgp", ["turning_inside"], episodes=2, seed=4000, obs_noise=True)
    (rule,) = evaluate(LeadRule(0.6), "lbgp", ["turning_inside"], episodes=2, seed=4000, obs_noise=True)
    assert rows["lead 0"]["sum"] == pytest.approx(constant["reward"], abs=2e-3)
    assert rows["lead 0.6"]["sum"] == pytest.approx(rule["reward"], abs=2e-3)
    # the lead changes the episodes (by 0.04 on these two since the Jackal's turn weight is 0.02, 0.05+ before)
    assert rows["lead 0.6"]["sum"] != pytest.approx(rows["lead 0"]["sum"], abs=0.01)
    assert rows["lead 0.6"]["minus_hc"]["sum"] == pytest.approx(rows["lead 0.6"]["sum"] - rows["HC"]["sum"], abs=1e-3)
    assert (tmp_path / "r.json").is_file()
