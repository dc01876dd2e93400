"""What a goal policy can reach through the real planner and robot: a searched goal sequence per scenario.

    python benchmarks/goal_ceiling.py --json results/goal_ceiling.json
    python benchmarks/goal_ceiling.py --start-from lbgp --segment 1 --std 0.15 --iterations 10 \
        --scenarios turning_ahead,... --json results/goal_ceiling_refined.json
    python benchmarks/goal_ceiling.py --levels straight,circles,smoothed,trajectories --episodes 8 \
        --start-from lbgp --json results/goal_ceiling_levels.json
    ... --resume   # after a crash or a stop: keep the episodes already searched (JSON.progress.jsonl)

``lbgp.experiments.ceiling`` bounds every method from above with a relaxed point robot (no heading,
no acceleration limit); it says nothing about what the TEB planner and the real base let a *goal*
policy do. This benchmark searches, per paper scenario (Jackal, seed 0, no observation noise: the
scenario's person motion is deterministic), for the sequence of goals that earns the most reward
when the planner drives to it: the goal in the person frame is held for ``segment`` agent steps at
a time (default 7 segments of 1 s in a 35-step episode), and the cross-entropy method searches
those numbers (population 24, 6 elites, 8 iterations), started from the constant goal 1.5 m ahead
or (``--start-from lbgp``) from the goals the shipped LBGP asks for in the same episode, whose
open-loop replay is that very episode.

With ``--levels`` the same search runs on training-level episodes (random spawn 1-2.5 m around
the person, half of them behind, random person motion), each seeded as ``lbgp evaluate`` seeds it
and replayed noise-free; per level the mean over the episodes of each return is set against the
level's point-robot ceiling (``results/reward_ceiling.json``, as ``benchmarks/levels_vs_ceiling.py``
reads it): what share of it a goal policy can reach through this planner and robot.

``--react-after-deg D`` asks how much of that is anticipation: per episode the goals are held at
LBGP's own, step by step, until the person's heading has turned by D degrees from its first value
(the onset step, ``turn_onset``; the person's motion does not depend on the robot), and only the
goals from there on are searched. A policy that reacts to a turn once it shows can at best reach
this (still optimistic: after the onset the search knows the rest of the path); what the full
search gains beyond it needs knowing that a turn comes before it shows.

An open-loop sequence tuned to one deterministic episode knows the future, which no policy does,
so its return is an optimistic target for LBGP; the search is not exhaustive either, so it is a
lower bound on the best open-loop sequence (a closed-loop policy can beat a weak search). Reported
beside it: the constant goal 1.5 m ahead, HC and the shipped LBGP on the same noise-free episode,
and the relaxed point robot's ceiling.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import command_line, level_ceilings, write_result  # noqa: E402

from lbgp.actions import DESIRED_GOAL, GOAL_X, GOAL_Y, action_from_goal, goal_from_action  # noqa: E402
from lbgp.experiments.sim_table import LEAD_ROWS  # noqa: E402
from lbgp.policies import make_policy  # noqa: E402
from lbgp.planner import planner_config_for  # noqa: E402
from lbgp.rollout import run_episode  # noqa: E402
from lbgp.sim import level_names, make_env  # noqa: E402
from lbgp.sim.tasks import DEFAULT_HORIZON, SCENARIOS  # noqa: E402

TURNING, TRAJECTORIES = LEAD_ROWS["turning"], LEAD_ROWS["trajectory"]


class GoalSequencePolicy:
    """Plays a fixed goal sequence: goal ``goals[k // segment]`` (person frame, m) at agent step k;
    with a ``prefix`` (one goal per step), ``prefix[k]`` for its steps first, then the segments."""

    control = "goal"

    def __init__(self, goals, segment: int, prefix=()):
        def actions(g):
            return [action_from_goal(x).astype(np.float32) for x in np.asarray(g, float).reshape(-1, 2)]

        self.prefix, self.actions = actions(prefix), actions(goals)
        self.segment = segment
        self.k = 0

    def reset(self) -> None:
        self.k = 0

    def act(self, observation) -> np.ndarray:
        k = self.k - len(self.prefix)
        action = self.prefix[self.k] if k < 0 else self.actions[min(k // self.segment, len(self.actions) - 1)]
        self.k += 1
        return action


class RecordingPolicy:
    """Wraps a closed-loop goal policy and records the goal it asks for at each step."""

    control = "goal"

    def __init__(self, policy):
        self.policy, self.goals = policy, []

    def reset(self) -> None:
        self.goals = []
        if hasattr(self.policy, "reset"):
            self.policy.reset()

    def act(self, observation) -> np.ndarray:
        action = self.policy.act(observation)
        self.goals.append(goal_from_action(action))
        return action


def play(env, episode, policy) -> float:
    """One noise-free episode's return: a paper scenario's (fixed start; ``episode`` None) or a
    training level's seeded one (``episode``: the seed ``lbgp evaluate`` gives it, e.g. [0, k, i]:
    random spawn and person motion), replayed identically on every call."""
    if episode is not None:
        env.reseed(list(episode))
    return float(run_episode(env, policy).total_reward)


def closed_loop_goals(scenario: str, method: str, robot: str = "jackal", episode=None) -> tuple[float, np.ndarray]:
    """A closed-loop method's return on the noise-free episode and the goals it asked for."""
    policy = RecordingPolicy(make_policy(method, robot=robot, transfer=True))
    return play(make_env(scenario, robot=robot, seed=0, obs_noise=False), episode, policy), np.array(policy.goals)


def turn_onset(scenario: str, degrees: float, robot: str = "jackal", episode=None) -> int:
    """The first agent step at which the person's heading differs from its first value by at least
    ``degrees`` (noise-free; a goal chosen at that step may react to the turn), or the horizon if never."""
    env = make_env(scenario, robot=robot, seed=0, obs_noise=False)
    if episode is not None:
        env.reseed(list(episode))
    timestep, yaws = env.reset(), [env.info()["person_pose"][2]]
    while not timestep.last():
        timestep = env.step(action_from_goal(DESIRED_GOAL))
        yaws.append(env.info()["person_pose"][2])
    turned = np.abs(np.degrees(np.unwrap(yaws) - yaws[0]))[:DEFAULT_HORIZON]
    hits = np.flatnonzero(turned >= degrees)
    return int(hits[0]) if hits.size else DEFAULT_HORIZON


def padded_to_horizon(goals) -> np.ndarray:
    """A per-step goal sequence (k, 2) extended to the episode's horizon by repeating its last goal: a
    closed-loop method's goals stop where its episode ended early (a contact), and the steps after
    that are never played, so any goal there replays the same episode."""
    goals = np.asarray(goals, float).reshape(-1, 2)
    if len(goals) == 0:
        raise ValueError("a start sequence needs at least one goal")
    return np.vstack([goals, np.repeat(goals[-1:], max(0, DEFAULT_HORIZON - len(goals)), axis=0)])


def search(scenario: str, robot: str = "jackal", segment: int = 5, population: int = 24, elites: int = 6,
           iterations: int = 8, std: float = 0.4, seed: int = 0, start=None, episode=None, frozen: int = 0) -> dict:
    """Cross-entropy search over one episode's goal sequence; returns the best sequence and its return.

    ``start``: a per-step goal sequence (35, 2) to start from (e.g. a closed-loop method's goals,
    whose open-loop replay is the same episode), averaged over each segment; default the constant
    goal 1.5 m ahead. ``episode``: a training level's episode seed (``episode_env``). ``frozen``:
    the first steps play ``start``'s goals unchanged and only the later ones are searched (needs
    ``start``); ``goals`` then holds the searched segments, ``prefix`` the frozen steps."""
    if frozen and start is None:
        raise ValueError("a frozen prefix needs a start sequence to freeze")
    env = make_env(scenario, robot=robot, seed=0, obs_noise=False)
    rng = np.random.default_rng(seed)
    frozen = min(int(frozen), DEFAULT_HORIZON - 1)
    segments = -(-(DEFAULT_HORIZON - frozen) // segment)
    lo, hi = np.array([GOAL_X[0], GOAL_Y[0]]), np.array([GOAL_X[1], GOAL_Y[1]])
    if start is not None:
        start = padded_to_horizon(start)
    prefix = start[:frozen] if frozen else np.zeros((0, 2))

    def score(goals):
        return play(env, episode, GoalSequencePolicy(goals, segment, prefix))

    constant = play(env, episode, GoalSequencePolicy([DESIRED_GOAL], DEFAULT_HORIZON))
    if start is None:
        mean = np.tile(np.asarray(DESIRED_GOAL, float), (segments, 1))
        best = constant
    else:
        rest = start[frozen:]
        mean = np.array([rest[k * segment : (k + 1) * segment].mean(axis=0) for k in range(segments)])
        best = score(mean)
    sigma = np.full_like(mean, std)
    best_goals = mean.copy()
    history = [best]
    for _ in range(iterations):
        samples = np.clip(mean + sigma * rng.standard_normal((population, *mean.shape)), lo, hi)
        samples[0] = best_goals  # elitism: the best so far is always re-scored (deterministic: same value)
        returns = np.array([score(s) for s in samples])
        order = np.argsort(returns)[::-1]
        if returns[order[0]] > best:
            best, best_goals = float(returns[order[0]]), samples[order[0]].copy()
        elite = samples[order[:elites]]
        mean, sigma = elite.mean(axis=0), np.maximum(elite.std(axis=0), 0.02)
        history.append(best)
    row = {"constant_1_5": float(constant), "start": history[0], "best": float(best), "goals": best_goals.tolist(),
           "history": [float(h) for h in history], "rollouts": 1 + (start is not None) + iterations * population}
    if frozen:
        row["prefix"] = prefix.tolist()
    return row


def one(args) -> dict:
    scenario, robot, start_from, kwargs, episode, *react = args
    hc, _ = closed_loop_goals(scenario, "hc", robot, episode)
    lbgp, lbgp_goals = closed_loop_goals(scenario, "lbgp", robot, episode)
    onset = turn_onset(scenario, react[0], robot, episode) if react and react[0] is not None else 0
    row = search(scenario, robot, start=lbgp_goals if start_from == "lbgp" else None, episode=episode, frozen=onset, **kwargs)
    row["start_from"] = start_from
    if onset:
        row["onset_step"] = onset
    row["hc"], row["lbgp"] = hc, lbgp
    if episode is None:
        from lbgp.experiments.ceiling import scenario_ceiling

        row["point_robot_ceiling"] = scenario_ceiling(scenario, planner_config_for(robot).max_vel_x)
    else:
        row["episode"] = list(episode)
    print(f"{scenario}{'' if episode is None else f' {list(episode)}'}: searched {row['best']:.2f}  constant "
          f"{row['constant_1_5']:.2f}  HC {row['hc']:.2f}  LBGP {row['lbgp']:.2f}", flush=True)
    return row


def _indexed(job):
    index, args = job
    return index, one(args)


def run_jobs(jobs: list, workers: int, progress: Path, settings: dict, resume: bool) -> list:
    """Every job's row, in the jobs' order. Each row is appended to ``progress`` (JSON lines, the
    settings first) as soon as its job finishes, so a crash or a stopped run loses only the jobs in
    flight; ``resume`` takes the rows of a progress file with the same settings and runs the rest.
    The file is removed once every job is done."""
    settings = json.loads(json.dumps(settings))  # as the file holds them (tuples become lists)
    done: dict[int, dict] = {}
    if resume and progress.is_file():
        lines = [json.loads(line) for line in progress.read_text().splitlines() if line.strip()]
        if not lines or lines[0].get("settings") != settings:
            raise ValueError(f"{progress}: made with other settings ({lines[0].get('settings') if lines else 'empty'}); "
                             "rerun without --resume to start again")
        done = {int(line["index"]): line["row"] for line in lines[1:]}
    else:
        progress.parent.mkdir(parents=True, exist_ok=True)
        progress.write_text(json.dumps({"settings": settings}) + "\n")
    todo = [(i, job) for i, job in enumerate(jobs) if i not in done]
    with multiprocessing.get_context("spawn").Pool(workers) as pool, progress.open("a") as log:
        for index, row in pool.imap_unordered(_indexed, todo, chunksize=1):
            done[index] = row
            log.write(json.dumps({"index": index, "row": row}) + "\n")
            log.flush()
    progress.unlink()
    return [done[i] for i in range(len(jobs))]


def level_summary(rows: list, ceiling: float) -> dict:
    """Mean over a level's episodes of each return, and its share of the level's point-robot ceiling.
    ``best_known``: per episode the best of the search, the constant goal, HC and LBGP (each a goal
    sequence that replays to its return)."""
    for r in rows:
        r["best_known"] = max(r["best"], r["constant_1_5"], r["hc"], r["lbgp"])
    means = {k: round(float(np.mean([r[k] for r in rows])), 3) for k in ("best_known", "best", "constant_1_5", "hc", "lbgp")}
    return {"mean": means, "point_robot_ceiling": round(ceiling, 3),
            "share_of_ceiling": {k: round(v / ceiling, 3) for k, v in means.items()}, "episodes": rows}


def main(argv=None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--json", default="results/goal_ceiling.json")
    p.add_argument("--robot", default="jackal", choices=("jackal", "turtlebot2"))
    p.add_argument("--scenarios", default=",".join(SCENARIOS))
    p.add_argument("--levels", default="", help="training levels to search instead of scenarios (e.g. straight,circles)")
    p.add_argument("--episodes", type=int, default=8, help="seeded episodes per level (with --levels)")
    p.add_argument("--seed", type=int, default=0, help="episode i of level k is seeded [seed, k, i], as lbgp evaluate does")
    p.add_argument("--ceiling", default="results/reward_ceiling.json", help="the levels' point-robot ceilings (with --levels)")
    p.add_argument("--iterations", type=int, default=8)
    p.add_argument("--population", type=int, default=24)
    p.add_argument("--segment", type=int, default=5, help="agent steps each goal is held")
    p.add_argument("--std", type=float, default=0.4, help="initial search spread of each goal coordinate (m)")
    p.add_argument("--start-from", choices=("constant", "lbgp"), default="constant",
                   help="start the search at the constant goal 1.5 m ahead or at the shipped LBGP's goals")
    p.add_argument("--react-after-deg", type=float, default=None,
                   help="hold LBGP's own goals until the person has turned by this many degrees, search only after "
                        "(needs --start-from lbgp)")
    p.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1))
    p.add_argument("--resume", action="store_true",
                   help="keep the rows of an interrupted run with the same settings (JSON.progress.jsonl) and run the rest")
    args = p.parse_args(argv)
    if args.react_after_deg is not None and (args.start_from != "lbgp" or args.react_after_deg <= 0):
        p.error("--react-after-deg needs --start-from lbgp and a positive angle")
    kwargs = dict(iterations=args.iterations, population=args.population, segment=args.segment, std=args.std)
    settings = {**kwargs, "start_from": args.start_from}
    if args.react_after_deg is not None:
        settings["react_after_deg"] = args.react_after_deg
    if args.levels:
        all_levels = level_names()
        levels = [name for name in args.levels.split(",") if name]
        unknown = sorted(set(levels) - set(all_levels))
        if unknown:
            p.error(f"unknown levels {unknown}; use {', '.join(all_levels)}")
        # the ceilings as benchmarks/levels_vs_ceiling.py reads them (top speed, finest grid)
        ceilings = {name: r["mean_bound"] for name, r in level_ceilings(args.ceiling).items()}
        jobs = [(name, args.robot, args.start_from, kwargs, (args.seed, all_levels.index(name), i), args.react_after_deg)
                for name in levels for i in range(args.episodes)]
    else:
        jobs = [(s, args.robot, args.start_from, kwargs, None, args.react_after_deg) for s in args.scenarios.split(",") if s]
    progress = Path(f"{args.json}.progress.jsonl")
    try:
        which = [[name, robot, episode] for name, robot, _, _, episode, _ in jobs]  # what each job searches
        done = run_jobs(jobs, args.workers, progress, {**settings, "jobs": which}, args.resume)
    except ValueError as error:
        p.error(str(error))
    if args.levels:
        rows = {name: level_summary([r for j, r in zip(jobs, done) if j[0] == name], ceilings[name]) for name in levels}
        result = {"benchmark": "goal_ceiling_levels", "robot": args.robot, "settings": {**settings, "episodes": args.episodes},
                  "command": command_line("goal_ceiling.py", argv), "levels": rows}
        write_result(args.json, result)
        return result
    rows = {j[0]: r for j, r in zip(jobs, done)}
    sums = {}
    for group, names in (("turning", TURNING), ("trajectories", TRAJECTORIES)):
        if all(n in rows for n in names):
            sums[group] = {k: round(sum(rows[n][k] for n in names), 2)
                           for k in ("best", "constant_1_5", "hc", "lbgp", "point_robot_ceiling")}
    result = {"benchmark": "goal_ceiling", "robot": args.robot, "settings": settings,
              "command": command_line("goal_ceiling.py", argv), "scenarios": rows, "sums": sums}
    write_result(args.json, result)
    return result


if __name__ == "__main__":
    main()
