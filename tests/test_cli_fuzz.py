"""Every bad input to the ``lbgp`` command line ends with one line on stderr that names the
problem, exit code 2, no traceback, and nothing written.

``BAD_CASES`` enumerates 333 (subcommand, option, invalid value) cases over every option of every
subcommand that takes a value: counts (negative, zero, NaN, huge, empty, not a number, fractional), rates and
durations (negative, NaN, infinite, empty, not a number), fractions in [0, 1) (negative, 1, above 1, NaN, infinite, empty, not a number), config settings
(malformed, unknown or unsettable field, wrong type, out of range), seeds (negative, too large, not an
integer), input files (missing, a directory, empty name), output files (a directory, under a
regular file, empty name), output folders (a regular file, under a regular file) and run folders
(missing, a file). ``test_every_bad_option_value_is_refused`` runs all of them (a test
introspects the parser, so that a new option without cases is noticed), and
``test_random_junk_in_numeric_options_is_refused`` adds hypothesis-generated strings.
The second group are bad *files* whose problem shows only when read (corrupt or malformed policy
files, a truncated log, a 10,000 km person path, an unknown protocol path).
"""

from __future__ import annotations

import contextlib
import io
import os

import numpy as np
import pytest
import torch
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lbgp.cli import main

COUNT = ["-5", "0", "nan", "1e400", "", "abc", "3.5", "99999999999"]
SEED = ["-1", "4294967296", "x", "1.5", ""]
POSITIVE = ["-1", "0", "nan", "inf", "", "x"]
NONNEGATIVE = ["-1", "nan", "inf", "-inf", "", "x"]
DISTANCE = ["0", "-1", "nan", "100", "x"]
FRACTION = ["-0.1", "1", "1.5", "nan", "inf", "", "x"]  # a rate in [0, 1)
SETTING = ["sigma", "=0.3", "sigma=", "nofield=1", "seed=3", "sigma=x", "sigma=nan", "sigma=-1", "batch_size=1.5",
           "normalize_obs=maybe", "spawn_front_share=2", "n_step=0", ""]  # NAME=VALUE of a settable config field

# (subcommand words, option, kind); option None: a positional argument
OPTIONS = [
    (["demo"], "--seed", "seed"), (["demo"], "--out", "outdir"), (["demo"], "--policy", "infile"),
    (["evaluate"], "--episodes", "count"), (["evaluate"], "--seed", "seed"), (["evaluate"], "--policy", "infile"),
    (["evaluate"], "--hc-distance", "distance"), (["evaluate"], "--hc-horizon", "nonneg"),
    (["evaluate"], "--person-path", "infile"), (["evaluate"], "--json", "outfile"), (["evaluate"], "--record", "outfile"),
    (["train"], "--steps", "count"), (["train"], "--minutes", "positive"), (["train"], "--seed", "seed"),
    (["train"], "--actors", "count"), (["train"], "--prior-weight", "nonneg"), (["train"], "--out", "outdir"),
    (["train"], "--resume", "rundir"),
    (["experiment", "sim"], "--episodes", "count"), (["experiment", "sim"], "--horizon", "count"),
    (["experiment", "sim"], "--seed", "seed"), (["experiment", "sim"], "--out", "outdir"),
    (["experiment", "sim"], "--lbgp-policy", "infile"), (["experiment", "sim"], "--e2e-policy", "infile"),
    (["experiment", "real-protocol"], "--steps", "count"), (["experiment", "real-protocol"], "--repeats", "count"),
    (["experiment", "real-protocol"], "--seed", "seed"), (["experiment", "real-protocol"], "--out", "outdir"),
    (["experiment", "real-protocol"], "--jobs", "count"),
    (["experiment", "ablation"], "--minutes", "positive"), (["experiment", "ablation"], "--max-steps", "count"),
    (["experiment", "ablation"], "--seeds", "seed"), (["experiment", "ablation"], "--runs-dir", "outdir"),
    (["experiment", "ablation"], "--max-new-runs", "count"),
    (["experiment", "ablation"], "--seed", "seed"), (["experiment", "ablation"], "--out", "outdir"),
    (["experiment", "ablation"], "--lbgp-policy", "infile"), (["experiment", "ablation"], "--e2e-policy", "infile"),
    (["experiment", "real-protocol"], "--lbgp-policy", "infile"), (["experiment", "real-protocol"], "--e2e-policy", "infile"),
    (["deploy"], "--steps", "count"), (["deploy"], "--seed", "seed"), (["deploy"], "--policy", "infile"),
    (["deploy"], "--person-path", "infile"), (["deploy"], "--log", "outfile"), (["deploy"], "--record", "outfile"),
    (["deploy"], "--planner-budget-ms", "nonneg"), (["deploy"], "--first-pose-timeout", "nonneg"),
    (["deploy"], "--json", "outfile"),
    (["replay"], None, "infile"), (["replay", "LOG"], "--record", "outfile"), (["replay", "LOG"], "--json", "outfile"),
    (["plot-curves", "RUN"], "--out", "outfile"), (["plot-curves"], None, "rundir"),
    (["evaluate"], "--dynamics", "infile"), (["deploy"], "--dynamics", "infile"), (["sysid", "--excite"], "--dynamics", "infile"),
    (["train"], "--randomize", "infile"), (["train"], "--updates-per-step", "positive"),
    (["evaluate"], "--calibration", "infile"), (["deploy"], "--calibration", "infile"),
    (["evaluate"], "--drive-model", "infile"), (["deploy"], "--drive-model", "infile"),
    (["sysid"], None, "infile"), (["sysid", "--excite"], "--log", "outfile"), (["sysid", "LOG"], "--out", "outfile"),
    (["sysid", "LOG"], "--png", "outfile"), (["sysid", "--excite"], "--seed", "seed"),
    (["evaluate"], "--goal-deadband", "nonneg"), (["deploy"], "--goal-deadband", "nonneg"),
    (["train"], "--turn-lead", "nonneg"), (["train"], "--policy-average", "fraction"),
    (["train"], "--set", "setting"), (["train"], "--init-policy", "infile"),
]
VALUES = {"count": COUNT, "seed": SEED, "positive": POSITIVE, "nonneg": NONNEGATIVE, "distance": DISTANCE, "fraction": FRACTION, "setting": SETTING,
          "infile": ["MISSING", "DIR", ""], "outfile": ["DIR", "UNDER_FILE", ""], "outdir": ["FILE", "UNDER_FILE_DIR"],
          "rundir": ["MISSING", "FILE"]}
BAD_CASES = [(words, option, value) for words, option, kind in OPTIONS for value in VALUES[kind]]


@pytest.fixture()
def sandbox(tmp_path, monkeypatch):
    """A working folder with one regular file, one folder and a minimal MCAP placeholder."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "file.txt").write_text("a regular file\n")
    (tmp_path / "folder").mkdir()
    (tmp_path / "run").mkdir()
    (tmp_path / "log.mcap").write_bytes(b"\x89MCAP0\r\n")
    return tmp_path


def concrete(value: str, tmp) -> str:
    return {"MISSING": str(tmp / "missing.file"), "DIR": str(tmp / "folder"), "UNDER_FILE": str(tmp / "file.txt" / "out.json"),
            "FILE": str(tmp / "file.txt"), "UNDER_FILE_DIR": str(tmp / "file.txt" / "sub")}.get(value, value)


def run_cli(argv) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main(argv)
        except SystemExit as exc:
            code = exc.code
    return code, err.getvalue()


def argv_for(words, option, value, tmp) -> list[str]:
    words = [str(tmp / "log.mcap") if w == "LOG" else str(tmp / "run") if w == "RUN" else w for w in words]
    if option is None:
        return words + [concrete(value, tmp)] + (["--out", str(tmp / "c.png")] if words[0] == "plot-curves" else [])
    extra = ["--out", str(tmp / "newrun")] if words == ["train"] and option not in ("--out", "--resume") else []
    return words + extra + [f"{option}={concrete(value, tmp)}"]


def snapshot(tmp):
    return sorted(str(p.relative_to(tmp)) for p in tmp.rglob("*"))


def test_the_case_list_covers_every_option_that_takes_a_value():
    """Introspects the parser: a new option without bad cases here fails this test."""
    import argparse

    from lbgp.cli import build_parser

    # options whose values are free text checked elsewhere (names, URLs) or closed choices
    free = {"--scenario", "--source", "--sink", "--scenarios", "--paths", "--dynamics", "--labels", "--method", "--robot", "--backend"}

    def walk(parser, words):
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    yield from walk(sub, words + [name])
            elif action.nargs != 0 and not isinstance(action, argparse._HelpAction):
                option = action.option_strings[-1] if action.option_strings else None
                if option not in free and not action.choices:
                    yield (words[0] if words[0] != "experiment" else " ".join(words[:2]), option)

    covered = {(w[0] if w[0] != "experiment" else " ".join(w[:2]), o) for w, o, _ in OPTIONS}
    missing = set(walk(build_parser(), [])) - covered
    assert not missing, f"options without bad cases: {sorted(missing, key=str)}"
    assert len(BAD_CASES) == 333  # the count quoted in the module docstring


@pytest.mark.parametrize("words,option,value", BAD_CASES, ids=[f"{' '.join(w)} {o} {v!r}" for w, o, v in BAD_CASES])
def test_every_bad_option_value_is_refused(sandbox, words, option, value):
    before = snapshot(sandbox)
    code, err = run_cli(argv_for(words, option, value, sandbox))
    assert code == 2, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert option is None or option in err or "argument" in err
    assert snapshot(sandbox) == before  # nothing written


def _not_a_number(text: str) -> bool:
    try:
        float(text)
    except (ValueError, OverflowError):
        return True
    return False


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(case=st.sampled_from([(w, o) for w, o, k in OPTIONS if k in ("count", "positive", "seed", "nonneg")]),
       junk=st.one_of(st.text(max_size=12).filter(_not_a_number),
                      st.sampled_from(["nan", "-nan", "inf", "-inf", "1e999", "-1e999"]),
                      st.integers(max_value=-1).map(str), st.floats(max_value=-1e-9).map(repr)))
def test_random_junk_in_numeric_options_is_refused(sandbox, case, junk):
    """Strings that are not numbers, non-finite numbers and negative numbers, in every numeric option."""
    words, option = case
    before = snapshot(sandbox)
    code, err = run_cli(argv_for(words, option, junk, sandbox))
    assert code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1, (junk, err)
    assert snapshot(sandbox) == before


# ---------------------------------------------------------------- bad files, found when read
def test_corrupt_and_malformed_policy_files_give_one_line_naming_the_file(sandbox):
    from lbgp.agent.networks import Actor
    from lbgp.agent.policy import save_policy

    corrupt = sandbox / "corrupt.pt"
    corrupt.write_bytes(b"PK\x03\x04 not really a zip")
    good = sandbox / "good.pt"
    save_policy(good, Actor(57, 2, (32, 32)), "lbgp", "jackal", (32, 32))
    data = torch.load(good, weights_only=True)
    malformed = sandbox / "malformed.pt"
    torch.save({**data, "hidden": "wide"}, malformed)
    wrong_method = sandbox / "e2e.pt"
    save_policy(wrong_method, Actor(57, 2, (32, 32)), "e2e", "jackal", (32, 32))
    for path, needle in ((corrupt, "not a readable lbgp-policy file"), (malformed, "malformed policy file"),
                         (wrong_method, "holds a e2e policy, not lbgp")):
        code, err = run_cli(["evaluate", "--method", "lbgp", "--policy", str(path), "--episodes", "1", "--scenario", "straight_ahead"])
        assert code == 2 and needle in err and str(path) in err, err
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err and "weights_only" not in err


def test_bad_files_found_when_read_are_one_line_errors(sandbox):
    huge = sandbox / "huge.csv"
    huge.write_text("x,y\n0,0\n10000000,0\n")  # 10,000 km
    cut = sandbox / "cut.mcap"
    cut.write_bytes(b"\x89MCAP0\r\n\x01\x02\x03")
    wild = sandbox / "wild_calibration.json"
    wild.write_text('{"fit": {"gain_v": 1.0, "gain_w": 0.01}, "robot": "jackal"}')  # would turn 86 times harder
    cases = [
        (["evaluate", "--method", "hc", "--episodes", "1", "--scenario", "straight_ahead", "--person-path", str(huge)], "km long"),
        (["replay", str(cut)], "cut.mcap"),
        (["experiment", "real-protocol", "--paths", "zigzag", "--out", str(sandbox / "o")], "unknown protocol path 'zigzag'"),
        (["experiment", "real-protocol", "--dynamics", "moon", "--out", str(sandbox / "o")], "unknown dynamics set"),
        (["evaluate", "--scenario", "stairs", "--episodes", "1"], "unknown scenario"),
        (["evaluate", "--method", "hc", "--episodes", "1", "--scenario", "straight_ahead", "--calibration", str(wild)],
         "calibration scale_w must be within"),
        (["deploy", "--source", "udp://203.0.113.7:47000", "--steps", "1"], "cannot listen on 203.0.113.7"),
    ]
    for argv, needle in cases:
        before = snapshot(sandbox)
        code, err = run_cli(argv)
        assert code == 2 and needle in err, (argv, err)
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
        assert snapshot(sandbox) == before
    assert not os.path.exists(sandbox / "o")
    np.testing.assert_equal(code, 2)


def test_a_policy_for_another_robot_is_refused_unless_transfer_is_asked_for(sandbox):
    from lbgp.agent.networks import Actor
    from lbgp.agent.policy import save_policy

    turtle = sandbox / "lbgp_turtlebot2.pt"
    save_policy(turtle, Actor(57, 2, (32, 32)), "lbgp", "turtlebot2", (32, 32))
    base = ["evaluate", "--method", "lbgp", "--policy", str(turtle), "--robot", "jackal", "--episodes", "1",
            "--scenario", "straight_ahead"]
    code, err = run_cli(base)
    assert code == 2 and "trained on the turtlebot2, not the jackal" in err and "--transfer" in err
    code, err = run_cli(base + ["--transfer"])
    assert code == 0, err
