"""Person paths: CSV input, the shipped library and the unseen evaluation paths."""

import numpy as np
import pytest

from lbgp.sim import paths


def test_csv_round_trip(tmp_path):
    pts = np.array([[0.0, 0.0], [1.0, 0.5], [2.0, 0.25]])
    f = tmp_path / "p.csv"
    paths.save_path_csv(f, pts)
    assert f.read_text().splitlines()[0] == "x,y"
    np.testing.assert_allclose(paths.load_path_csv(f), pts, atol=1e-4)


@pytest.mark.parametrize(
    "text, message",
    [
        ("a,b\n0,0\n1,1\n", "header 'x,y'"),
        ("x,y\n0,0\nnan,1\n", "waypoint 1 is not a finite number"),
        ("x,y\n0,0\n", "at least two points"),
        ("x,y\n0,0\n1,one\n", "not a number"),
        ("x,y\n0,0\n1,1,1\n", "expected 2 columns"),
        ("", "header 'x,y'"),
        ("x,y\n1,1\n1,1\n", "same point"),
    ],
)
def test_malformed_csv_gives_clear_error(tmp_path, text, message):
    f = tmp_path / "bad.csv"
    f.write_text(text)
    with pytest.raises(paths.PathError, match=message):
        paths.load_path_csv(f)


def test_missing_file(tmp_path):
    with pytest.raises(paths.PathError, match="no such path file"):
        paths.load_path_csv(tmp_path / "nope.csv")


def test_shipped_library_is_what_the_generator_draws():
    for i, seed in enumerate(paths.TRAIN_SEEDS):
        shipped = paths.load_path_csv(paths.DATA_DIR / f"train_{i:02d}.csv")
        np.testing.assert_allclose(shipped, paths.draw_path(seed, paths.TRAIN_LENGTH), atol=1e-4)
    for name, seed in paths.EVAL_PATHS.items():
        np.testing.assert_allclose(paths.evaluation_path(name), paths.draw_path(seed, paths.EVAL_LENGTH), atol=1e-4)


def test_library_size_and_reverses():
    library = paths.training_library()
    assert len(library) == 20  # 10 layouts and their reverses
    forward = library[:10]
    assert 45.0 < sum(paths.path_length(p) for p in forward) < 55.0
    for p, r in zip(forward, library[10:]):
        np.testing.assert_allclose(p[::-1], r)


def test_evaluation_paths_are_unseen():
    library = paths.training_library()
    for name in paths.EVAL_PATHS:
        e = paths.evaluation_path(name)
        for p in library:
            n = min(len(p), len(e))
            assert not np.allclose(p[:n] - p[0], e[:n] - e[0], atol=0.05)


def test_paths_are_smooth_and_evenly_sampled():
    for p in paths.training_library():
        seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
        assert seg.max() < 0.08 and seg.min() > 0.0
