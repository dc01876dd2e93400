"""The layers of lbgp point one way (docs/architecture.md): a module imports only modules of its
own or a lower layer, so that e.g. the planner never pulls in the simulator. Read from the source
(every import statement, also those inside functions)."""

import ast
from pathlib import Path

import numpy as np
import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "lbgp"

# bottom to top; a module's layer is that of its longest matching prefix
LAYERS = [
    ("core", ["lbgp.conventions", "lbgp.geometry", "lbgp.files", "lbgp.robots", "lbgp.actions", "lbgp.world",
              "lbgp.metrics", "lbgp.cli_args", "lbgp"]),
    ("planner", ["lbgp.planner"]),
    ("control", ["lbgp.control", "lbgp.stack"]),
    ("sim", ["lbgp.sim"]),
    ("policies", ["lbgp.rollout", "lbgp.baselines", "lbgp.agent", "lbgp.policies", "lbgp.viz"]),
    ("real", ["lbgp.real", "lbgp.evaluate"]),
    ("experiments", ["lbgp.experiments"]),
    ("cli", ["lbgp.cli"]),
]
RANK = {prefix: rank for rank, (_, prefixes) in enumerate(LAYERS) for prefix in prefixes}


def layer_of(module: str) -> int:
    parts = module.split(".")
    for n in range(len(parts), 0, -1):
        prefix = ".".join(parts[:n])
        if prefix in RANK:
            return RANK[prefix]
    raise KeyError(module)


def modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        name = ".".join(rel.parts[:-1] if rel.name == "__init__" else rel.parts)
        yield name, path


def lbgp_imports(path: Path, module: str):
    package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(package.split(".")[: len(package.split(".")) - node.level + 1] + ([base] if base else []))
            names = [f"{base}.{a.name}" for a in node.names] if base == "lbgp" else [base]
        else:
            continue
        yield from (n for n in names if n == "lbgp" or n.startswith("lbgp."))


def test_every_module_has_a_layer():
    for name, _ in modules():
        layer_of(name)


@pytest.mark.parametrize("name,path", list(modules()), ids=[n for n, _ in modules()])
def test_no_module_imports_a_higher_layer(name, path):
    own = layer_of(name)
    higher = [imp for imp in lbgp_imports(path, name) if layer_of(imp) > own]
    assert not higher, f"{name} (layer {LAYERS[own][0]}) imports {higher}"


def test_the_planner_and_the_robot_descriptions_do_not_load_the_simulator():
    import subprocess
    import sys

    code = "import sys, lbgp.planner, lbgp.robots, lbgp.stack; print(any(m.startswith('lbgp.sim') for m in sys.modules))"
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip() == "False"


# ---------------------------------------------------------------- one home per setting
@pytest.mark.parametrize("period", [0.05, 0.1, 0.2])
def test_the_planner_period_reaches_the_acceleration_clamp(period):
    """make_env(planner_period=...) used to leave the planner's control period at 0.1 s, so at
    0.05 s the clamp allowed twice the acceleration limit."""
    from lbgp.sim import make_env

    env = make_env("straight_ahead", robot="jackal", seed=0, planner_period=period)
    limits = env.task.limits
    assert limits.control_period == period
    env.reset()
    velocities, commands = [], []
    planner = env.task.controller.planner
    original = planner.plan

    def spy(*args, **kwargs):
        plan = original(*args, **kwargs)
        velocities.append(np.asarray(args[1], float))
        commands.append((plan.v, plan.w))
        return plan

    planner.plan = spy
    for _ in range(5):
        env.step(np.array([1.0, 0.0]))  # a goal far ahead: accelerate as hard as allowed
    step = np.abs(np.array(commands)[:, 0] - np.array(velocities)[:, 0])
    assert step.max() <= limits.acc_lim_x * period + 1e-9
    assert step.max() > 0.5 * limits.acc_lim_x * period  # it does accelerate


def test_the_desired_distance_and_agent_period_have_one_home():
    from lbgp import conventions
    from lbgp.actions import DESIRED_GOAL
    from lbgp.baselines.hc import HCPolicy
    from lbgp.sim import observation, rewards, tasks

    assert DESIRED_GOAL == (conventions.DESIRED_DISTANCE, 0.0)
    assert HCPolicy().distance == conventions.DESIRED_DISTANCE
    assert rewards.distance_reward(conventions.DESIRED_DISTANCE) == max(rewards.distance_reward(d) for d in np.linspace(0.5, 3, 251))
    assert observation.FRAME_PERIOD == tasks.CONTROL_PERIOD == conventions.AGENT_PERIOD
