"""Reading a BVH file a block of frames at a time gives what reading it whole gives: the same bits, the same errors."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import toolkit.bvh as bvh_module
from plugins.lib import root_frame
from tests.toolkit.test_bvh import SMALL, bvh_files
from tests.toolkit.test_profile import PROFILE, _max_parts, _write_max_clip
from toolkit import ConfigError
from toolkit.bvh import format_bvh, from_joint_positions, iter_bvh_blocks, open_bvh, parse_bvh, read_bvh
from toolkit.profile import load_profile


def _blocks(path, frames):
    blocks = list(iter_bvh_blocks(path, frames))
    assert all(len(b) == frames for b in blocks[:-1]) and (not blocks or 0 < len(blocks[-1]) <= frames)
    return blocks


def _error(call):
    try:
        call()
    except ConfigError as exc:
        return str(exc)
    return None


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(bvh_files(), st.integers(1, 7), st.sampled_from([3, 9, 17]), st.sampled_from([7, 64, 1 << 20]))
def test_blocks_of_a_generated_file_are_the_whole_file_bit_for_bit(tmp_path, monkeypatch, bvh, frames, precision,
                                                                    chunk):
    monkeypatch.setattr(bvh_module, "_CHUNK", chunk)  # small chunks: tokens and '\r\n' cut between chunks
    path = tmp_path / "g.bvh"
    path.write_text(format_bvh(bvh, precision=precision).replace("\n", "\r\n"), newline="")
    whole = read_bvh(path)
    blocks = _blocks(path, frames)
    assert np.concatenate(blocks).tobytes() == whole.values.tobytes()
    assert whole.values.tobytes() == parse_bvh(open(path, newline="").read(), str(path)).values.tobytes()


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.integers(1, 40), st.integers(2, 6), st.integers(1, 50), st.data())
def test_the_profile_stream_is_the_read_motion_sliced_bit_for_bit(tmp_path, max_character, frames_per_block, n_extra,
                                                                 n_frames, data):
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    parts = max_character.body.parts
    positions = np.cumsum(rng.normal(0, 2.0, (n_frames, len(parts), 3)), axis=0) + rng.normal(0, 50, (len(parts), 3))
    names = [f"J_{p}" for p in parts]
    root = max_character.body.root_index
    order = [root] + [i for i in range(len(parts)) if i != root]
    bvh = from_joint_positions([names[i] for i in order], [-1] + [0] * (len(order) - 1), positions[:, order],
                               data.draw(st.sampled_from([30.0, 120.0, 240.0])))
    path = tmp_path / "p.bvh"
    path.write_text(format_bvh(bvh, precision=data.draw(st.sampled_from([4, 9, 15]))))
    up = data.draw(st.sampled_from(["+y", "+z", "-x"]))
    profile_path = tmp_path / "p.toml"
    profile_path.write_text(PROFILE.format(units="cm", up=up, parts=_max_parts(max_character)))
    profile = load_profile(profile_path)
    motion = profile.read(path)
    with profile.stream(path, block=frames_per_block) as stream:
        assert stream.fps == motion.fps and stream.n_frames == motion.n_frames and stream.parts == list(motion.parts)
        got = list(stream)
    f = 0
    for pos, vis in got:
        assert pos.tobytes() == motion.positions[f : f + len(pos)].tobytes()
        assert vis.tobytes() == motion.visible[f : f + len(pos)].tobytes()
        f += len(pos)
    assert f == motion.n_frames


def _long_file(n_frames=6000):
    rng = np.random.default_rng(5)
    positions = np.cumsum(rng.normal(0, 1.0, (n_frames, 3, 3)), axis=0)
    return format_bvh(from_joint_positions(["a", "b", "c"], [-1, 0, 1], positions, 120.0), precision=7)


@pytest.mark.parametrize("bad, expected", [("x9", "expected a number"), ("nan", "expected a finite channel value"),
                                           ("1e999", "expected a finite channel value")])
def test_a_bad_value_in_frame_5000_is_reported_at_the_same_line_and_column_by_both_readers(tmp_path, bad, expected):
    lines = _long_file().split("\n")
    first = lines.index("Frame Time: 0.00833333333") + 1
    words = lines[first + 4999].split(" ")
    words[4] = bad
    lines[first + 4999] = " ".join(words)
    path = tmp_path / "bad.bvh"
    path.write_text("\n".join(lines))
    column = len(" ".join(words[:4])) + 2
    whole = _error(lambda: read_bvh(path))
    assert whole is not None and whole.startswith(f"{path}:{first + 5000}:{column}: found {bad!r}"), whole
    assert expected in whole
    for frames in (1, 7, 4096, 10000):
        assert _error(lambda: _blocks(path, frames)) == whole
    assert _error(lambda: parse_bvh(path.read_text(), str(path))) == whole
    assert _error(lambda: bvh_module._parse(path.read_text(), str(path), fast=False)) == whole


def test_the_blocks_before_a_bad_value_come_out_and_then_the_error(tmp_path):
    lines = _long_file().split("\n")
    first = lines.index("Frame Time: 0.00833333333") + 1
    lines[first + 4999] = "y " + " ".join(lines[first + 4999].split(" ")[1:])
    path = tmp_path / "bad.bvh"
    path.write_text("\n".join(lines))
    got = []
    with pytest.raises(ConfigError, match=f":{first + 5000}:1: found 'y'"):
        for block in iter_bvh_blocks(path, 1000):
            got.append(block)
    assert sum(len(b) for b in got) == 4000


@pytest.mark.parametrize("edit", [
    lambda t: t.replace("Frames: 2", "Frames: 3"),
    lambda t: t.replace("Frames: 2", "Frames: 1"),
    lambda t: t.replace("Frames: 2", "Frames: 0"),
    lambda t: t.replace("1 90 0 90 0 0  0 0 0  5 0 0 0 0 0", "1 90 0 90 0 0  0 0 0  5 0 0 0 0"),
    lambda t: t.replace("1 90 0 90", "1 90 0 9 9"),
    lambda t: t.replace("0 90 0 0", "0 x 0 0").replace("1 90 0 90", "1 90 0 nan"),
    lambda t: t.replace("0 90 0 0", "0 inf 0 0").replace("1 90 0 90", "1 90 0 x"),
    lambda t: t.replace("Frame Time: 0.0333333", "Frame Time: 0.0333333 5"),
    lambda t: t + "7\r\n",
    lambda t: t.rstrip("\r\n").rsplit("\r\n", 1)[0],
    lambda t: t.replace("\r\n", "\n").replace("0 90 0 0 0 0  0 0 0  5 0 0 0 0 0\n", ""),
])
def test_edited_files_give_the_same_error_streamed_in_any_block_size(tmp_path, edit):
    path = tmp_path / "bad.bvh"
    path.write_text(edit(SMALL), newline="")
    whole = _error(lambda: read_bvh(path))
    assert whole == _error(lambda: bvh_module._parse(edit(SMALL), str(path), fast=False))
    for frames in (1, 2, 3):
        assert _error(lambda: _blocks(path, frames)) == whole


def test_reading_keeps_numbers_as_arrays_memory_a_small_multiple_of_frames_x_channels(tmp_path):
    path = tmp_path / "long.bvh"
    path.write_text(_long_file(100000))
    tracemalloc.start()
    try:
        values = read_bvh(path).values
        _, whole_peak = tracemalloc.get_traced_memory()
        array = values.nbytes  # 100000 frames x 9 channels x 8 bytes = 7.2 MB (the text: 8.3 MB)
        del values
        tracemalloc.reset_peak()
        base, _ = tracemalloc.get_traced_memory()
        n = 0
        for block in iter_bvh_blocks(path, 256):
            n += len(block)
        _, stream_peak = tracemalloc.get_traced_memory()
        stream_peak -= base
    finally:
        tracemalloc.stop()
    assert n == 100000
    # the array, one chunk of text and one block's tokens (a tuple per value, as before, was 72 MB here)
    assert whole_peak < array + 8 * 2**20, whole_peak
    assert stream_peak < 8 * 2**20, stream_peak


def test_a_huge_frame_count_allocates_nothing(tmp_path):
    path = tmp_path / "huge.bvh"
    path.write_text(SMALL.replace("Frames: 2", "Frames: 1000000000000"), newline="")
    tracemalloc.start()
    try:
        with pytest.raises(ConfigError, match=r"huge.bvh:26:1: 2 frame lines after 'Frames: 1000000000000'"):
            read_bvh(path)
        with pytest.raises(ConfigError, match="expected 1000000000000 frame lines"):
            list(iter_bvh_blocks(path))
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 4 * 2**20


def test_the_header_is_known_before_any_frame_is_read(tmp_path):
    path = tmp_path / "s.bvh"
    path.write_text(SMALL, newline="")
    with open_bvh(path) as stream:
        assert stream.names == ["hips", "chest", "arm", "arm_end"] and stream.n_frames == 2
        assert stream.n_channels == 15 and stream.fps == pytest.approx(30.0, rel=1e-4)
        assert stream.header.n_frames == 0
        first = next(stream.blocks(1))
        assert first.tobytes() == read_bvh(path).values[:1].tobytes()


@pytest.mark.parametrize("budget", [1, 5, 1000])
def test_facing_medians_taken_a_few_windows_at_a_time_are_the_same_bits(monkeypatch, budget):
    rng = np.random.default_rng(budget)
    headings = rng.uniform(-np.pi, np.pi, 300)
    headings[rng.random(300) < 0.2] = np.nan
    whole = root_frame.smooth_heading(headings, 31)
    filt = root_frame.HeadingFilter(17)
    streamed = np.concatenate([filt.update_many(headings[:120]), filt.update_many(headings[120:])])
    monkeypatch.setattr(root_frame, "_WINDOW_BUDGET", budget)
    assert root_frame.smooth_heading(headings, 31).tobytes() == whole.tobytes()
    filt = root_frame.HeadingFilter(17)
    again = np.concatenate([filt.update_many(headings[:120]), filt.update_many(headings[120:])])
    assert again.tobytes() == streamed.tobytes()


def test_observe_streams_a_file_and_finds_what_watching_it_whole_finds(tmp_path, pm, max_character, monkeypatch):
    import contextlib
    import io
    import json

    from toolkit.cli import main
    from toolkit.observe import Observer, compose_observer

    monkeypatch.setenv("LIKEME_DISABLE_PLUGIN_AUTOLOAD", "1")
    root = tmp_path / "rep"
    for movement in ("jump", "wave"):
        (root / movement).mkdir(parents=True)
        _write_max_clip(max_character, root / movement / "max.bvh", movement)
    profile_path = tmp_path / "p.toml"
    profile_path.write_text(PROFILE.format(units="cm", up="+y", parts=_max_parts(max_character)))
    profile = load_profile(profile_path)
    jump, wave = profile.read(root / "jump" / "max.bvh"), profile.read(root / "wave" / "max.bvh")
    both = np.concatenate([jump.positions, wave.positions, jump.positions])
    parts = max_character.body.parts
    names = [f"J_{p}" for p in parts]
    r = max_character.body.root_index
    order = [r] + [i for i in range(len(parts)) if i != r]
    stream_path = tmp_path / "stream.bvh"
    stream_path.write_text(format_bvh(from_joint_positions([names[i] for i in order], [-1] + [0] * (len(order) - 1),
                                                           both[:, order] * 100, 30.0), precision=9))
    monkeypatch.setattr(bvh_module, "BLOCK", 7)  # many blocks
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["observe", "--body", str(profile_path), "--repertoire", str(root), str(stream_path),
                     "--json"]) == 0
    report = json.loads(out.getvalue())[0]
    character = compose_observer(pm, profile, root)
    found = Observer(character, profile.body, 30.0).watch(profile.read(stream_path))
    assert report["frames"] == len(both)
    assert [(s["start_frame"], s["end_frame"], s["movement"]) for s in report["segments"]] == \
        [(o.segment.start, o.segment.end, o.movement or "unknown") for o in found]
    assert report["segments"]
