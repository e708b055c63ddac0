"""The MOTION block read as one array gives what reading it token by token gives: the same values, the same errors."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import BANDAI
from tests.toolkit.test_bvh import SMALL, bvh_files
from toolkit import ConfigError
from toolkit.bvh import BVH, _parse, format_bvh, from_joint_positions, open_bvh, read_bvh, write_bvh


def _both(text: str, source: str = "x.bvh"):
    """(fast result or error text, token-by-token result or error text); the file streamed in blocks of 1 and 2
    frames is checked against the fast result on the way."""
    out = []
    for fast in (True, False):
        try:
            out.append(_parse(text, source, fast=fast))
        except ConfigError as exc:
            out.append(str(exc))
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder, source)
        with open(path, "w", encoding="utf-8", newline="") as f:
            f.write(text)
        for frames in (1, 2):
            try:
                with open_bvh(path) as stream:
                    streamed = BVH(stream.joints, stream.header.frame_time,
                                   np.concatenate([np.empty((0, stream.n_channels)), *stream.blocks(frames)]), source)
            except ConfigError as exc:
                streamed = str(exc).replace(folder + "/", "")
            _same(out[0], streamed)
    return out


def _same(a, b) -> None:
    if isinstance(a, str) or isinstance(b, str):
        assert a == b
        return
    assert a.names == b.names and a.joints == b.joints and a.frame_time == b.frame_time
    assert a.values.shape == b.values.shape
    assert a.values.tobytes() == b.values.tobytes()  # bit for bit


@settings(max_examples=60, deadline=None)
@given(bvh_files(), st.sampled_from([3, 6, 12, 17]))
def test_generated_files_read_bit_for_bit_the_same_both_ways(bvh, precision):
    _same(*_both(format_bvh(bvh, precision=precision)))


def test_a_written_file_reads_the_same_both_ways(tmp_path):
    rng = np.random.default_rng(1)
    positions = np.cumsum(rng.normal(0, 3, (200, 5, 3)), axis=0)
    bvh = from_joint_positions(["a", "b", "c", "d", "e"], [-1, 0, 1, 1, 0], positions, 30.0)
    text = write_bvh(bvh, tmp_path / "w.bvh").read_text()
    fast, slow = _both(text)
    _same(fast, slow)
    np.testing.assert_allclose(fast.positions(), positions, atol=1e-3)


MALFORMED = [
    lambda t: t.replace("Frames: 2", "Frames: 3"),
    lambda t: t.replace("Frames: 2", "Frames: 1"),
    lambda t: t.replace("1 90 0 90 0 0  0 0 0  5 0 0 0 0 0", "1 90 0 90 0 0  0 0 0  5 0 0 0 0"),
    lambda t: t.replace("1 90 0 90", "1 90 0 nan"),
    lambda t: t.replace("1 90 0 90", "1 90 0 -inf"),
    lambda t: t.replace("1 90 0 90", "1 90 0 1e999"),
    lambda t: t.replace("1 90 0 90", "1 90 0 x9"),
    lambda t: t.replace("1 90 0 90", "1 90 0 0x10"),
    lambda t: t.replace("1 90 0 90", "1 90 0 9 9"),
    lambda t: t + "7\r\n",
    lambda t: t.rstrip(),
    lambda t: t.replace("\r\n", "\n"),
    lambda t: t.replace("\r\n", "\r"),
    lambda t: t.replace("Frame Time: 0.0333333", "Frame Time: 0.0333333 5"),
    lambda t: t.replace("Frame Time: 0.0333333", "Frame Time: 1e-7"),
    lambda t: t.replace("Frames: 2", "Frames: 1000000000000"),
    lambda t: t.replace("Frames: 2", "Frames: 0"),
    lambda t: t.replace("CHANNELS 3", "CHANNELS \u00b2"),
    lambda t: "\ufeff" + t,
    lambda t: t.replace("1 90 0 90 0 0  0 0 0  5 0 0 0 0 0\r\n", "1 90 0 90 0 0  0 0 0\r\n5 0 0 0 0 0\r\n"),
    lambda t: t.replace("0 90 0 0", "0 x 0 0").replace("Frames: 2", "Frames: 3"),
]


@pytest.mark.parametrize("edit", MALFORMED)
def test_edited_and_malformed_files_give_the_same_value_or_the_same_error_both_ways(edit):
    _same(*_both(edit(SMALL), "bad.bvh"))


def test_a_bad_token_is_still_named_by_line_and_column():
    fast, slow = _both(SMALL.replace("1 90 0 90", "1 90 0 x9"), "bad.bvh")
    assert fast == slow and fast.startswith("bad.bvh:25:") and "found 'x9'" in fast


@pytest.mark.skipif(not BANDAI.exists(), reason="the Bandai-Namco clips are not here")
def test_real_clips_read_bit_for_bit_the_same_both_ways():
    for path in sorted(BANDAI.glob("*.bvh"))[:6]:
        text = path.read_text(encoding="utf-8", errors="replace")
        fast = read_bvh(path)
        _same(fast, _parse(text, str(path), fast=False))
        for frames in (1, 50):
            with open_bvh(path) as stream:
                _same(fast, BVH(stream.joints, stream.header.frame_time, np.concatenate(list(stream.blocks(frames))),
                                str(path)))
