"""Benchmark scores: the one-to-one segment rule, the movement error rate, macro F1 and the confusion matrix.

The edit distance, macro F1 and confusion matrix come from rapidfuzz and scikit-learn; the hand-written functions
they replaced are kept here as references, and hypothesis checks the libraries give exactly their results."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.bench.metrics import (confusion_matrix, edit_distance, macro_f1, match_segments, movement_error_rate,
                                   segmentation_scores)
from tests.likeme.test_cli import likeme


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


def reference_edit_distance(a, b):
    """The hand-written Levenshtein distance that rapidfuzz replaced."""
    prev = np.arange(len(b) + 1)
    for i, x in enumerate(a, 1):
        cur = np.empty_like(prev)
        cur[0] = i
        for j, y in enumerate(b, 1):
            cur[j] = min(prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (x != y))
        prev = cur
    return int(prev[-1])


def reference_macro_f1(truth, predicted):
    """The hand-written macro F1 that scikit-learn's f1_score replaced."""
    scores = []
    for label in sorted(set(truth)):
        tp = sum(t == label and p == label for t, p in zip(truth, predicted))
        fp = sum(t != label and p == label for t, p in zip(truth, predicted))
        fn = sum(t == label and p != label for t, p in zip(truth, predicted))
        scores.append(2 * tp / (2 * tp + fp + fn) if tp else 0.0)
    return float(np.mean(scores)) if scores else 0.0


def reference_confusion(truth, predicted, labels):
    """The hand-written confusion matrix that scikit-learn's confusion_matrix replaced."""
    confusion = np.zeros((len(labels), len(labels)), dtype=int)
    for t, p in zip(truth, predicted):
        confusion[labels.index(t), labels.index(p)] += 1
    return confusion


labels = st.sampled_from(["jump", "wave", "reach", "sit", "unknown", "Jump", "jump ", "", "1"])
long_words = st.lists(labels, max_size=40)


@settings(max_examples=300, deadline=None)
@given(long_words, long_words)
def test_edit_distance_equals_the_hand_written_one(a, b):
    assert edit_distance(a, b) == reference_edit_distance(a, b)
    assert movement_error_rate(a, b) == reference_edit_distance(a, b) / max(len(b), 1)


@given(st.lists(st.one_of(st.integers(-3, 3), st.text(max_size=2), st.tuples(st.integers(0, 2))), max_size=12),
       st.lists(st.one_of(st.integers(-3, 3), st.text(max_size=2), st.tuples(st.integers(0, 2))), max_size=12))
def test_edit_distance_of_any_hashable_labels(a, b):
    assert edit_distance(a, b) == reference_edit_distance(a, b)


pairs = st.lists(st.tuples(labels, labels), max_size=60)


@settings(max_examples=300, deadline=None)  # the first call imports scikit-learn
@given(pairs)
def test_macro_f1_and_confusion_equal_the_hand_written_ones(items):
    truth, predicted = [t for t, _ in items], [p for _, p in items]
    assert macro_f1(truth, predicted) == reference_macro_f1(truth, predicted)  # bit for bit
    names = sorted(set(truth) | set(predicted))
    m = confusion_matrix(truth, predicted, names)
    assert m.dtype == int and m.tolist() == reference_confusion(truth, predicted, names).tolist()


def test_macro_f1_counts_true_labels_only():
    # "unknown" is only predicted: it costs "jump" a miss and has no F1 of its own
    assert macro_f1(["jump", "jump", "sit"], ["jump", "unknown", "sit"]) == (2 / 3 + 1.0) / 2
    assert macro_f1([], []) == 0.0
    assert confusion_matrix(["a", "b"], ["b", "b"], ["a", "b"]).tolist() == [[0, 1], [0, 1]]


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


def test_boundary_scores_count_true_boundaries_within_the_tolerance():
    truth = [(10, 30), (40, 60), (70, 90)]
    found = [(12, 30), (40, 52)]  # errors 2, 0 and 0, 8; the third movement is missed
    s = segmentation_scores(found, truth, tolerance=3)
    assert sorted(s["boundary_errors"]) == [0.0, 0.0, 2.0, 8.0]
    assert s["boundary_error"] == pytest.approx(2.5)
    assert s["within"] == pytest.approx(3 / 6)  # of the six true boundaries, three found within 3 frames
    assert segmentation_scores(found, truth, tolerance=8)["within"] == pytest.approx(4 / 6)
    assert segmentation_scores([], [])["within"] == 1.0


@given(st.lists(st.tuples(st.integers(0, 500), st.integers(1, 60)), max_size=6),
       st.lists(st.tuples(st.integers(0, 500), st.integers(1, 60)), max_size=6), st.floats(0, 100))
def test_boundary_share_is_a_share_that_grows_with_the_tolerance(a, b, tolerance):
    found, truth = [(s, s + n) for s, n in a], [(s, s + n) for s, n in b]
    low, high = (segmentation_scores(found, truth, tolerance=t)["within"] for t in (tolerance, tolerance + 10))
    assert 0.0 <= low <= high <= 1.0
    disjoint = [(100 * k + s % 40, 100 * k + s % 40 + n) for k, (s, n) in enumerate(b)]
    assert segmentation_scores(disjoint, disjoint)["within"] == 1.0
