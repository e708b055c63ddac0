"""``likeme bench latency``: the frame that closes each segment, and the benchmark end to end."""

from __future__ import annotations

import json

import pytest

from likeme.cli import main
from plugins.bench.data import make_data
from plugins.bench.latency import closing_frames
from toolkit import create_plugin_manager
from toolkit.observe import compose_observer
from toolkit.recordings.profile import load_profile
from toolkit.recordings.segments import read_segments


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    return make_data(create_plugin_manager(), tmp_path_factory.mktemp("latency"), streams=1, per_stream=3)


def test_each_segment_is_closed_after_its_last_frame_and_before_the_next_starts(data):
    profile = load_profile(data / "profile.toml")
    character = compose_observer(create_plugin_manager(), profile, data / "repertoire")
    stream = data / "streams" / "stream_1.bvh"
    closed = closing_frames(character, profile, profile.read(stream))
    truth = read_segments(stream.with_name("stream_1.segments.csv"))
    assert len(closed) >= len(truth) - 1  # the last may be closed by the end of the input
    for (start, end), frame in closed.items():
        assert end - 1 <= frame < end + profile.read(stream).fps  # decided within a second of its end


@pytest.mark.benchmark
def test_the_benchmark_feeds_a_stream_and_reports_median_and_p95(data, tmp_path, capsys):
    out = tmp_path / "latency.json"
    assert main(["bench", "latency", "--body", str(data / "profile.toml"), "--repertoire", str(data / "repertoire"),
                 "--streams", str(data / "streams"), "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "after the segmenter closed" in text and "p95 ms" in text
    report = json.loads(out.read_text())
    assert report["rows"][0]["segments"] >= 2
    assert all(x >= 0 for x in report["rows"][0]["after_decision_s"])
