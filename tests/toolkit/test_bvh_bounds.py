"""What the BVH reader and the file checks refuse at once: every quantity that sizes memory or time is bounded."""

from __future__ import annotations

import os
import tracemalloc

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import toolkit.bvh as bvh_module

from tests.toolkit.test_bvh import SMALL
from toolkit import ConfigError
from toolkit.bvh import (MAX_DEPTH, MAX_FPS, MIN_FPS, BVH, BVHStream, Joint, format_bvh, iter_bvh_blocks, parse_bvh,
                         read_bvh, write_bvh)
from toolkit.files import check_regular_file, max_bytes
from toolkit.profile import load_profile


def _chain(depth: int, frames: int = 2) -> str:
    """A BVH whose joints are nested ``depth`` deep (a chain), three rotation channels each."""
    joints = [Joint(f"j{i}", i - 1, (0.0, 1.0, 0.0), ("Zrotation", "Xrotation", "Yrotation")) for i in range(depth)]
    values = np.zeros((frames, 3 * depth))
    return format_bvh(BVH(joints, 1 / 30, values))


def test_a_byte_order_mark_is_accepted(tmp_path):
    path = tmp_path / "bom.bvh"
    path.write_bytes(b"\xef\xbb\xbf" + SMALL.encode())
    whole = read_bvh(path)
    assert whole.names == ["hips", "chest", "arm", "arm_end"]
    assert whole.values.tobytes() == parse_bvh(SMALL).values.tobytes() == parse_bvh("\ufeff" + SMALL).values.tobytes()
    assert np.concatenate(list(iter_bvh_blocks(path, 1))).tobytes() == whole.values.tobytes()


def test_a_byte_order_mark_elsewhere_is_not_a_token():
    with pytest.raises(ConfigError, match=r"bad.bvh:2:1: found '\\ufeffROOT'; expected 'ROOT'"):
        parse_bvh(SMALL.replace("ROOT", "\ufeffROOT"), "bad.bvh")


@pytest.mark.parametrize("frame_time, ok", [("1e-7", False), ("0.00009", False), ("0.0001", True), ("0.00833333", True),
                                            ("60", True), ("61", False), ("1e300", False), ("-0.1", False)])
def test_frame_rates_from_one_a_minute_to_10_khz_are_read(frame_time, ok):
    text = SMALL.replace("Frame Time: 0.0333333", f"Frame Time: {frame_time}")
    if ok:
        assert MIN_FPS * 0.999 < parse_bvh(text).fps < MAX_FPS * 1.001
        return
    with pytest.raises(ConfigError) as info:
        parse_bvh(text, "ft.bvh")
    assert str(info.value).startswith("ft.bvh:23:13: frame time ")


def test_hierarchies_up_to_the_depth_bound_read_and_deeper_ones_are_refused_without_recursion():
    deep = parse_bvh(_chain(MAX_DEPTH))
    assert len(deep.joints) == MAX_DEPTH and deep.joints[-1].parent == MAX_DEPTH - 2
    assert deep.positions()[0, -1, 1] == pytest.approx(MAX_DEPTH)  # every OFFSET, the root's too, is 1 up
    with pytest.raises(ConfigError, match=f"joints nested deeper than {MAX_DEPTH}; expected at most {MAX_DEPTH}"):
        parse_bvh(_chain(MAX_DEPTH + 1))
    with pytest.raises(ConfigError, match="joints nested deeper"):
        parse_bvh(_chain(5000, frames=1))  # no RecursionError, reading or writing


@pytest.mark.parametrize("count", ["²", "٣", "３", "+3", "7", "99999999999999999999999"])
def test_a_channel_count_is_ascii_digits_from_0_to_6(count):
    with pytest.raises(ConfigError, match=r"bad.bvh:9:12: found .*; expected the number of channels \(ASCII digits, "
                                          r"at most 6\)"):
        parse_bvh(SMALL.replace("CHANNELS 3", f"CHANNELS {count}"), "bad.bvh")


def test_a_joint_may_have_no_channels_but_the_file_must_have_some():
    some = SMALL.replace("CHANNELS 3 Xrotation Yrotation Zrotation", "CHANNELS 0").replace("0 0 0  5", "5")
    assert parse_bvh(some).n_channels == 12
    none = "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 0\n}\nMOTION\nFrames: 2\nFrame Time: 0.1\n\n\n"
    with pytest.raises(ConfigError, match="none.bvh:7:1: no channels in the hierarchy"):
        parse_bvh(none, "none.bvh")


def test_a_frame_count_of_twenty_digits_is_refused_and_a_huge_one_allocates_nothing():
    with pytest.raises(ConfigError, match=r"bad.bvh:22:9: found '9{20}'; expected the number of frames"):
        parse_bvh(SMALL.replace("Frames: 2", "Frames: " + "9" * 20), "bad.bvh")
    with pytest.raises(ConfigError, match=r"found '9{40}'\.\.\.;"):  # a long token is cut in the message
        parse_bvh(SMALL.replace("Frames: 2", "Frames: " + "9" * 5000), "bad.bvh")
    tracemalloc.start()
    try:
        with pytest.raises(ConfigError, match=r"bad.bvh:26:1: 2 frame lines after 'Frames: 999999999999999'"):
            parse_bvh(SMALL.replace("Frames: 2", "Frames: 999999999999999"), "bad.bvh")
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 2**20


def test_writing_a_deep_hierarchy_does_not_recurse(tmp_path):
    text = _chain(3000, frames=1)
    assert text.count("JOINT") == 2999 and text.count("}") == 3000


@pytest.mark.parametrize("reader", ["bvh", "profile", "validate"])
def test_a_fifo_a_device_or_a_directory_fails_at_once(tmp_path, reader):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    folder = tmp_path / "folder.bvh"
    folder.mkdir()
    for path, kind in ((fifo, "a FIFO"), ("/dev/zero", "a character device"), (folder, "a directory")):
        with pytest.raises(ConfigError) as info:
            if reader == "bvh":
                read_bvh(path)
            elif reader == "profile":
                load_profile(path)
            else:
                check_regular_file(path, "TOML file")
        assert f"{path}: is {kind}" in str(info.value) and "expected a regular file" in str(info.value)


def test_the_size_cap_has_a_default_and_an_environment_variable(tmp_path, monkeypatch):
    path = write_bvh(parse_bvh(SMALL), tmp_path / "s.bvh")
    monkeypatch.delenv("LIKEME_MAX_MOTION_MB", raising=False)
    monkeypatch.delenv("LIKEME_MAX_CONFIG_MB", raising=False)
    assert max_bytes("motion") == 4096 * 2**20 and max_bytes("config") == 16 * 2**20
    monkeypatch.setenv("LIKEME_MAX_MOTION_MB", "0.0001")  # 104 bytes
    with pytest.raises(ConfigError, match="s.bvh: BVH file of [0-9,]+ bytes is larger than the cap of 104 bytes; "
                                          "expected a smaller file, or a higher cap in megabytes in the environment "
                                          "variable LIKEME_MAX_MOTION_MB"):
        read_bvh(path)
    monkeypatch.setenv("LIKEME_MAX_MOTION_MB", "nan")
    with pytest.raises(ConfigError, match="key LIKEME_MAX_MOTION_MB: invalid size cap 'nan'"):
        read_bvh(path)
    monkeypatch.setenv("LIKEME_MAX_MOTION_MB", "1")
    assert read_bvh(path).n_frames == 2
    monkeypatch.setenv("LIKEME_MAX_CONFIG_MB", "0.00001")
    profile = tmp_path / "p.toml"
    profile.write_text('[parts]\nroot = "hips"\n' + "# padding\n" * 10)
    with pytest.raises(ConfigError, match="p.toml: body profile of .* is larger than the cap"):
        load_profile(profile)


_WORDS = ["HIERARCHY", "ROOT", "JOINT", "End", "Site", "{", "}", "OFFSET", "CHANNELS", "MOTION", "Frames:", "Frame",
          "Time:", "Xrotation", "Yposition", "0", "1", "6", "7", "²", "-1", "1e-7", "1e999", "nan", "x",
          "1000000000000", "\ufeff", "\r\n", "\n", "\r", "\t", " ", "\v", "\u2028", "\x00"]


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 10**6), st.integers(0, 3), st.sampled_from(_WORDS)), min_size=1, max_size=4),
       st.integers(1, 3), st.sampled_from([5, 64, 1 << 18]))
def test_mutated_files_read_or_fail_with_a_config_error_the_same_whole_and_streamed(edits, frames, chunk):
    text = SMALL
    for at, how, word in edits:  # insert, replace a token, delete a token, or cut the file
        i = at % (len(text) + 1)
        if how == 0:
            text = text[:i] + word + text[i:]
        elif how in (1, 2):
            j = i + len(text[i:].split(maxsplit=1)[0]) if text[i:].strip() else i
            text = text[:i] + (word if how == 1 else "") + text[j:]
        else:
            text = text[:i]
    results = []
    for read in (lambda: parse_bvh(text, "m.bvh").values,
                 lambda: bvh_module._parse(text, "m.bvh", fast=False).values,
                 lambda: _stream_text(text, frames, chunk)):
        try:
            results.append(read().tobytes())
        except ConfigError as exc:
            results.append(str(exc))
    assert results[0] == results[1] == results[2]


def _stream_text(text: str, frames: int, chunk: int) -> np.ndarray:
    """The values of ``text`` streamed in blocks of ``frames`` frames from chunks of ``chunk`` characters."""
    saved, bvh_module._CHUNK = bvh_module._CHUNK, chunk
    try:
        stream = BVHStream(lambda: bvh_module._text_chunks(text), "m.bvh", len(text))
        return np.concatenate([np.empty((0, stream.n_channels)), *stream.blocks(frames)])
    finally:
        bvh_module._CHUNK = saved
