"""Tracker output as it comes (issue 37): a CSV time column with dropped frames is placed on the frame grid, the
missing frames not visible; a CSV without a header is read with the joints named (a body profile's ``joints``).
Small made-up files, Kinect-like: 30 fps, times rounded to the millisecond."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from toolkit.errors import ConfigError
from toolkit.recordings import open_recording
from toolkit.recordings.csv_positions import frame_grid, has_header
from toolkit.recordings.positions import read_positions
from toolkit.recordings.profile import load_profile

JOINTS = ["SpineBase", "Head", "HipLeft", "HipRight", "ShoulderLeft"]
PROFILE = """[profile]
name = "kinect"
units = "metre"
up = "+y"
{joints}

[parts]
root = "SpineBase"
head = "Head"
left_hip = "HipLeft"
right_hip = "HipRight"

[facing]
left = "left_hip"
right = "right_hip"
"""


def write(path, text):
    path.write_text(text, encoding="utf-8", newline="")
    return path


def body(frames: int, seed: int = 0) -> np.ndarray:
    """A standing body's joints (frames, 5, 3) in metres, swaying a little: distinct values in every frame."""
    rng = np.random.default_rng(seed)
    rest = np.array([[0.0, 0.9, 0.0], [0.0, 1.6, 0.05], [0.1, 0.88, 0.0], [-0.1, 0.88, 0.0], [0.18, 1.4, 0.0]])
    return rest + rng.normal(0.0, 0.01, (frames, len(rest), 3))


def kinect_csv(positions, frames_kept, *, fps=30.0, header=True, time=True, jitter=None, t0=12.5):
    """The rows of the kept frames, each with its time (t0 + frame / fps, rounded to 1 ms, plus ``jitter``)."""
    lines = []
    if header:
        lines.append(",".join((["time"] if time else []) + [f"{j}_{a}" for j in JOINTS for a in "xyz"]))
    for i, f in enumerate(frames_kept):
        t = t0 + f / fps + (0.0 if jitter is None else jitter[i])
        cells = ([f"{t:.3f}"] if time else []) + [repr(float(v)) for v in positions[f].ravel()]
        lines.append(",".join(cells))
    return "\n".join(lines) + "\n"


# -- dropped frames ---------------------------------------------------------------------------------------------


def test_dropped_frames_are_placed_on_the_grid_and_not_seen(tmp_path):
    positions = body(12)
    kept = [0, 1, 2, 5, 6, 7, 8, 10, 11]  # frames 3, 4 and 9 dropped
    path = write(tmp_path / "kinect.csv", kinect_csv(positions, kept))
    read = read_positions(path)
    assert read.fps == pytest.approx(30.0, rel=1e-3)
    assert read.positions.shape == (12, 5, 3)
    np.testing.assert_array_equal(read.positions[kept], positions[kept])
    assert np.isnan(read.positions[[3, 4, 9]]).all()


def test_through_a_profile_the_dropped_frames_are_not_visible(tmp_path):
    positions = body(10)
    kept = [0, 1, 2, 3, 6, 7, 8, 9]
    path = write(tmp_path / "kinect.csv", kinect_csv(positions, kept))
    profile = load_profile(write(tmp_path / "kinect.toml", PROFILE.format(joints="")))
    motion = profile.read(path)
    assert motion.n_frames == 10
    assert motion.visible[kept].all() and not motion.visible[[4, 5]].any()
    np.testing.assert_allclose(motion.positions[kept, 1], positions[kept, 1])


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data(), frames=st.integers(3, 80), block=st.integers(1, 9), fps=st.sampled_from([15.0, 30.0, 60.0]))
def test_any_dropped_frames_and_block_size_give_the_grid(tmp_path_factory, data, frames, block, fps):
    """Rows kept at random (first and last kept, fewer than a third of the frames dropped, so that most steps are
    one frame), times rounded to 1 ms and jittered by up to 5% of a frame: each row at its frame, every other
    frame NaN, in blocks of any size."""
    dropped = data.draw(st.sets(st.integers(1, frames - 2), max_size=(frames - 2) // 3))
    kept = [f for f in range(frames) if f not in dropped]
    jitter = data.draw(st.lists(st.floats(-0.05 / fps, 0.05 / fps), min_size=len(kept), max_size=len(kept)))
    positions = body(frames, seed=frames)
    path = write(tmp_path_factory.mktemp("grid") / "t.csv", kinect_csv(positions, kept, fps=fps, jitter=jitter))
    with open_recording(path, frames=block) as recording:
        blocks = list(recording.blocks())
        assert recording.fps == pytest.approx(fps, rel=0.05)
        assert recording.n_frames in (None, frames)
    assert all(len(b) <= block for b in blocks)
    read = np.concatenate(blocks)
    assert read.shape == (frames, 5, 3)
    np.testing.assert_array_equal(read[kept], positions[kept])
    assert np.isnan(read[sorted(dropped)]).all()


def test_a_gap_of_many_frames_counts_them_all_with_rounded_times():
    """At 30 fps rounded to 1 ms the steps are 33 and 34 ms: a gap of 100 frames is 100 frames, not 101."""
    frames = np.r_[np.arange(50), np.arange(150, 200)]
    times = np.round(frames / 30.0, 3)
    grid, step = frame_grid(times)
    np.testing.assert_array_equal(grid, frames)
    assert 1 / step == pytest.approx(30.0, rel=1e-4)


def test_more_gaps_than_single_steps_take_the_shortest_step():
    """Frames 0, 2, 4, 5, 7: the median step is two frames, which the last single step is not; the shortest is one."""
    grid, step = frame_grid(np.array([0, 2, 4, 5, 7]) / 30.0)
    assert grid.tolist() == [0, 2, 4, 5, 7] and 1 / step == pytest.approx(30.0)


@pytest.mark.parametrize(("times", "message"), [
    ([0, 0.1, 0.2, 0.35, 0.45], r"t.csv:6:1: irregular timing: a step of 0.15 s from the row before is 1.5 frames; "
                                r"expected steps of whole frames of 0.1 s \(one, or more where frames were dropped\) "
                                r"within 25% of a frame"),
    ([0, 0.1, 0.2, 0.3, 0.22], r"t.csv:7:1: time 0.22 s does not increase from 0.3 s"),
    ([0, 0.1, 0.2, 100.0], r"t.csv:6:1: 997 frames missing between 4 rows \(the longest gap, 997 frames, before this "
                           r"row\); expected at least as many rows as frames missing"),
    ([0, 0.1, 0.2, 1e300], r"t.csv:6:1: 1e\+301 frames missing between 4 rows"),
])
def test_times_that_are_no_frame_grid_are_refused_at_their_row(tmp_path, times, message):
    text = "time,a_x,a_y,a_z\n\n" + "".join(f"{t},1,2,3\n" for t in times)
    with pytest.raises(ConfigError, match=message):
        read_positions(write(tmp_path / "t.csv", text))


# -- no header ----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("time", [False, True])
def test_a_headerless_csv_is_read_in_the_profiles_joints_order(tmp_path, time):
    positions = body(6)
    path = write(tmp_path / "raw.csv", kinect_csv(positions, range(6), header=False, time=time))
    assert not has_header(path)
    read = read_positions(path, names=JOINTS, fps=None if time else 30.0)
    assert read.names == tuple(JOINTS) and read.fps == pytest.approx(30.0, rel=1e-2)
    np.testing.assert_array_equal(read.positions, positions)
    joints = "joints = [" + ", ".join(f'"{j}"' for j in JOINTS) + "]\nfps = 30"
    profile = load_profile(write(tmp_path / "kinect.toml", PROFILE.format(joints=joints)))
    motion = profile.read(path)
    np.testing.assert_allclose(motion.positions[:, 1], positions[:, 1])  # the head, the file's second joint
    assert motion.visible.all()


def test_a_headerless_csv_with_dropped_frames_is_placed_on_the_grid(tmp_path):
    positions = body(8)
    kept = [0, 1, 2, 4, 5, 6, 7]
    path = write(tmp_path / "raw.csv", kinect_csv(positions, kept, header=False))
    read = read_positions(path, names=JOINTS)
    assert np.isnan(read.positions[3]).all()
    np.testing.assert_array_equal(read.positions[kept], positions[kept])


def test_without_joints_a_profile_reads_a_headerless_csv_in_its_parts_order(tmp_path):
    """No ``joints`` list: the mapped joints in the order of [parts], as for a .npy array."""
    positions = body(4)[:, :4]
    text = "".join(",".join(repr(float(v)) for v in row.ravel()) + "\n" for row in positions)
    path = write(tmp_path / "raw.csv", text)
    profile = load_profile(write(tmp_path / "kinect.toml", PROFILE.format(joints="fps = 30")))
    np.testing.assert_allclose(profile.read(path).positions, positions)


def test_a_header_is_not_mistaken_for_a_frame(tmp_path):
    assert has_header(write(tmp_path / "h.csv", "time,a_x,a_y,a_z\n0,1,2,3\n"))
    assert has_header(write(tmp_path / "n.csv", "1,2,a_z\n0,1,2\n"))  # one cell that is no number
    assert has_header(tmp_path / "absent.csv")  # reading it says what is wrong
    assert not has_header(write(tmp_path / "f.csv", "1,,nan\n"))
    assert not has_header(write(tmp_path / "q.csv", '"1.5";2;3\n'))


@pytest.mark.parametrize(("names", "text", "message"), [
    (None, "1,2,3\n", r"raw.csv:1: the file has no header \(its first line is numbers\); expected a header naming the "
                      r"columns JOINT_x, JOINT_y, JOINT_z, or the joints in column order"),
    (["a"], "1,2,3,4,5\n", r"raw.csv:1:1: 5 fields in a file without a header; expected x, y and z of each of the 1 "
                           r"joints named, in order \(3 fields\), or a time in seconds first \(4\); available: a"),
    (["a"], "1,2,3\n1,2\n", r"raw.csv:2:1: 2 fields; expected 3 fields separated by commas"),
    (["a"], "1,2,3\n1,x,3\n", r"raw.csv:2:3: found 'x' in column 'a_y'"),
    (["a"], "0,1,2,3\n0.1,1,2,3\nq,1,2,3\n", r"raw.csv:3:1: found 'q' in column 'time'; expected a time in seconds"),
])
def test_headerless_errors_name_the_line(tmp_path, names, text, message):
    with pytest.raises(ConfigError, match=message):
        read_positions(write(tmp_path / "raw.csv", text), names=names, fps=30)
