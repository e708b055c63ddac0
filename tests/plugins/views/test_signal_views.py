"""Signal plots: what the views draw is what the segmenters and the matcher decided on, and it is in the pixels.

The three views (``hub-signal``, ``speed-profile``, ``prediction-error``) read signals the plugins record while a
character watches a demonstration; these tests check the recorded signals against the plugins' own decisions,
then check the pictures for the lines and shadings those decisions should produce.
"""

from __future__ import annotations

import numpy as np
import pytest

from plugins.views.demonstration import perform_sequence, watch
from plugins.lib.rendering import hex_to_rgb
from toolkit import Motion, create_plugin_manager, load_character
from toolkit.cli import main

imageio = pytest.importorskip("imageio.v2")

GAMES = ["left_front", "left_side", "left_side"]  # Kopp & Graeser 2006, §5: the three imitation games


@pytest.fixture
def pm():
    return create_plugin_manager(autoload=False)


def _image(path):
    return imageio.imread(path)[..., :3].astype(int)


def _near(image, colour, tol=40):
    return np.abs(image - np.array(hex_to_rgb(colour))).sum(axis=-1) < tol


def _runs(mask_1d):
    """Number of runs of True in a 1-D boolean array."""
    m = np.asarray(mask_1d, dtype=int)
    return int((np.diff(np.concatenate([[0], m])) == 1).sum())


# -- hub-signal ---------------------------------------------------------------------------------------------


def test_the_plotted_level_is_the_one_the_hub_threshold_segmenter_decides_on(pm):
    max_ = load_character("max", pm)
    demo = perform_sequence(max_, "morris", ["jump", "wave", "reach"], "movements", rest=0.8, noise=0.003, seed=2)
    observer, found = watch(max_, demo)
    seen = Motion(np.array(observer.poses), observer.fps, max_.body.parts, np.array(observer.visible))
    segmenter = max_.segmenter
    raw, filtered, level = segmenter.signal(seen)
    start, end = segmenter.thresholds
    assert end < start
    window = int(round(segmenter.params["floor"] * observer.fps))  # the floor: the running minimum of the last window
    floor = np.array([filtered[max(0, i - window + 1) : i + 1].min() for i in range(len(filtered))])
    assert np.allclose(level, filtered - floor) and np.all(level >= 0)
    assert [o.movement for o in found] == ["jump", "wave", "reach"]
    delay = segmenter._delay
    inside = np.zeros(len(level), dtype=bool)
    for o in found:  # every segment's level rose above the start threshold ...
        assert level[o.segment.start : o.segment.end + delay].max() > start
        inside[o.segment.start : o.segment.end + delay + 1] = True
    assert not np.any(level[~inside] > start)  # ... and it never did outside a segment
    # the batch segmentation of the same level agrees with the stream
    assert [(s.start, s.end) for s in segmenter.segment(seen)] == [(o.segment.start, o.segment.end) for o in found]


def test_hub_signal_view_shades_each_segment_and_draws_the_thresholds(tmp_path):
    out = tmp_path / "signal.png"
    status = main(["show", "max", "--view", "hub-signal", "--out", str(out), "--set", 'movements=["jump","wave","reach"]',
                   "--set", "width=900", "--set", "height=500"])
    assert status == 0
    image = _image(out)
    assert image.shape[:2] == (500, 900)
    shade = _near(image, "#d8d8d8", tol=12)
    assert _runs(shade.sum(axis=0) > 0.3 * image.shape[0]) == 3  # one grey band per segment found
    assert _near(image, "#e6194b", tol=120).sum() > 500  # the thresholds (thin antialiased lines: a loose match)
    assert _near(image, "#4363d8").sum() > 300  # the level compared


# -- speed-profile ------------------------------------------------------------------------------------------


def test_recorded_analyses_are_where_the_velocity_direction_segmenter_cut(pm):
    max_ = load_character("max_learner", pm, override={"segmenter": {"level": "stroke"}})
    demo = perform_sequence(max_, "moritz", ["left_side", "left_front"], "movements", rest=0.8)
    analysed = {}  # each movement the segmenter's working memory closed, read through inspect() as it closes

    def keep(_):
        signals = max_.segmenter.inspect()
        analysed.setdefault(signals["movement"], signals["analysis"])

    _, found = watch(max_, demo, each=keep)
    record = [(start, end, analysis) for (start, end), analysis in analysed.items()]
    assert len(record) == 4  # out and back, twice
    cuts = {o.segment.start for o in found} | {o.segment.end for o in found}
    expected = set()
    for start, end, analysis in record:
        expected |= {start, end} | {start + b for b in analysis.breaks}
        assert set(analysis.breaks) <= set(analysis.speed_breaks) | set(analysis.direction_breaks)
        assert len(analysis.speed) == len(analysis.clusters) == len(analysis.window) - 1
    assert cuts == expected
    # the side movement goes out by way of the front: its way out has a speed minimum the segmenter cuts at
    side_out = record[0][2]
    assert side_out.speed_breaks and side_out.breaks
    b = side_out.speed_breaks[0]
    assert side_out.speed[b - 1] < 0.5 * side_out.speed.max()


def test_speed_profile_view_draws_a_line_per_speed_break(tmp_path):
    out = tmp_path / "speed.png"
    status = main(["show", "max_learner", "--view", "speed-profile", "--out", str(out), "--set", "demonstrator=moritz",
                   "--set", 'movements=["left_side"]', "--set", "width=1000", "--set", "height=500"])
    assert status == 0
    image = _image(out)
    red = _near(image, "#e6194b")
    columns = red.sum(axis=0) > 0.3 * image.shape[0]
    assert _runs(columns) == 1  # the one speed break point of the side movement's way out
    assert _near(image, "#4363d8").sum() > 100  # points of direction cluster 0


# -- prediction-error ---------------------------------------------------------------------------------------


def test_the_trace_shows_facilitation_deviation_and_waiting_between_candidates(pm):
    max_ = load_character("max_learner", pm)
    demo = perform_sequence(max_, "moritz", GAMES, "movements", rest=0.8)
    matcher = max_.matcher
    segments = []
    def keep(o):
        signals = matcher.inspect()
        segments.append((o, list(signals["trace"]), signals["committed_at"], signals["deviated_at"],
                         signals["committed_path"]))

    watch(max_, demo, each=keep)
    assert len(segments) == 6  # each game: out and back
    threshold, deviation = matcher.params["threshold"], matcher.params["deviation"]
    # game 1: nothing to predict with (only the hub): no candidate, no commitment
    assert all(not errors for _, errors in segments[0][1]) and segments[0][2] is None
    # game 2, the way out: the known front command predicts it; Max commits early, then deviates
    o, trace, committed_at, deviated_at, path = segments[2]
    assert committed_at is not None and committed_at / o.segment.n_frames < 0.5
    assert deviated_at is not None and deviated_at > committed_at
    frame, errors = trace[-1]
    assert list(errors) == [path] and errors[path] > deviation  # the last comparison is the one that stopped him
    assert o.match.details["deviated"] and o.match.details["learned"]
    # game 3, the way out: two candidates until the front one fails, then Max commits at once
    o, trace, committed_at, deviated_at, path = segments[4]
    assert len(trace[0][1]) == 2
    commit_frame = next(i for i, (f, _) in enumerate(trace) if f == committed_at - 1)
    at_commit = trace[commit_frame][1]
    dropped = [p for p, e in at_commit.items() if e > threshold]
    assert dropped and all(p[0] != path[0] for p in dropped)
    assert all(len(errors) >= 2 for _, errors in trace[:commit_frame])  # he waited while both predicted well
    assert deviated_at is None and committed_at < o.segment.n_frames


def test_prediction_error_view_marks_each_commitment(tmp_path):
    out = tmp_path / "errors.png"
    status = main(["show", "max_learner", "--view", "prediction-error", "--out", str(out), "--set", "demonstrator=moritz",
                   "--set", f"movements={GAMES!r}".replace("'", '"'), "--set", "width=1200", "--set", "height=600"])
    assert status == 0
    image = _image(out)
    black = (image.sum(axis=-1) < 60)
    solid = black.sum(axis=0) > 0.45 * image.shape[0]
    # the two spines of the axes, and one solid line per commitment (games 2 and 3: three, see the trace test)
    assert _runs(solid) - 2 == 3
    assert _near(image, "#e6194b").sum() > 300  # thresholds
