"""Benchmark scores: the one-to-one segment rule and the movement error rate."""

from __future__ import annotations

import json

from hypothesis import given
from hypothesis import strategies as st

from plugins.bench.metrics import edit_distance, match_segments, movement_error_rate, segmentation_scores
from tests.test_cli import likeme


def test_segment_counts_when_midpoint_inside_and_half_overlap():
    truth = [(10, 30), (40, 60)]
    assert match_segments([(12, 28)], truth) == [(0, 0)]
    assert match_segments([(25, 45)], truth) == []  # midpoint 35 lies in no movement
    assert match_segments([(0, 24)], truth) == [(0, 0)]  # midpoint 12 inside, overlap 14 >= 12
    assert match_segments([(0, 21)], [(10, 12)]) == []  # midpoint 10.5 inside a short movement, overlap 2 < 10.5


def test_one_to_one():
    truth = [(10, 30)]
    found = [(10, 20), (20, 30)]
    pairs = match_segments(found, truth)
    assert len(pairs) == 1
    s = segmentation_scores(found, truth)
    assert s["precision"] == 0.5 and s["recall"] == 1.0 and abs(s["f1"] - 2 / 3) < 1e-12


def test_scores_of_perfect_and_empty():
    truth = [(0, 10), (20, 30)]
    assert segmentation_scores(truth, truth)["f1"] == 1.0
    assert segmentation_scores(truth, truth)["boundary_error"] == 0.0
    assert segmentation_scores([], truth)["f1"] == 0.0
    assert segmentation_scores([], [])["f1"] == 1.0


words = st.lists(st.sampled_from(["jump", "wave", "reach", "sit"]), max_size=8)


@given(words, words)
def test_edit_distance_is_a_metric(a, b):
    d = edit_distance(a, b)
    assert d == edit_distance(b, a)
    assert (d == 0) == (a == b)
    assert abs(len(a) - len(b)) <= d <= max(len(a), len(b))


def test_movement_error_rate():
    assert movement_error_rate(["jump", "cover_face"], ["jump", "cover_face"]) == 0.0
    assert movement_error_rate(["jump", "unknown", "wave"], ["jump", "cover_face"]) == 1.0


def test_bench_watch_runs_and_writes_json(tmp_path):
    out = tmp_path / "watch.json"
    result = likeme("bench", "watch", "--movements", "12", "--quiet", "--json", out)
    assert result.returncode == 0, result.stderr
    assert "segmentation F1" in result.stdout
    data = json.loads(out.read_text())
    assert data["movements"] == 12
    assert data["segmentation"]["f1"] >= 0.8 and data["recognition_accuracy"] >= 0.8
    assert data["frames_per_second"] > 0


def test_bench_facilitation_runs(tmp_path):
    out = tmp_path / "f.json"
    result = likeme("bench", "facilitation", "--demonstrations", "12", "--repertoire", "3", "--quiet", "--json", out)
    assert result.returncode == 0, result.stderr
    data = json.loads(out.read_text())
    hand = data["hand"]
    assert data["known"] + data["novel"] + hand["known"] + hand["novel"] == 12 and hand["known"] + hand["novel"] > 0
    assert data["recognition_accuracy"] >= 0.5 and data["imitation_error_mean"] < 0.05
    assert hand["recognition_accuracy"] >= 0.5 and hand["imitation_error_mean"] < 0.1  # radians
    assert "hands" in result.stdout  # the table has a column for them
