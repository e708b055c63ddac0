"""Live input placed on the frame grid (dropped frames not visible), read as it arrives, and a block at a time."""

from __future__ import annotations

import io
import json
import os
import threading

import numpy as np
import pytest

from plugins.bench.data import write_positions
from toolkit.errors import ConfigError
from toolkit.recordings.live import MAX_GAP, LiveInput
from toolkit.recordings.profile import load_profile

PROFILE = '[profile]\nname = "three"\n[parts]\nroot = "b"\nhead = "a"\nnose = "c"\n[facing]\nleft = "head"\n' \
    'right = "nose"\n'


@pytest.fixture
def profile(tmp_path):
    (tmp_path / "p.toml").write_text(PROFILE)
    return load_profile(tmp_path / "p.toml")


def _csv(times, positions) -> str:
    head = "time," + ",".join(f"{j}_{a}" for j in "abc" for a in "xyz")
    return head + "\n" + "".join(f"{t!r}," + ",".join(repr(float(v)) for v in p.ravel()) + "\n"
                                 for t, p in zip(times, positions))


def test_dropped_frames_are_placed_on_the_grid_not_visible_as_a_file_reads_them(profile, tmp_path):
    rng = np.random.default_rng(1)
    kept = [0, 1, 2, 3, 6, 7, 9, 10, 11]  # frames 4, 5 and 8 dropped; times rounded to the millisecond
    times = [round(k / 30, 3) for k in kept]
    positions = rng.normal(size=(len(kept), 3, 3))
    text = _csv(times, positions)
    live = np.array(list(LiveInput(io.BytesIO(text.encode()), profile)))
    assert len(live) == 12
    seen = np.isfinite(live).all(axis=(1, 2))
    np.testing.assert_array_equal(np.flatnonzero(~seen), [4, 5, 8])
    (tmp_path / "m.csv").write_text(text)
    from_file = profile.read(tmp_path / "m.csv")
    np.testing.assert_array_equal(live, from_file.positions)


def test_dropped_frames_are_placed_with_a_rate_given_too(profile):
    kept = [0, 1, 2, 4, 5, 8]
    text = _csv([k / 30 for k in kept], np.ones((6, 3, 3)))
    live = LiveInput(io.BytesIO(text.encode()), profile, 30.0)
    frames = list(live)
    assert live.fps == 30.0 and len(frames) == 9
    assert [bool(np.isfinite(f).all()) for f in frames] == [k in kept for k in range(9)]


def test_a_frame_dropped_among_the_first_gives_the_right_rate(profile):
    kept = [0, 2, 3, 4]
    text = _csv([k / 25 for k in kept], np.zeros((4, 3, 3)))
    live = LiveInput(io.BytesIO(text.encode()), profile)
    assert live.fps == pytest.approx(25.0)
    assert len(list(live)) == 5


def test_json_lines_with_dropped_frames(profile):
    lines = [json.dumps({"time": k / 30, "a": [0, 1, 0], "b": [0, 0, 0], "c": [1, 0, 0]}) for k in (0, 1, 2, 5)]
    frames = list(LiveInput(io.BytesIO(("\n".join(lines) + "\n").encode()), profile, 30.0))
    assert len(frames) == 6 and [bool(np.isfinite(f).all()) for f in frames] == [True] * 3 + [False] * 2 + [True]


@pytest.mark.parametrize("times, fragment", [
    ([0, 1 / 30, 2 / 30, 3.5 / 30], "-:5: irregular timing: a step of"),
    ([0, 1 / 30, 2 / 30, 1 / 30], "-:5: time 0.0333333333 s does not increase"),
    ([0, 1 / 30, 2 / 30, MAX_GAP + 1.0], "-:5: a gap of"),
])
def test_times_off_the_grid_are_an_error_naming_the_line(profile, times, fragment):
    with pytest.raises(ConfigError) as info:
        list(LiveInput(io.BytesIO(_csv(times, np.zeros((4, 3, 3))).encode()), profile))
    assert fragment in str(info.value)


def test_a_pipe_is_read_as_it_arrives_and_in_blocks_of_what_has_arrived(profile, tmp_path):
    rng = np.random.default_rng(2)
    positions = rng.normal(size=(40, 3, 3))
    write_positions(tmp_path / "m.csv", list("abc"), positions)
    lines = (tmp_path / "m.csv").read_bytes().splitlines(keepends=True)
    read, write = os.pipe()
    with os.fdopen(read, "rb", buffering=0) as source, os.fdopen(write, "wb", buffering=0) as sink:
        sink.write(b"".join(lines[:2]))  # the header and one frame: the input is made before the rest is written
        live = LiveInput(source, profile, 30.0)
        blocks = live.blocks()
        first = next(blocks)
        assert len(first) == 1  # given out without waiting for more
        arrived = threading.Event()

        def later() -> None:
            sink.write(b"".join(lines[2:]))
            sink.close()
            arrived.set()

        thread = threading.Thread(target=later)
        thread.start()
        arrived.wait(60)
        rest = list(blocks)
        thread.join()
    assert sum(len(b) for b in rest) == 39 and len(rest) < 39  # what had arrived, a block at a time
    np.testing.assert_array_equal(np.concatenate([first, *rest]), profile.read(tmp_path / "m.csv", 30.0).positions)


def test_a_long_line_from_a_pipe_is_an_error(profile):
    read, write = os.pipe()
    sink = os.fdopen(write, "wb", buffering=0)

    def produce() -> None:
        try:
            sink.write(b"a_x," * 400_000)
        except BrokenPipeError:  # the reader gave up on the line, as it should
            pass
        finally:
            sink.close()

    thread = threading.Thread(target=produce)
    thread.start()
    with os.fdopen(read, "rb", buffering=0) as source:
        with pytest.raises(ConfigError, match="line longer than"):
            LiveInput(source, profile, 30.0)
    thread.join(60)
    assert not thread.is_alive()
