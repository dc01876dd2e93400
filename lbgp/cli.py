"""The ``lbgp`` command line."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from lbgp import cli_args as A
from lbgp.files import write_json
from lbgp.policies import default_policy_path


def _print_table(rows: list[dict]) -> None:
    header = (f"{'episode':<18}{'steps':>6}{'reward':>9}{'D mean':>8}{'D std':>7}{'alpha mean':>11}{'alpha std':>10}"
              f"{'|alpha| 2nd half':>17}  end")
    print(header)
    print("-" * len(header))
    for r in rows:
        end = "contact" if r["collision"] else ("terminated" if r["terminated_early"] else "horizon")
        print(
            f"{r['setting']:<18}{r['steps']:>6d}{r['reward']:>9.2f}{r['distance_mean']:>8.2f}{r['distance_std']:>7.2f}"
            f"{r['alpha_mean_deg']:>11.1f}{r['alpha_std_deg']:>10.1f}{r['abs_alpha_second_half_deg']:>17.1f}  {end}"
        )


def cmd_demo(args) -> int:
    from lbgp.rollout import ConstantGoalPolicy, run_episode
    from lbgp.sim import make_env
    from lbgp.sim.tasks import CURRICULUM
    from lbgp.stack import policy_planner, policy_planner_note
    from lbgp.viz.recording import EpisodeRecorder

    out = Path(args.out)
    policy_file = Path(args.policy) if args.policy else default_policy_path()
    if args.scripted:
        policy, policy_name = ConstantGoalPolicy(), "scripted goal 1.5 m ahead of the person"
    elif policy_file.is_file():
        from lbgp.agent import load_policy

        policy, policy_name = load_policy(policy_file), f"{policy_file}"
    elif args.policy:
        raise FileNotFoundError(f"{policy_file}: no such policy file")
    else:
        policy, policy_name = ConstantGoalPolicy(), "scripted goal 1.5 m ahead of the person (no pretrained policy found)"
    print(f"lbgp demo: robot={args.robot} seed={args.seed} policy: {policy_name}")
    if note := policy_planner_note(policy, args.robot):
        print(note)
    rows = []
    with EpisodeRecorder(out / "demo.rrd") as recorder:
        for i, level in enumerate(CURRICULUM):
            env = make_env(level, robot=args.robot, seed=args.seed + i, control=policy.control,
                           planner_config=policy_planner(policy, args.robot))
            rows.append(run_episode(env, policy, recorder, episode_index=i).summary())
    _print_table(rows)
    summary = {"robot": args.robot, "seed": args.seed, "policy": policy_name, "episodes": rows}
    write_json(out / "summary.json", summary)
    print(f"wrote {out / 'demo.rrd'} (open with: rerun {out / 'demo.rrd'}) and {out / 'summary.json'}")
    return 0


def cmd_evaluate(args) -> int:
    from lbgp.evaluate import evaluate, resolve_names
    from lbgp.policies import make_policy
    from lbgp.stack import policy_planner_note

    policy = make_policy(args.method, args.policy, args.hc_distance, args.hc_horizon, robot=args.robot, transfer=args.transfer,
                         goal_deadband=args.goal_deadband, mirror_average=False if args.no_mirror else None)
    names = resolve_names(args.scenario)
    if note := policy_planner_note(policy, args.robot):
        print(note)
    recorder = None
    if args.record or args.spawn:
        from lbgp.viz.recording import EpisodeRecorder

        recorder = EpisodeRecorder(args.record, spawn=args.spawn)
    try:
        results = evaluate(policy, args.method, names, robot=args.robot, episodes=args.episodes, seed=args.seed,
                           recorder=recorder, person_path=args.person_path, dynamics=args.dynamics,
                           calibration=args.calibration, drive_model=args.drive_model)
    finally:
        if recorder is not None:
            recorder.close()
    print(f"{'scenario':<18}{'D mean+-std':>14}{'alpha mean+-std':>18}{'reward':>9}{'coll':>6}{'early':>6}{'steps':>7}")
    for r in results:
        print(f"{r['scenario']:<18}{r['distance_mean']:>7.2f}+-{r['distance_std']:<5.2f}{r['alpha_mean_deg']:>9.1f}+-{r['alpha_std_deg']:<6.1f}"
              f"{r['reward']:>9.2f}{r['collisions']:>6d}{r['terminated_early']:>6d}{r['steps']:>7.1f}")
    if args.json:
        write_json(Path(args.json), results)
    return 0


def training_setting(text: str) -> tuple:
    """``NAME=VALUE`` for ``lbgp train --set`` (an argparse type): a settable training-config field
    and a valid value (D4PGConfig.parse_setting); lives here, not in cli_args, which is below the agent."""
    from lbgp.agent.config import D4PGConfig

    try:
        return D4PGConfig.parse_setting(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


# `lbgp train` options that also apply to --resume; every other option describes a new run and
# --resume refuses it (the parser hands cmd_train that list as args.new_run_options: dest -> option)
TRAIN_RESUME_OPTIONS = ("help", "steps", "minutes", "backend", "resume")


def cmd_train(args) -> int:
    from lbgp.agent.config import D4PGConfig
    from lbgp.agent.train import train

    if args.resume:
        changed = [option for dest, option in args.new_run_options.items()
                   if getattr(args, dest) is not None and getattr(args, dest) is not False]  # --seed 0 counts
        if changed:
            raise ValueError(f"--resume continues the run with its own config ({args.resume}/config.json); "
                             f"{', '.join(changed)} would be ignored: drop it or start a new run with --out")
        cfg = D4PGConfig(total_steps=args.steps or 0, time_limit_s=(args.minutes or 0) * 60.0)
        summary = train(cfg, args.resume, resume=True, backend=args.backend)
    else:
        if not args.out:
            raise ValueError("--out DIR is required (or --resume DIR)")
        preset = D4PGConfig.paper if args.paper else D4PGConfig
        chosen = dict(
            curriculum=not args.no_curriculum,
            total_steps=args.steps or D4PGConfig.total_steps, time_limit_s=(args.minutes or 0) * 60.0,
        )
        given = {"method": args.method, "robot": args.robot, "seed": args.seed,  # None: the config's default
                 "num_actors": args.actors, "prior_weight": args.prior_weight, "turn_lead": args.turn_lead, "max_updates_per_step": args.updates_per_step,
                 "mirror_augment": True if args.mirror_augment else None, "motion_features": True if args.motion_features else None,
                 "previous_goal": True if args.previous_goal else None, "policy_average": args.policy_average,
                 "init_policy": str(args.init_policy) if args.init_policy else None}
        if args.randomize:
            from lbgp.dynamics import load_randomization

            given["randomize"] = load_randomization(args.randomize).to_dict()
        given.update(dict(args.set or []))  # --set NAME=VALUE, last one wins
        cfg = preset(**chosen, **{k: v for k, v in given.items() if v is not None}).validate()
        summary = train(cfg, args.out, backend=args.backend)
    print(json.dumps(summary, indent=2))
    return 130 if summary.get("interrupted") else 0


def _stop_on_signals():
    """SIGTERM and SIGHUP end ``lbgp deploy`` as Ctrl-C does (zero command, summary, closed log);
    returns the previous handlers. A second signal while stopping is ignored. SIGINT gets Python's
    own handler (KeyboardInterrupt) even when the process inherited it ignored, as a command started
    in the background by a non-interactive shell (``nohup lbgp deploy ... &``) does: otherwise
    ``kill -INT`` would not stop the robot."""
    import signal

    from lbgp.real.loop import StopRequested

    stopping = []

    def handler(number, frame):
        if not stopping:
            stopping.append(number)
            raise StopRequested(signal.Signals(number).name)

    previous = {signal.SIGINT: signal.signal(signal.SIGINT, signal.default_int_handler)}
    for sig in (signal.SIGTERM, getattr(signal, "SIGHUP", None)):
        if sig is not None:
            previous[sig] = signal.signal(sig, handler)
    return previous


def cmd_deploy(args) -> int:
    import signal

    from lbgp.policies import make_policy
    from lbgp.real.deploy import deploy
    from lbgp.stack import policy_planner_note

    policy = make_policy(args.method, args.policy, robot=args.robot, transfer=args.transfer, goal_deadband=args.goal_deadband,
                         mirror_average=False if args.no_mirror else None)
    print(f"lbgp deploy: {args.method} policy, source {args.source}, sink {args.sink or 'default'}, robot {args.robot}"
          + (f", logging to {args.log}" if args.log else ""), flush=True)
    if note := policy_planner_note(policy, args.robot):
        print(f"lbgp deploy: {note}", flush=True)
    previous = _stop_on_signals()
    try:
        loop = deploy(policy, source=args.source, sink=args.sink, robot=args.robot, steps=args.steps, log=args.log,
                      record=args.record, spawn_viewer=args.spawn, seed=args.seed, person_path=args.person_path,
                      planner_time_budget=args.planner_budget_ms / 1e3 if args.planner_budget_ms > 0 else None,
                      metadata={"method": args.method, "policy": args.policy or "default"},
                      first_pose_timeout=args.first_pose_timeout or None, dynamics=args.dynamics, calibration=args.calibration,
                      drive_model=args.drive_model, on_open=lambda msg: print(f"lbgp deploy: {msg}", file=sys.stderr, flush=True),
                      on_wait=lambda msg: print(f"lbgp deploy: {msg}", file=sys.stderr, flush=True))
    except KeyboardInterrupt:  # before the loop ran (opening the source, the log, the viewer)
        print("interrupted before the loop started: no command was sent", file=sys.stderr)
        return 130
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    summary = {"end": loop.end_reason, "ticks": loop.ticks, "agent_steps": loop.agent_steps, **loop.metrics.summary(),
               "rejected_frames": loop.monitor.counts}
    if hasattr(loop.cfg.calibration, "gains"):  # --calibration online: what it learned about the robot
        summary["calibration"] = {**loop.cfg.calibration.to_dict(), "gains": loop.cfg.calibration.gains}
    if loop.error is not None:
        summary["error"] = f"{type(loop.error).__name__}: {loop.error}"
    print(json.dumps(summary, indent=2))
    if args.json:
        write_json(Path(args.json), summary)
    if loop.error is not None:
        print(f"lbgp deploy: error: {summary['error']} (a zero command was sent)", file=sys.stderr)
        return 1
    if loop.end_reason == "no_pose":
        print(f"lbgp deploy: error: no valid pose from {args.source} within {args.first_pose_timeout:g} s "
              f"(--first-pose-timeout); the robot was held stopped", file=sys.stderr)
        return 1
    if loop.end_reason == "interrupted":
        print("interrupted: a zero command was sent", file=sys.stderr)
        return 130
    if loop.end_reason.startswith("signal "):
        name = loop.end_reason.split()[1]
        print(f"stopped by {name}: a zero command was sent", file=sys.stderr)
        return 128 + int(getattr(signal, name))
    return 0


def cmd_replay(args) -> int:
    from lbgp.real.replay import replay_log

    recorder = None
    if args.record:
        from lbgp.viz.recording import EpisodeRecorder

        recorder = EpisodeRecorder(args.record)
    try:
        metrics, log = replay_log(args.log, recorder)
    finally:
        if recorder is not None:
            recorder.close()
    summary = {"log": args.log, "truncated": log["truncated"], "metadata": log["metadata"], **metrics.summary()}
    print(json.dumps(summary, indent=2))
    if args.json:
        write_json(Path(args.json), summary)
    return 0


def cmd_experiment(args) -> int:
    command = "lbgp experiment " + " ".join(sys.argv[2:]) if sys.argv[1:2] == ["experiment"] else f"lbgp experiment {args.which}"
    policies = {"lbgp": args.lbgp_policy, "e2e": args.e2e_policy}
    if args.which == "sim":
        from lbgp.experiments.sim_table import run_sim_table

        run_sim_table(args.out, episodes=args.episodes, seed=args.seed, scenarios=args.scenarios, policies=policies,
                      horizon=args.horizon, command=command, obs_noise=not args.no_noise)
        print(Path(args.out, "sim_table.md").read_text())
    elif args.which == "real-protocol":
        from lbgp.experiments.real_protocol import run_real_protocol

        if args.robot != "turtlebot2":
            raise ValueError("the real-world protocol uses the TurtleBot 2 (the paper's robot): --robot turtlebot2")
        run_real_protocol(args.out, steps=args.steps, seed=args.seed, paths=args.paths, policies=policies, repeats=args.repeats,
                          command=command, dynamics_sets=args.dynamics, jobs=args.jobs)
        tables = {"nominal": "real_protocol_table.md", "hardware_like": "real_protocol_hardware_table.md"}
        written = [tables[d] for d in args.dynamics] + (["real_protocol_gap.md"] if len(set(args.dynamics)) == 2 else [])
        for name in written:
            print(Path(args.out, name).read_text())
    else:
        from lbgp.experiments.ablation import run_ablation

        report = run_ablation(args.out, minutes=args.minutes, seeds=args.seeds, steps=args.max_steps, backend=args.backend,
                              runs_dir=args.runs_dir, command=command, max_new_runs=args.max_new_runs)
        print(json.dumps({k: v.get("final_exploit_return_mean_last20") for k, v in report["runs"].items()}, indent=2))
        if report["missing_runs"]:
            print(f"not trained yet (run the same command again): {', '.join(report['missing_runs'])}")
        if report["runs"]:
            print(f"wrote {Path(args.out, 'ablation_curves.png')}")
    return 0


GOAL_DEADBAND_HELP = ("LBGP: shrink the policy's residual goal this far toward the goal 1.5 m ahead "
                      "(m; default 0.075, docs/training.md; 0: the actor's raw goal)")
NO_MIRROR_HELP = ("act with the actor's own answer instead of the mean of its answers to the observation and to its mirror "
                  "image (lbgp, e2e; docs/training.md)")
DRIVE_MODEL_HELP = ("the planner's model of the robot's drive: none (default: it acts at once), hardware_like, or lbgp sysid's "
                    "JSON; goal methods (lbgp, hc) then plan within its acceleration limits from the state predicted one latency ahead")


def _names(text: str) -> list[str]:
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise argparse.ArgumentTypeError("needs at least one name")
    return names


def _seed_list(text: str) -> list[int]:
    return [A.seed(x) for x in _names(text)]


def cmd_plot_curves(args) -> int:
    from lbgp.viz.curves import plot_learning_curves

    plot_learning_curves(args.run_dirs, args.out, labels=args.labels, x=args.x, band=args.band)
    print(f"wrote {args.out}")
    return 0


def cmd_sysid(args) -> int:
    if args.excite:
        return _sysid_excite(args)
    if not args.log_file:
        raise ValueError("name the log to fit (lbgp sysid LOG.mcap --robot ROBOT --out dynamics.json), or record one with --excite")
    from lbgp.dynamics import save_dynamics
    from lbgp.real.sysid import identify, plot_fit

    result = identify(args.log_file, args.robot)
    summary = result.summary()
    print(f"lbgp sysid: {args.log_file}, robot {args.robot}, {summary['duration_s']} s of data, {result.poses} poses from {result.pose_topic}")
    for key, value in summary.items():
        print(f"  {key:<18}{'not limiting' if value is None else value}")
    if args.out:
        save_dynamics(Path(args.out), result.dynamics, extra={"fit": summary, "log": str(args.log_file), "robot": args.robot})
        print(f"dynamics written to {args.out} (simulate this robot: --dynamics {args.out}; calibrate commands for it: --calibration {args.out})")
    if args.png:
        plot_fit(result, Path(args.png))
        print(f"measured vs simulated velocity: {args.png}")
    return 0


def _sysid_excite(args) -> int:
    import signal

    from lbgp.real.sysid import record_excitation

    if not args.log:
        raise ValueError("--excite records a log: name it with --log FILE.mcap")
    print(f"lbgp sysid --excite: ~41 s of steps and a chirp on {args.robot}, log {args.log}", flush=True)
    previous = _stop_on_signals()
    try:
        loop = record_excitation(args.robot, args.log, source=args.source, sink=args.sink, dynamics=args.dynamics, seed=args.seed,
                                 on_open=lambda msg: print(f"lbgp sysid: {msg}", file=sys.stderr, flush=True))
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    if loop.error is not None:
        raise ValueError(f"excitation stopped: {loop.error}")
    print(f"recorded {loop.ticks} ticks ({loop.end_reason}); fit it with: lbgp sysid {args.log} --robot {args.robot} --out dynamics.json")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = A.OneLineParser(prog="lbgp", description="Learning Based Goal Planning: a robot that walks in front of a person.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True, parser_class=A.OneLineParser)

    p = sub.add_parser("demo", help="run one seeded episode per curriculum level, write a rerun recording and a summary")
    p.add_argument("--robot", default="jackal", choices=["jackal", "turtlebot2"])
    p.add_argument("--seed", type=A.seed, default=0)
    p.add_argument("--out", type=A.output_dir, default="demo_out", help="output folder (default: demo_out)")
    p.add_argument("--policy", type=A.input_file, help="policy file (default: the shipped pretrained LBGP policy for the Jackal)")
    p.add_argument("--scripted", action="store_true", help="use the scripted goal 1.5 m ahead instead of a policy")
    p.set_defaults(func=cmd_demo)

    p = sub.add_parser("evaluate", help="seeded episodes of a method on levels or scenarios; metrics table and JSON")
    p.add_argument("--method", default="lbgp", choices=["lbgp", "e2e", "hc", "scripted"])
    p.add_argument("--policy", type=A.input_file, help="policy file (default: the shipped pretrained one for the method)")
    p.add_argument("--hc-distance", type=A.distance, default=None, help="HC: goal distance ahead of the predicted person (m, default 1.5)")
    p.add_argument("--hc-horizon", type=A.nonnegative_float, default=None, help="HC: EKF prediction horizon (s, default 0: the planner predicts the goal)")
    p.add_argument("--scenario", default="all", help="all (paper scenarios), levels, or comma-separated names")
    p.add_argument("--robot", default="jackal", choices=["jackal", "turtlebot2"])
    p.add_argument("--episodes", type=A.positive_int, default=10)
    p.add_argument("--seed", type=A.seed, default=0)
    p.add_argument("--person-path", type=A.input_file, help="CSV of x,y waypoints for the person (replaces the scenario's motion)")
    p.add_argument("--json", type=A.output_file, help="write the metrics here")
    p.add_argument("--record", type=A.output_file, help="write a rerun recording (.rrd) of every episode")
    p.add_argument("--spawn", action="store_true", help="also open a live rerun viewer (when one is installed)")
    p.add_argument("--transfer", action="store_true", help="allow a policy file trained on another robot (zero-shot transfer)")
    p.add_argument("--goal-deadband", type=A.nonnegative_float, default=None, metavar="M", help=GOAL_DEADBAND_HELP)
    p.add_argument("--no-mirror", action="store_true", help=NO_MIRROR_HELP)
    p.add_argument("--dynamics", type=A.dynamics_spec, default=None,
                   help="robot dynamics: nominal (default), hardware_like, or a JSON file (e.g. from lbgp sysid)")
    p.add_argument("--calibration", type=A.calibration_spec, default=None,
                   help="command calibration: none (default), online (the robot's gains estimated while driving) or lbgp sysid's JSON "
                        "(commands scaled so the robot answers like the simulated one)")
    p.add_argument("--drive-model", type=A.drive_model_spec, default=None, help=DRIVE_MODEL_HELP)
    p.set_defaults(func=cmd_evaluate)

    p = sub.add_parser("train", help="train a D4PG policy (LBGP goals or E2E velocities), with curriculum")
    # the options that say what a new run is default to None (or False): `--resume`, which continues with
    # the run's own config.json, refuses any of them that was given (TRAIN_RESUME_OPTIONS)
    p.add_argument("--method", default=None, choices=["lbgp", "e2e"], help="lbgp (default) or e2e")
    p.add_argument("--robot", default=None, choices=["jackal", "turtlebot2"], help="jackal (default) or turtlebot2")
    p.add_argument("--no-curriculum", action="store_true", help="train on the final level from the start")
    p.add_argument("--steps", type=A.positive_int, default=None, help="environment steps in all (default 300000)")
    p.add_argument("--minutes", type=A.positive_float, default=None, help="also stop after this much wall time")
    p.add_argument("--seed", type=A.seed, default=None, help="default 0")
    p.add_argument("--actors", type=A.positive_int, default=None, help="actor processes, one of them exploits (default 2: one per core beside the learner's on 2 cores)")
    p.add_argument("--prior-weight", type=A.nonnegative_float, default=None,
                   help="LBGP: pull the goals toward 1.5 m ahead with this weight in the actor loss (default 1; --paper: 0)")
    p.add_argument("--turn-lead", type=A.nonnegative_float, default=None, metavar="M_PER_RAD_S",
                   help="LBGP: a turn-aware base goal, this much farther ahead per rad/s of the person's turn rate (default 0: 1.5 m ahead)")
    p.add_argument("--updates-per-step", type=A.positive_float, default=None,
                   help="the learner's updates per collected env step at most (default 2; --paper: 1)")
    p.add_argument("--randomize", type=A.randomize_spec, default=None, metavar="PRESET|FILE",
                   help="domain randomisation per episode: a preset (default, none) or a JSON file of ranges (docs/simulation.md)")
    p.add_argument("--mirror-augment", action="store_true",
                   help="also store every transition's mirror image (about the person's heading line) in the replay")
    p.add_argument("--motion-features", action="store_true",
                   help="actor and critic also see the person's velocity and turn rate and the robot's velocity, read off the observation")
    p.add_argument("--previous-goal", action="store_true",
                   help="actor and critic also see the action sent one step before (the previous goal); the policy carries it")
    p.add_argument("--policy-average", type=A.fraction, default=None, metavar="TAU",
                   help="the policy file holds a moving average of the actor's weights, moved TAU toward it per update "
                        "(e.g. 1e-4; default 0: the last actor); the last actor is kept as policy_last.pt")
    p.add_argument("--init-policy", type=A.input_file, default=None, metavar="FILE",
                   help="start the actor from this policy file (fine-tuning: its weights and input standardisation; "
                        "the critic starts fresh); the file must fit the run's configuration")
    p.add_argument("--set", type=training_setting, action="append", metavar="NAME=VALUE",
                   help="change one training-config field that has no option of its own, over the preset "
                        "(repeatable; e.g. spawn_front_share=0.5, noise_correlation=0, sigma=0.3; "
                        "the fields: D4PGConfig.SETTABLE, docs/training.md)")
    p.add_argument("--paper", action="store_true",
                   help="the paper's plain D4PG configuration: tanh actor on raw inputs, white noise 0.3, uniform spawns, no goal prior")
    p.add_argument("--backend", default="processes", choices=["processes", "inline", "ray"],
                   help="processes: actor processes (default); inline: one process, reproducible; ray: Ray tasks (extra)")
    p.add_argument("--out", type=A.output_dir, help="run directory (created)")
    p.add_argument("--resume", type=A.existing_dir, metavar="DIR", help="continue the run in DIR from its last checkpoint")
    p.set_defaults(func=cmd_train, new_run_options={a.dest: a.option_strings[0] for a in p._actions
                                                    if a.option_strings and a.dest not in TRAIN_RESUME_OPTIONS})

    p = sub.add_parser("experiment", help="the paper's experiments: sim table, real-world protocol in sim, ablation")
    exp = p.add_subparsers(dest="which", metavar="EXPERIMENT", required=True)
    for name, help_text in (("sim", "9 scenarios x LBGP/HC/E2E on the Jackal -> results/sim_table.md + .csv"),
                            ("real-protocol", "Straight/S-shape/U-turn x 4 settings on the TurtleBot 2 through the deploy loop with "
                                              "simulated mocap -> results/real_protocol_table.md + .csv"),
                            ("ablation", "train LBGP, LBGP-no-curriculum and E2E over seeds -> results/ablation_curves.png")):
        q = exp.add_parser(name, help=help_text)
        q.add_argument("--out", type=A.output_dir, default="results", help="output folder (default: results)")
        q.add_argument("--seed", type=A.seed, default=0)
        q.add_argument("--lbgp-policy", type=A.input_file, help="LBGP policy file (default: the shipped one)")
        q.add_argument("--e2e-policy", type=A.input_file, help="E2E policy file (default: the shipped one)")
        if name == "sim":
            q.add_argument("--episodes", type=A.positive_int, default=20, help="seeded episodes per scenario and method (default 20)")
            q.add_argument("--no-noise", action="store_true", help="switch the observation noise off (default: the paper's noise on)")
            q.add_argument("--horizon", type=A.positive_int, default=35, help="agent steps per episode")
            q.add_argument("--scenarios", type=_names, help="comma-separated subset of the 9 scenarios")
        if name == "real-protocol":
            q.add_argument("--robot", default="turtlebot2", choices=["turtlebot2", "jackal"])
            q.add_argument("--steps", type=A.positive_int, default=60, help="agent steps per setting (constant, as in the paper)")
            q.add_argument("--repeats", type=A.positive_int, default=20,
                           help="runs per setting (different mocap noise, the same seeds for every method; default 20: "
                                "a row's winner needs separated 95 %% intervals)")
            q.add_argument("--paths", type=_names, help="comma-separated subset of straight,s_shape,u_turn")
            q.add_argument("--dynamics", type=_names, default=["nominal", "hardware_like"],
                           help="comma-separated dynamics sets: nominal (trained on), hardware_like (the held-out robot); default both")
            q.add_argument("--jobs", type=A.positive_int, default=1,
                           help="processes, one per (dynamics set, method) at a time (default 1; the same numbers with any count)")
        if name == "ablation":
            q.add_argument("--minutes", type=A.positive_float, default=30.0, help="wall-time budget per training run (default 30)")
            q.add_argument("--seeds", type=_seed_list, default=[0, 1, 2], help="comma-separated seeds (default 0,1,2)")
            q.add_argument("--max-steps", type=A.positive_int, help="also stop each run after this many env steps")
            q.add_argument("--backend", default="processes", choices=["processes", "inline", "ray"])
            q.add_argument("--runs-dir", type=A.output_dir, help="where the training runs go (default: runs/ablation); runs found there resume")
            q.add_argument("--max-new-runs", type=A.positive_int, help="train at most this many runs now; finished runs are kept in "
                           "OUT/ablation_runs and reused, so the same command later trains the rest")
        q.set_defaults(func=cmd_experiment)

    p = sub.add_parser("deploy", help="run a policy on a robot (or the simulated one): poses in, commands out")
    p.add_argument("--method", default="lbgp", choices=["lbgp", "e2e", "hc", "scripted"])
    p.add_argument("--policy", type=A.input_file, help="policy file (default: the shipped pretrained Jackal policy of the method)")
    p.add_argument("--source", default="sim", help="vicon://HOST, optitrack://HOST, udp://[HOST:]PORT[?from=IP], mcap://FILE or sim[://SCENARIO]")
    p.add_argument("--sink", help="udp://HOST:PORT, ros2[:///TOPIC], sim or none (default: sim for a sim source, else none)")
    p.add_argument("--robot", default="turtlebot2", choices=["jackal", "turtlebot2"])
    p.add_argument("--steps", type=A.positive_int, help="agent steps (0.2 s) to run; default: until Ctrl-C or the source ends")
    p.add_argument("--seed", type=A.seed, default=0, help="sim source: seed")
    p.add_argument("--person-path", type=A.input_file, help="sim source: CSV of x,y waypoints for the person")
    p.add_argument("--log", type=A.output_file, help="write an MCAP log (ROS 2 schemas, opens in Foxglove)")
    p.add_argument("--record", type=A.output_file, help="write a rerun recording (.rrd)")
    p.add_argument("--spawn", action="store_true", help="open a live rerun viewer")
    p.add_argument("--transfer", action="store_true",
                   help="allow a policy file trained on another robot (zero-shot transfer; the shipped Jackal policies always may)")
    p.add_argument("--goal-deadband", type=A.nonnegative_float, default=None, metavar="M", help=GOAL_DEADBAND_HELP)
    p.add_argument("--no-mirror", action="store_true", help=NO_MIRROR_HELP)
    p.add_argument("--planner-budget-ms", type=A.nonnegative_float, default=2.0,
                   help="anytime SQP budget per planner call (default 2 ms, keeps pose-to-command latency p99 under 5 ms; 0: "
                        "fixed iteration counts as in simulation)")
    p.add_argument("--first-pose-timeout", type=A.nonnegative_float, default=10.0, metavar="S",
                   help="end with an error if no valid pose arrived within S seconds (default 10; 0: wait for ever)")
    p.add_argument("--json", type=A.output_file, help="write the run's summary here")
    p.add_argument("--dynamics", type=A.dynamics_spec, default=None,
                   help="simulated robot only (--source sim): nominal (default), hardware_like, or a JSON file")
    p.add_argument("--calibration", type=A.calibration_spec, default=None,
                   help="command calibration: none (default), online (the robot's gains estimated while driving) or lbgp sysid's JSON "
                        "for this robot (every command sent is scaled by it)")
    p.add_argument("--drive-model", type=A.drive_model_spec, default=None, help=DRIVE_MODEL_HELP)
    p.set_defaults(func=cmd_deploy)

    p = sub.add_parser("sysid", help="identify a robot's dynamics from a deploy log (or --excite: record one)")
    p.add_argument("log_file", nargs="?", type=A.input_file, help="an lbgp MCAP log (from lbgp deploy --log or --excite)")
    p.add_argument("--robot", default="turtlebot2", choices=["jackal", "turtlebot2"])
    p.add_argument("--out", type=A.output_file, help="write the fitted dynamics here (JSON, for --dynamics)")
    p.add_argument("--png", type=A.output_file, help="plot of measured vs simulated velocity")
    p.add_argument("--excite", action="store_true", help="drive a safe excitation sequence (steps, chirp; safety stops on) and log it")
    p.add_argument("--log", type=A.output_file, help="--excite: the MCAP log to write")
    p.add_argument("--source", default=None, help="--excite: pose source (default: the simulator, person standing 6 m away)")
    p.add_argument("--sink", default=None, help="--excite: command sink (default: the simulator's)")
    p.add_argument("--dynamics", type=A.dynamics_spec, default=None, help="--excite in simulation: the simulated robot's dynamics")
    p.add_argument("--seed", type=A.seed, default=0)
    p.set_defaults(func=cmd_sysid)

    p = sub.add_parser("replay", help="re-play an lbgp MCAP log: metrics and a rerun recording")
    p.add_argument("log", type=A.input_file, help="the .mcap file written by lbgp deploy --log")
    p.add_argument("--record", type=A.output_file, help="write a rerun recording (.rrd)")
    p.add_argument("--json", type=A.output_file, help="write the metrics here")
    p.set_defaults(func=cmd_replay)

    p = sub.add_parser("plot-curves", help="learning curves of runs (mean and a half-std or 95 %% CI band over seeds)")
    p.add_argument("run_dirs", nargs="+", type=A.existing_dir, help="run directories; runs with the same label are averaged")
    p.add_argument("--out", type=A.output_file, required=True, help="output image (.png)")
    p.add_argument("--labels", nargs="*", help="one label per run dir (default: method + curriculum from config)")
    p.add_argument("--x", default="env_steps", choices=["env_steps", "wall_time"], help="horizontal axis (default env_steps)")
    p.add_argument("--band", default="half_std", choices=["half_std", "ci95"],
                   help="shaded band: half a standard deviation (the paper's) or the 95 %% CI of the mean")
    p.set_defaults(func=cmd_plot_curves)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # a bad argument (one line already printed, 2) or --help (0)
        return exc.code if isinstance(exc.code, int) else 2
    try:
        return int(args.func(args) or 0)
    except (ValueError, OSError, ImportError) as exc:  # bad input found while working: one line, exit 2
        message = " ".join(str(exc).split()) or type(exc).__name__
        print(f"lbgp {args.command}: error: {message}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
