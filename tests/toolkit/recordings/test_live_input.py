"""``likeme observe -``: frames piped in on standard input, as CSV lines or JSON lines, each observation printed as
its segment closes (run as a subprocess with a pipe)."""

from __future__ import annotations

import io
import json
import selectors
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from plugins.bench.data import make_data, write_positions
from toolkit import ConfigError
from toolkit.recordings.bvh import read_bvh
from toolkit.recordings.live import LiveInput
from toolkit.recordings.profile import load_profile

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    """A benchmark folder (BVH) and its first stream as a CSV without a time column, with one, and as JSON lines."""
    from toolkit.manager import create_plugin_manager

    root = make_data(create_plugin_manager(), tmp_path_factory.mktemp("live") / "d", streams=1, per_stream=3)
    bvh = read_bvh(root / "streams" / "stream_1.bvh")
    write_positions(root / "plain.csv", bvh.names, bvh.positions())
    write_positions(root / "timed.csv", bvh.names, bvh.positions(), bvh.fps)
    frames = [{"time": k / bvh.fps, **{n: p.tolist() for n, p in zip(bvh.names, pose)}}
              for k, pose in enumerate(bvh.positions())]
    (root / "frames.jsonl").write_text("".join(json.dumps(f) + "\n" for f in frames))
    return root


def _command(data: Path, *extra: str) -> list[str]:
    return [sys.executable, "-m", "likeme", "observe", "--body", str(data / "profile.toml"), "--repertoire",
            str(data / "repertoire"), *extra]


def _run(data: Path, text: str, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run(_command(data, *extra, "-"), input=text, capture_output=True, text=True, cwd=ROOT,
                          timeout=600)


def _file_segments(data: Path) -> list[dict]:
    done = subprocess.run(_command(data, "--json", str(data / "streams" / "stream_1.bvh")), capture_output=True,
                          text=True, cwd=ROOT, timeout=600)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)[0]["segments"]


@pytest.mark.parametrize("source, extra", [("plain.csv", ("--fps", "30")), ("timed.csv", ()), ("frames.jsonl", ())])
def test_piped_frames_give_the_files_observations_one_json_line_each(data, source, extra):
    expected = _file_segments(data)
    done = _run(data, (data / source).read_text(), "--json", *extra)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert [json.loads(line) for line in lines] == [{"file": "-", **seg} for seg in expected]
    assert len(expected) >= 2


def test_text_output_prints_each_segment_and_a_closing_line(data):
    done = _run(data, (data / "plain.csv").read_text(), "--fps", "30")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    n = read_bvh(data / "streams" / "stream_1.bvh").n_frames
    segments = _file_segments(data)
    assert lines[0] == "-: standard input at 30 fps"
    assert lines[-1] == f"-: {n} frames at 30 fps, {len(segments)} segments"
    assert [line.split()[1] for line in lines[1:-1] if line.startswith("  frames")] == \
        [f"{s['start_frame']}-{s['end_frame']}" for s in segments]


def test_an_observation_is_printed_before_the_input_ends(data):
    """The first segment's line arrives while the pipe is still open: observe does not wait for the end."""
    segments = _file_segments(data)
    lines = (data / "plain.csv").read_text().splitlines(keepends=True)
    cut = segments[1]["start_frame"] + 1  # well after the first segment closed; the header is line 0
    proc = subprocess.Popen(_command(data, "--json", "--fps", "30", "-"), stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    try:
        proc.stdin.write("".join(lines[: cut + 1]))
        proc.stdin.flush()
        selector = selectors.DefaultSelector()
        selector.register(proc.stdout, selectors.EVENT_READ)
        assert selector.select(timeout=300), "no observation while the input is open"  # a guard, not a timing test
        assert proc.poll() is None  # still reading
        first = json.loads(proc.stdout.readline())
        assert first == {"file": "-", **segments[0]}
        proc.stdin.write("".join(lines[cut + 1:]))
        proc.stdin.close()
        rest = [json.loads(line) for line in proc.stdout.read().splitlines()]
        assert proc.wait(timeout=300) == 0, proc.stderr.read()
        assert [first, *rest] == [{"file": "-", **seg} for seg in segments]
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.stdout.close()
        proc.stderr.close()


def test_a_frame_with_missing_values_is_not_visible_and_the_stream_goes_on(data):
    lines = (data / "plain.csv").read_text().splitlines(keepends=True)
    cells = lines[5].rstrip("\n").split(",")
    lines[5] = ",".join(["nan"] * 3 + [""] * 3 + cells[6:]) + "\n"  # root and head not seen in one frame
    done = _run(data, "".join(lines), "--fps", "30")
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1].startswith(f"-: {len(lines) - 1} frames at 30 fps")


@pytest.mark.parametrize("edit, fragments", [
    (lambda lines: lines[:7] + ["1,2\n"] + lines[8:], ["-:8:1: 2 fields", "expected 33 fields"]),
    (lambda lines: lines[:4] + ["x" + lines[4]] + lines[5:], ["-:5:1: found 'x", "in column 'root_x'"]),
])
def test_a_malformed_csv_line_is_an_error_naming_the_line(data, edit, fragments):
    lines = (data / "plain.csv").read_text().splitlines(keepends=True)
    done = _run(data, "".join(edit(lines)), "--fps", "30")
    assert done.returncode == 1
    err = done.stderr.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("likeme: error: "), done.stderr
    assert "Traceback" not in done.stderr
    for fragment in fragments:
        assert fragment in err[0]


def _live(data: Path, text: str, fps: float | None = None) -> list[np.ndarray]:
    return list(LiveInput(io.BytesIO(text.encode()), load_profile(data / "profile.toml"), fps))


def test_json_lines_shape_missing_values_and_errors(data):
    first = json.loads((data / "frames.jsonl").read_text().splitlines()[0])
    second = {**first, "time": first["time"] + 0.1, "head": None, "nose": [1.0, None, 2.0], "extra": "ignored"}
    del second["left_knee"]
    frames = _live(data, json.dumps(first) + "\n\n" + json.dumps(second) + "\n")
    assert len(frames) == 2 and frames[0].shape == (11, 3) and np.isfinite(frames[0]).all()
    parts = list(load_profile(data / "profile.toml").body.parts)
    hidden = [parts[k] for k in np.flatnonzero(~np.isfinite(frames[1]).all(axis=-1))]
    assert hidden == ["head", "nose", "left_knee"]
    for text, fragment in [
        (json.dumps(first) + "\n[1, 2, 3]\n", "-:2: a JSON list, not an object"),
        ("[1, 2, 3]\n", "-:1: no joint columns in the header"),  # not an object: read as a CSV header
        (json.dumps(first) + "\n{oops\n", "-:2:2: not JSON"),
        (json.dumps({**first, "head": [1, 2]}) + "\n", "-:1: key head: joint 'head' is [1, 2]"),
        (json.dumps({k: v for k, v in first.items() if k != "nose"}) + "\n", "joint 'nose' of part 'nose' is not in "
                                                                             "standard input"),
        (json.dumps(first) + "\n" + json.dumps({**first, "time": 0.0}) + "\n", "-:2: time 0 s does not increase"),
        (json.dumps({k: v for k, v in first.items() if k != "time"}) + "\n", "-: no frame rate: no time on the frames"),
        ("", "-: no input"),
    ]:
        with pytest.raises(ConfigError) as info:
            _live(data, text)
        assert fragment in str(info.value), (fragment, str(info.value))


def test_the_rate_comes_from_the_fps_given_else_the_first_step(data):
    text = (data / "frames.jsonl").read_text()
    profile = load_profile(data / "profile.toml")
    assert LiveInput(io.BytesIO(text.encode()), profile).fps == pytest.approx(30.0, rel=1e-6)
    assert LiveInput(io.BytesIO(text.encode()), profile, 50.0).fps == 50.0


def test_docs_pipe_example_is_the_command_the_tests_run():
    text = (ROOT / "docs" / "formats.md").read_text()
    assert "cat rec.csv | likeme observe --body profile.toml --repertoire repertoire --fps 30 -" in text


PROFILE_3 = '[profile]\nname = "three"\nfps = 25\n[parts]\nroot = "b"\nhead = "a"\nnose = "c"\n' \
    '[facing]\nleft = "head"\nright = "nose"\n'


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(frames=st.integers(1, 12), joints=st.permutations(["a", "b", "c", "d"]),
       values=st.lists(st.one_of(st.floats(-1e6, 1e6, allow_nan=False), st.just(float("nan"))), min_size=144,
                       max_size=144))
def test_csv_npy_and_piped_lines_give_the_same_motion(tmp_path, frames, joints, values):
    """Random positions with missing values, written as CSV, .npy, CSV lines and JSON lines: the same parts' positions
    through a profile, NaN (not visible) where a value is missing."""
    positions = np.array(values[: frames * 12]).reshape(frames, 4, 3)
    profile_path = tmp_path / "p.toml"
    profile_path.write_text(PROFILE_3.replace("fps = 25", f"fps = 25\njoints = {json.dumps(list(joints))}"))
    profile = load_profile(profile_path)
    write_positions(tmp_path / "m.csv", list(joints), positions)
    write_positions(tmp_path / "m.npy", list(joints), positions)
    expected = positions[:, [joints.index(j) for j in ("b", "a", "c")]]
    expected[~np.isfinite(expected).all(axis=-1)] = np.nan  # a part with a missing coordinate is not visible at all
    for name in ("m.csv", "m.npy"):
        motion = profile.read(tmp_path / name)
        np.testing.assert_array_equal(motion.positions, expected)
        np.testing.assert_array_equal(motion.visible, np.isfinite(expected).all(axis=-1))
    piped = np.array(list(LiveInput(io.BytesIO((tmp_path / "m.csv").read_bytes()), profile, 25.0)))
    np.testing.assert_array_equal(piped, expected)
    lines = "".join(json.dumps({j: [None if np.isnan(v) else v for v in p.tolist()] for j, p in zip(joints, pose)})
                    + "\n" for pose in positions)
    np.testing.assert_array_equal(np.array(list(LiveInput(io.BytesIO(lines.encode()), profile, 25.0))), expected)


def test_huge_numbers_in_json_lines_are_not_seen_or_a_time_error_never_a_traceback(data):
    """A coordinate of 400 or 5,000 digits is read as a number too large to be finite: that joint is not seen on
    that frame, and the stream goes on; such a time is an error naming the line. JSON nested 100,000 deep too."""
    lines = (data / "frames.jsonl").read_text().splitlines()
    first, second = json.loads(lines[0]), json.loads(lines[1])
    for digits in (400, 5000):
        huge = "9" * digits
        text = lines[0] + "\n" + json.dumps(second).replace(json.dumps(second["head"]), f"[{huge}, 0, 0]", 1) + "\n"
        frames = _live(data, text)
        assert len(frames) == 2 and np.isfinite(frames[0]).all()
        parts = list(load_profile(data / "profile.toml").body.parts)
        assert [parts[k] for k in np.flatnonzero(~np.isfinite(frames[1]).all(axis=-1))] == ["head"]
        with pytest.raises(ConfigError, match="-:2: time inf; expected a finite time in seconds"):
            _live(data, lines[0] + "\n" + json.dumps({**first, "time": "@"}).replace('"@"', huge) + "\n")
    with pytest.raises(ConfigError, match="-:1: JSON nested too deeply"):
        _live(data, '{"time": ' + "[" * 100_000 + "]" * 100_000 + "}\n")
