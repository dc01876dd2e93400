"""Training end to end: the real multi-process path, checkpoint/resume after a kill, the CLI."""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import torch

from lbgp.agent import load_policy
from lbgp.agent.config import D4PGConfig
from lbgp.agent.train import Trainer, read_curve, train

TINY = dict(total_steps=300, min_replay=100, num_actors=2, checkpoint_every_s=1.0, horizon=10, hidden=(32, 32), batch_size=32)


def test_training_smoke_runs_the_real_multi_process_path(tmp_path):
    cfg = D4PGConfig(**TINY, seed=3)
    summary = train(cfg, tmp_path / "run", progress=False)
    assert summary["env_steps"] >= 300 and summary["learner_updates"] > 0 and not summary["interrupted"]
    run = tmp_path / "run"
    for name in ("config.json", "curve.csv", "checkpoint.pt", "policy.pt", "summary.json"):
        assert (run / name).is_file(), name
    rows = read_curve(run / "curve.csv")
    assert rows and all(r["level"] in ("straight", "circles", "smoothed", "trajectories") for r in rows)
    assert [r["env_steps"] for r in rows] == sorted(r["env_steps"] for r in rows)
    policy = load_policy(run / "policy.pt")
    assert policy.act(np.zeros(57, np.float32)).shape == (2,)
    with pytest.raises(ValueError, match="already holds a run"):
        Trainer(cfg, run, progress=False)


def _start_cli(args, cwd):
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    return subprocess.Popen([sys.executable, "-m", "lbgp.cli", *args], cwd=cwd, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT)


def test_kill_mid_run_then_resume_continues_from_the_checkpoint(tmp_path):
    run = tmp_path / "run"
    cfg = D4PGConfig(**dict(TINY, total_steps=100_000), seed=5)
    run.mkdir()
    # start through the Python API in a subprocess so that the kill is a real SIGKILL
    code = (
        "from lbgp.agent.config import D4PGConfig; from lbgp.agent.train import train; import json, sys\n"
        f"cfg = D4PGConfig.from_dict(json.loads({cfg.to_json()!r}))\n"
        f"train(cfg, {str(run / 'r')!r}, progress=False)\n"
    )
    log = open(tmp_path / "train.log", "w")
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=log, stderr=subprocess.STDOUT)
    ckpt = run / "r" / "checkpoint.pt"
    deadline = time.monotonic() + 180
    while time.monotonic() < deadline and proc.poll() is None:
        if ckpt.exists():
            data = torch.load(ckpt, weights_only=True)
            if data["learner"]["updates"] > 0:
                break
        time.sleep(0.5)
    else:
        proc.kill()
        pytest.fail("no checkpoint with learner updates appeared: " + (tmp_path / "train.log").read_text()[-3000:])
    import psutil

    actors = psutil.Process(proc.pid).children(recursive=True)
    assert actors, "the learner runs its actors as child processes"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)
    # the actors notice that their learner died and exit instead of lingering as orphans
    gone, alive = psutil.wait_procs(actors, timeout=60)
    for p in alive:
        p.kill()
    assert not [p for p in alive if p.name().startswith("python")], "actor processes outlived their learner"

    saved = torch.load(ckpt, weights_only=True)  # the state the resume must start from
    # rows written after the checkpoint are dropped on resume; none is corrupted
    resumed = Trainer(D4PGConfig.from_dict(saved["config"]), run / "r", resume=True, progress=False)
    assert resumed.env_steps == saved["env_steps"] and resumed.learner.updates == int(saved["learner"]["updates"])
    for k, v in saved["learner"]["actor"].items():
        torch.testing.assert_close(resumed.learner.actor.state_dict()[k], v)
    assert len(resumed.replay) == len(saved["replay"]["ret"])
    assert all(r["env_steps"] <= saved["env_steps"] for r in read_curve(run / "r" / "curve.csv"))
    assert resumed.restarts == saved["restarts"] + 1
    resumed.close()  # a Trainer holds its folder (run.lock) until it has run or is closed

    # and it really continues: run a little more through the CLI's --resume
    target = saved["env_steps"] + 150
    out = subprocess.run([sys.executable, "-m", "lbgp.cli", "train", "--resume", str(run / "r"), "--steps", str(target)],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
    summary = json.loads((run / "r" / "summary.json").read_text())
    assert summary["env_steps"] >= target and summary["learner_updates"] >= int(saved["learner"]["updates"])


def test_corrupt_checkpoint_gives_a_clear_error(tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    (run / "config.json").write_text(D4PGConfig(**TINY).to_json())
    (run / "checkpoint.pt").write_bytes(b"not a checkpoint")
    with pytest.raises(ValueError, match="not a readable lbgp-checkpoint file"):
        train(D4PGConfig(**TINY), run, resume=True, progress=False)


def test_cli_train_rejects_unknown_options_and_missing_out():
    out = subprocess.run([sys.executable, "-m", "lbgp.cli", "train", "--learning-rate", "3"], capture_output=True, text=True)
    assert out.returncode == 2 and "unrecognized arguments: --learning-rate" in out.stderr
    out = subprocess.run([sys.executable, "-m", "lbgp.cli", "train"], capture_output=True, text=True)
    assert out.returncode == 2 and "--out DIR is required" in out.stderr


def test_plot_curves(tmp_path):
    from lbgp.viz.curves import plot_learning_curves

    for seed in (0, 1):
        d = tmp_path / f"run{seed}"
        d.mkdir()
        (d / "config.json").write_text(D4PGConfig(seed=seed).to_json())
        rows = ["env_steps,wall_time_s,level,exploit_return"] + [f"{100 * i},{i},straight,{i * 0.5 + seed}" for i in range(1, 40)]
        (d / "curve.csv").write_text("\n".join(rows) + "\n")
    plot_learning_curves([tmp_path / "run0", tmp_path / "run1"], tmp_path / "curves.png")
    assert (tmp_path / "curves.png").stat().st_size > 5000
    plot_learning_curves([tmp_path / "run0", tmp_path / "run1"], tmp_path / "wall.png", x="wall_time", band="ci95")
    assert (tmp_path / "wall.png").stat().st_size > 5000
    with pytest.raises(ValueError, match="band must be one of"):
        plot_learning_curves([tmp_path / "run0"], tmp_path / "x.png", band="std")
    with pytest.raises(ValueError, match="not a training run directory"):
        plot_learning_curves([tmp_path], tmp_path / "x.png")


def test_curves_against_wall_time_and_their_confidence_band(tmp_path):
    from lbgp.viz.curves import curve_band, smoothed_curve

    d = tmp_path / "run"
    d.mkdir()
    # 10 env steps per second of wall time, return = 2 * seconds
    rows = ["env_steps,wall_time_s,level,exploit_return"] + [f"{10 * i},{i},straight,{2.0 * i}" for i in range(1, 30)]
    (d / "curve.csv").write_text("\n".join(rows) + "\n")
    by_time = smoothed_curve(d, np.array([15.0, 100.0]), window=1, x="wall_time")
    by_steps = smoothed_curve(d, np.array([150.0]), window=1)
    assert by_time[0] == pytest.approx(30.0) and by_steps[0] == pytest.approx(30.0) and np.isnan(by_time[1])
    # three runs 1, 2, 3 at a point: mean 2, 95 % CI half-width t(0.975, 2) * 1 / sqrt(3) = 2.484;
    # where one run has ended, the band uses the two left; a single run has no band
    curves = np.array([[1.0, 1.0, 5.0], [2.0, 3.0, np.nan], [3.0, np.nan, np.nan]])
    mean, half = curve_band(curves, "ci95")
    assert mean == pytest.approx([2.0, 2.0, 5.0])
    assert half == pytest.approx([2.484, 12.706 * np.sqrt(2.0) / np.sqrt(2.0), 0.0], abs=1e-3)
    mean, half = curve_band(curves, "half_std")
    assert half[0] == pytest.approx(0.5 * np.std([1.0, 2.0, 3.0]))


def test_ray_backend_trains_where_ray_is_installed(tmp_path):
    pytest.importorskip("ray")
    cfg = D4PGConfig(**TINY, seed=4)
    summary = train(cfg, tmp_path / "run", backend="ray", progress=False)
    assert summary["env_steps"] >= 300 and summary["learner_updates"] > 0
    assert load_policy(tmp_path / "run" / "policy.pt").act(np.zeros(57, np.float32)).shape == (2,)


def _replay_rows(replay) -> np.ndarray:
    n = len(replay)
    return np.hstack([replay.obs[:n], replay.action[:n], replay.ret[:n, None], replay.discount[:n, None], replay.next_obs[:n]])


def test_mirror_augment_stores_each_transition_and_its_mirror_image(tmp_path):
    """With ``mirror_augment`` the replay holds what the same seeded run collects without it, plus
    each of those transitions reflected about the person's heading line (y and phi of every relative
    state negated, the goal's lateral part negated, the same n-step return and discount)."""
    common = {**TINY, "total_steps": 60, "min_replay": 10_000}  # no learning: both runs act alike
    plain = Trainer(D4PGConfig(**common, seed=1), tmp_path / "plain", backend="inline", progress=False)
    plain.run()
    augmented = Trainer(D4PGConfig(**common, seed=1, mirror_augment=True), tmp_path / "aug", backend="inline", progress=False)
    augmented.run()
    rows = _replay_rows(plain.replay)
    assert len(rows) > 0 and len(augmented.replay) == 2 * len(rows)
    obs, act, nxt = rows[:, :57].copy(), rows[:, 57:59].copy(), rows[:, 61:].copy()
    for frame in (obs, nxt):
        frame[:, 1::3] *= -1.0
        frame[:, 2::3] *= -1.0
    act[:, 1] *= -1.0
    reflected = np.hstack([obs, act, rows[:, 59:61], nxt])
    assert not np.array_equal(reflected, rows)  # the episodes were not their own mirror images
    expected = np.vstack([rows, reflected])
    got = _replay_rows(augmented.replay)

    def by_rows(a):
        return a[np.lexsort(a.T[::-1])]

    np.testing.assert_array_equal(by_rows(got), by_rows(expected))
    assert json.loads((tmp_path / "aug" / "config.json").read_text())["mirror_augment"] is True
    assert json.loads((tmp_path / "plain" / "config.json").read_text())["mirror_augment"] is False
