"""A stream's true segments, ``NAME.segments.csv`` (toolkit/recordings/segments.py): written and read back."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from toolkit.errors import ConfigError
from toolkit.recordings import is_recording
from toolkit.recordings.segments import read_segments, segments_of, write_segments

NAMES = st.text(st.characters(codec="utf-8", exclude_characters=",\"\r\n\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029"),
                min_size=1, max_size=12).map(str.strip).filter(bool)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 10**6), st.integers(1, 10**4), NAMES), max_size=20))
def test_what_is_written_is_read_back(rows):
    rows = [(start, start + length, name) for start, length, name in rows]
    with tempfile.TemporaryDirectory() as folder:
        path = write_segments(Path(folder, "s.segments.csv"), rows)
        assert read_segments(path) == rows


def test_a_recordings_segments_sit_beside_it_and_are_not_a_recording():
    for name in ("stream_1.bvh", "stream_1.csv", "stream_1.npy", "stream_1.c3d"):
        assert segments_of(Path("streams") / name) == Path("streams") / "stream_1.segments.csv"
    assert is_recording("stream_1.csv") and not is_recording("stream_1.segments.csv")
    assert not is_recording("STREAM.SEGMENTS.CSV") and is_recording("take.BVH") and not is_recording("notes.txt")


@pytest.mark.parametrize("text, message", [
    ("", r"s.segments.csv:1: found header ''"),
    ("start,end\n", r"s.segments.csv:1: found header 'start,end'; expected the header start_frame,end_frame,movement"),
    ("start_frame,end_frame,movement\n3,3,bow\n", r"s.segments.csv:2: segment 3..3; expected 0 <= start_frame < end_frame"),
    ("start_frame,end_frame,movement\n\n1,x,bow\n", r"s.segments.csv:3: found '1,x,bow'; expected two frame numbers"),
])
def test_a_bad_row_is_named_by_its_line(tmp_path, text, message):
    path = tmp_path / "s.segments.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ConfigError, match=message):
        read_segments(path)
