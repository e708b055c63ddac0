"""The velocity/direction segmenter (Kopp & Graeser 2006, §4.1, §4.3)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.fixtures.motions import with_visibility
from plugins.lib.guiding_stroke import SHAPES, GuidingStroke
from plugins.bench.metrics import segmentation_scores
from plugins.lib.strokes import direction_breaks, direction_clusters, speed_breaks
from plugins.segmenters.velocity_direction import VelocityDirection
from tests.conftest import CHARACTERS
from toolkit import ConfigError, Motion, create_plugin_manager, load_character

FPS = 30.0


def stroke_sequence(rng, n_strokes, noise=0.001, end_gain=0.0):
    p = np.array([0.0, 1.0, 0.3])
    chunks, truth, t = [np.repeat([p], 12, 0)], [], 12
    for _ in range(n_strokes):
        target = p + rng.uniform(-0.3, 0.3, 3)
        while np.linalg.norm(target - p) < 0.15:
            target = p + rng.uniform(-0.3, 0.3, 3)
        shape = SHAPES[rng.integers(0, 5)]
        stroke = GuidingStroke(p, target, rng.uniform(0.4, 0.9), rng.uniform(0.35, 0.65), end_gain, shape, rng.normal(size=3),
                               0.0 if shape == "linear" else rng.uniform(0.2, 0.7), rng.uniform(0.2, 0.8), rng.uniform(-0.4, 0.4))
        path = stroke.trajectory(FPS)[:-1]
        chunks.append(path)
        truth.append((t, t + len(path)))
        t += len(path)
        p = target
    chunks.append(np.repeat([p], 12, 0))
    path = np.concatenate(chunks) + rng.normal(0, noise, (t + 12, 3))
    return Motion(np.stack([np.zeros_like(path), path], 1), FPS, ("root", "wrist")), truth


def test_random_stroke_sequences_are_cut_at_the_strokes():
    rng = np.random.default_rng(7)
    scores = []
    for _ in range(40):
        motion, truth = stroke_sequence(rng, int(rng.integers(1, 5)))
        found = [(s.start, s.end) for s in VelocityDirection(parts=["wrist"]).segment(motion)]
        scores.append(segmentation_scores(found, truth)["f1"])
    assert np.mean(scores) >= 0.97


def test_streaming_equals_batch_and_movement_level():
    rng = np.random.default_rng(3)
    motion, truth = stroke_sequence(rng, 3)
    seg = VelocityDirection(parts=["wrist"])
    batch = seg.segment(motion)
    seg.reset(motion.parts, motion.fps)
    streamed = [s for f in range(motion.n_frames) for s in seg.push(motion.positions[f], motion.visible[f])] + seg.flush()
    assert streamed == batch
    flowing, truth = stroke_sequence(rng, 3, end_gain=0.3)  # strokes that flow into each other: one movement
    whole = VelocityDirection(parts=["wrist"], level="movement").segment(flowing)
    assert len(whole) == 1 and abs(whole[0].start - truth[0][0]) <= 3 and abs(whole[0].end - truth[-1][1]) <= 4


def test_onset_is_known_while_the_movement_goes_on():
    rng = np.random.default_rng(4)
    motion, truth = stroke_sequence(rng, 2)
    seg = VelocityDirection(parts=["wrist"])
    seg.reset(motion.parts, motion.fps)
    onset = None
    for f in range(motion.n_frames):
        seg.push(motion.positions[f], motion.visible[f])
        if seg.active_since is not None and onset is None:
            onset = (f, seg.active_since)
    detected_at, start = onset
    assert abs(start - truth[0][0]) <= 3 and detected_at - truth[0][0] <= 0.2 * FPS  # within the sensory memory


def test_it_reads_any_body_and_pairs_with_the_mouse():
    pm = create_plugin_manager(autoload=False)
    morris = load_character(CHARACTERS / "morris.toml", pm)
    rest = morris.motor.rest_pose()
    pos = np.concatenate([np.repeat(rest[None], 15, 0), morris.motor.perform("wave", fps=FPS).positions, np.repeat(rest[None], 15, 0)])
    motion = Motion(pos - pos[:, :1], FPS, morris.body.parts)
    whole = VelocityDirection(level="movement").segment(motion)
    assert len(whole) == 1
    strokes = VelocityDirection(parts=["right_hand"]).segment(motion)
    assert len(strokes) >= 4  # raising the arm, the waves, lowering it


def test_hidden_parts_do_not_move_and_unknown_parts_are_refused():
    rng = np.random.default_rng(5)
    motion, truth = stroke_sequence(rng, 1)
    visible = np.ones(motion.visible.shape, bool)
    visible[:, 1] = False
    assert VelocityDirection(parts=["wrist"]).segment(with_visibility(motion, visible)) == []
    with pytest.raises(ConfigError, match=r"key parts: parts \['left_wrist'\] are not in the observed body.*available: root, wrist"):
        VelocityDirection(parts=["left_wrist"]).reset(motion.parts, FPS)


def test_building_blocks():
    speed = np.array([0, 1, 2, 3, 2, 0.5, 2, 3, 2, 1, 0.0])
    assert speed_breaks(speed, 0.5) == [5]
    assert speed_breaks(np.array([0, 1, 2, 3, 2.5, 2.4, 2.6, 3, 1, 0.0]), 0.5) == []  # a shallow dip: one curved stroke
    right, up = np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    labels = direction_clusters(np.array([right] * 5 + [up] * 5), 45)
    assert direction_breaks(labels) == [5]
    assert len(set(direction_clusters(np.array([right] * 10), 45))) == 1


@settings(max_examples=80, deadline=None)
@given(out=st.integers(5, 40), hold=st.integers(1, 20), back=st.integers(5, 40), top=st.floats(0.2, 3.0),
       start=st.floats(0.0, 1.0), end=st.floats(0.0, 1.0), ripple=st.floats(0.0, 0.07), seed=st.integers(0, 2**16))
def test_a_hold_inside_a_movement_is_one_break_even_when_the_movement_starts_at_full_speed(out, hold, back, top,
                                                                                            start, end, ripple, seed):
    """Out, hold, back: one break in the hold, whatever the speed at the movement's ends (a clip cropped
    while moving, a key-pose animation that leaves its first key at speed) and however the pause ripples
    below the rest speed (smoothing, noise). The hold is found although no maximum of the speed lies before
    it inside the movement."""
    rest = 0.08
    pause = np.random.default_rng(seed).uniform(0.0, ripple, hold)
    speed = np.r_[np.linspace(start * top, top, out // 2), np.linspace(top, 0.0, out - out // 2),
                  pause, np.linspace(0.0, top, back - back // 2), np.linspace(top, end * top, back // 2)]
    breaks = speed_breaks(speed, 0.5, rest)
    assert len(breaks) == 1
    slow = np.flatnonzero(speed <= rest)
    slow = slow[(slow > out // 2) & (slow < out + hold + back // 2)]  # the pause and the slow ends of the ramps
    assert slow[0] <= breaks[0] <= slow[-1]


def test_minima_joined_by_a_rest_are_one_hold_at_its_middle():
    """Two minima with nothing faster than the rest speed between them are one hold, cut once at its middle (the
    rule that keeps speed_breaks hand-written: scipy.signal.find_peaks on the negated speed finds 3 and 5 here)."""
    speed = np.array([1, 1, 1, 0.05, 0.07, 0.05, 1, 1, 1.0])
    assert speed_breaks(speed, 0.5, 0.08) == [4]
    speed[4] = 0.3  # faster than the rest speed between them: two holds, two breaks
    assert speed_breaks(speed, 0.5, 0.08) == [3, 5]


def test_noise_at_rest_and_minima_at_the_ends_are_no_breaks():
    rng = np.random.default_rng(1)
    flicker = np.r_[rng.uniform(0, 0.06, 12), np.linspace(0.1, 1.0, 10), np.linspace(1.0, 0.1, 10), rng.uniform(0, 0.06, 12)]
    assert speed_breaks(flicker, 0.5, 0.08) == []
    assert speed_breaks(np.array([0.42, 0.06, 0.31, 0.61, 1.05, 1.41, 1.59, 1.47, 1.23, 1.03, 0.54, 0.17, 0.04, 0.15]),
                        0.5) == []  # the first and last two samples bracket nothing


# -- real people: rests relative to the body and to the demonstrator's own speed (K&G §4.1, §6) -------------------


def movements_with_rests(rng, n_movements, noise, rest_s=0.8):
    """Movements of two or three strokes each that flow into each other (no stop inside a movement, only velocity
    minima), separated by real rests of ``rest_s`` seconds; positions with tracker noise (m). The truth is the
    movements."""
    chunks, truth, at = [], [], 0
    p = np.array([0.0, 1.0, 0.3])
    hold = int(round(rest_s * FPS))
    chunks.append(np.repeat([p], hold, 0))
    at += hold
    for _ in range(n_movements):
        begin = at
        for _ in range(int(rng.integers(2, 4))):
            target = p + rng.uniform(-0.3, 0.3, 3)
            while np.linalg.norm(target - p) < 0.2:
                target = p + rng.uniform(-0.3, 0.3, 3)
            stroke = GuidingStroke(p, target, rng.uniform(0.4, 0.7), 0.5, 0.4, "linear", rng.normal(size=3), 0.0,
                                   0.5, 0.0)
            path = stroke.trajectory(FPS)[:-1]
            chunks.append(path)
            at += len(path)
            p = target
        truth.append((begin, at))
        chunks.append(np.repeat([p], hold, 0))
        at += hold
    path = np.concatenate(chunks) + rng.normal(0.0, noise, (at, 3))
    return Motion(np.stack([np.zeros_like(path), path], 1), FPS, ("root", "wrist")), truth


def test_the_rest_speed_in_body_sizes_and_above_the_noise_by_hand():
    """Two parts 1 m apart: body size 0.5 m, so 0.1 body sizes/s is 0.05 m/s. Still for the first frames (speed 0),
    then moving 0.3 m/s: with noise = 2 the rest speed stays 0.05 (twice the slowest, 0, is less); a body whose
    slowest speed over the floor is 0.3 m/s (sway and noise) rests below 0.6 m/s."""
    seg = VelocityDirection(units="body", body={"rest_speed": 0.1}, noise=2.0, memory=0.1)
    seg.reset(("root", "wrist"), FPS)
    pose = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    assert seg._rest_speed(pose, 0.0) == pytest.approx(0.05)
    assert seg._rest_speed(pose, 0.3) == pytest.approx(0.05)
    seg.reset(("root", "wrist"), FPS)
    for _ in range(5):
        level = seg._rest_speed(pose, 0.3)
    assert level == pytest.approx(0.6)
    assert VelocityDirection()._rest_speed.__doc__  # the formula is documented where it is computed


def test_movements_between_real_rests_under_noise():
    """A tracker 6 mm noisy: the paper's absolute rest speed (0.08 m/s over 0.1 s) is never reached, so the whole
    stream is one movement; relative to the demonstrator's own slowest speed and averaged over a pause of 0.3 s, the
    movements are found and the velocity minima between their strokes cut nothing."""
    rng = np.random.default_rng(11)
    scores = {"paper": [], "relative": []}
    for _ in range(6):
        motion, truth = movements_with_rests(rng, 4, noise=0.006)
        for name, params in (("paper", {}), ("relative", {"units": "body", "noise": 2.0, "pause": 0.3})):
            found = VelocityDirection(parts=["wrist"], level="movement", **params).segment(motion)
            scores[name].append(segmentation_scores([(s.start, s.end) for s in found], truth)["f1"])
    assert np.mean(scores["paper"]) < 0.5
    assert np.mean(scores["relative"]) >= 0.95, scores


def test_the_papers_rest_is_the_default():
    rng = np.random.default_rng(2)
    motion, truth = movements_with_rests(rng, 3, noise=0.001)
    plain = VelocityDirection(parts=["wrist"], level="movement")
    assert plain.params["units"] == "metres" and plain.params["noise"] == 0 and plain.params["pause"] == 0
    explicit = VelocityDirection(parts=["wrist"], level="movement", units="metres", noise=0.0, pause=0.0)
    assert plain.segment(motion) == explicit.segment(motion)


def _frames_and_blocks(params, parts, poses, visible, cuts):
    """The same stream pushed frame by frame and in blocks of ``cuts`` frames: each segmenter, the segments each
    closed (with the frame that closed them) and the onsets it reported at each frame."""
    one = VelocityDirection(**params)
    one.reset(parts, FPS)
    expected, onsets = [], []
    for f in range(len(poses)):
        expected.extend((f, s) for s in one.push(poses[f], visible[f]))
        onsets.append(-1 if one.active_since is None else one.active_since)
    blocks = VelocityDirection(**params)
    blocks.reset(parts, FPS)
    got, since = _in_blocks(blocks, poses, visible, cuts)
    return one, expected, onsets, blocks, got, since


def _in_blocks(segmenter, poses, visible, cuts):
    """``poses`` pushed to ``segmenter`` in blocks of ``cuts`` frames (the rest in one): the segments closed (with the
    frame that closed them) and the onsets reported at each frame."""
    got, since, at = [], [], 0
    for n in [*cuts, len(poses)]:
        closed, block_since = segmenter.push_block(poses[at : at + n], visible[at : at + n])
        got.extend((at + i, s) for i, s in closed)
        since.extend(block_since.tolist())
        at += n
        if at >= len(poses):
            break
    return got, since


@given(seed=st.integers(0, 10_000), cuts=st.lists(st.integers(1, 40), min_size=1, max_size=12),
       params=st.sampled_from([{}, {"level": "movement"}, {"units": "body", "noise": 2.0, "pause": 0.3},
                               {"max_movement": 1.0, "memory": 0.2}, {"parts": ["wrist"], "rest_speed": 0.05},
                               {"level": "movement", "end": "rest", "units": "body", "noise": 2.0},
                               {"end": "rest", "rest": {"settle": 0.5}, "max_movement": 1.0},
                               {"level": "movement", "end": "rest", "units": "body", "noise": 2.0, "window": 0.2,
                                "jitter": 3.0}, {"window": 0.3, "jitter": 2.0, "memory": 0.2}]),
       hidden=st.booleans())
@settings(max_examples=40, deadline=None)
def test_a_block_pushed_at_once_is_its_frames_pushed_one_by_one(seed, cuts, params, hidden):
    """push_block (the block's speeds computed at once, issue 22) closes the same segments at the same frames and
    reports the same onsets as push frame by frame, whatever the packet sizes; a part not seen in the first frames
    (before the first movement) and one hidden for a while (held where last seen) included."""
    rng = np.random.default_rng(seed)
    motion, _ = stroke_sequence(rng, int(rng.integers(1, 4)), noise=0.003)
    poses = motion.positions.copy()
    visible = np.ones(poses.shape[:2], dtype=bool)
    if hidden:  # the wrist not seen in the first frames (at rest: NaN), then lost for a while (held where last seen)
        visible[:3, 1] = False
        poses[:3, 1] = np.nan
        visible[30:40, 1] = False
        poses[30:40, 1] = poses[29, 1]
    one, expected, onsets, blocks, got, since = _frames_and_blocks(params, motion.parts, poses, visible, cuts)
    assert got == expected
    assert since == onsets[: len(since)] and len(since) == len(poses)
    assert blocks.flush() == one.flush()


@pytest.mark.parametrize("level", ["movement", "stroke"])
@pytest.mark.parametrize("moving", [22, 23, 52])
def test_a_movement_after_one_closed_at_max_movement_begins_after_it(level, moving):
    """A movement closed at ``max_movement`` and followed by a rest too short to report: the next movement is
    back-dated to where its motion began, but never into the movement already reported (segments stay disjoint).
    Found by hypothesis in CI: (58, 70) then (67, 73)."""
    speed = np.concatenate([np.zeros(10), np.full(moving, 0.5), np.zeros(5), np.full(30, 0.5), np.zeros(20)])
    poses = np.zeros((len(speed), 2, 3))
    poses[:, 1, 0] = np.cumsum(speed) / FPS
    seg = VelocityDirection(max_movement=1.0, level=level)
    seg.reset(["root", "wrist"], FPS)
    got = [s for f in range(len(poses)) for s in seg.push(poses[f], np.ones(2, bool))] + seg.flush()
    assert len(got) >= 3
    assert all(a.end <= b.start for a, b in zip(got, got[1:])), [(s.start, s.end) for s in got]
    assert got[-1].end > len(poses) - 25  # the second motion is still found


@given(runs=st.lists(st.tuples(st.sampled_from([0.0, 0.02, 0.07, 0.09, 0.2, 0.6, np.nan]), st.integers(1, 15)),
                    min_size=1, max_size=30),
       cuts=st.lists(st.integers(1, 50), max_size=8),
       params=st.fixed_dictionaries({}, optional={"max_movement": st.sampled_from([0.0, 0.05, 0.1, 0.3, 1.0]),
                                                  "memory": st.sampled_from([0.0, 0.05, 0.1, 0.2]),
                                                  "level": st.sampled_from(["stroke", "movement"]),
                                                  "rest_speed": st.sampled_from([0.05, 0.08, 0.1])}))
@settings(max_examples=300, deadline=None)
def test_a_block_followed_at_once_is_its_frames_stepped_one_by_one(runs, cuts, params):
    """With a fixed rest speed (the default) push_block finds onsets, ends and max_movement cuts from the block's
    arrays (issue 22): the same segments at the same frames, the same onsets and the same last working memory as
    push frame by frame, whatever the packet sizes; frames with no speed (the wrist not seen: NaN) included."""
    speed = np.repeat([v for v, _ in runs], [k for _, k in runs])  # runs of a speed (m/s)
    poses = np.zeros((len(speed), 2, 3))
    poses[:, 1, 0] = np.cumsum(np.nan_to_num(speed)) / FPS
    poses[:, 1, 1] = np.sin(np.arange(len(speed)) / 3.0) * 0.02  # turns: direction breaks in stroke level
    poses[np.isnan(speed), 1] = np.nan
    visible = np.isfinite(poses).all(axis=2)
    one, expected, onsets, blocks, got, since = _frames_and_blocks(params, ["root", "wrist"], poses, visible, cuts)
    assert got == expected
    assert since == onsets
    assert (blocks._moving, blocks._resting, blocks._frame) == (one._moving, one._resting, one._frame)
    mine, theirs = blocks.inspect(), one.inspect()
    assert mine.keys() == theirs.keys()
    if mine:
        assert mine["movement"] == theirs["movement"]
        np.testing.assert_array_equal(mine["analysis"].window, theirs["analysis"].window)
    assert blocks.flush() == one.flush()


def test_the_compiled_clustering_cuts_where_numpys_steps_cut(monkeypatch):
    """Random stroke sequences (one part, and the wrist with the root drifting: 6 columns) segment the same with
    the direction clustering's compiled rounds as with numpy's steps (numba absent), segment for segment."""
    import plugins.lib.strokes as strokes

    rng = np.random.default_rng(22)
    motions = [stroke_sequence(rng, int(rng.integers(2, 6)), noise=float(rng.choice([0.001, 0.004])))[0]
               for _ in range(12)]
    settings_ = [dict(parts=["wrist"]), dict(parts=["root", "wrist"], angle=20.0, corner=1.0, drop=0.8,
                                                min_stroke=0.05, smooth=0.0)]
    compiled = [VelocityDirection(**s).segment(m) for s in settings_ for m in motions]
    monkeypatch.setattr(strokes, "_round_kernels", lambda: None)
    assert [VelocityDirection(**s).segment(m) for s in settings_ for m in motions] == compiled
    assert sum(len(c) for c in compiled) > len(compiled)  # movements were cut into strokes


class _Stepped(VelocityDirection):
    """The reference for ``_walk``: every frame of a block stepped (``_steps``), as the segmenter does with ``pause``
    or ``noise``."""

    def _walk(self, poses, flat, speeds, floors, sizes, lags, own):
        return self._steps(poses, flat, speeds, floors, sizes, lags)


@given(seed=st.integers(0, 10_000), cuts=st.lists(st.integers(1, 60), min_size=1, max_size=8),
       params=st.sampled_from([{"level": "movement", "end": "rest", "units": "body", "window": 0.2, "jitter": 3.0},
                               {"end": "rest", "rest": {"settle": 0.5}, "max_movement": 1.0, "jitter": 2.0},
                               {"units": "body", "window": 0.3}, {"level": "movement", "max_movement": 1.5},
                               {"end": "rest", "units": "body", "memory": 0.2, "rest": {"radius": 0.3}}]),
       hidden=st.booleans())
@settings(max_examples=30, deadline=None)
def test_a_block_walked_is_its_frames_stepped(seed, cuts, params, hidden):
    """Without ``pause`` and ``noise`` a block is walked (only the frames where something can happen stepped): the
    same segments at the same frames and the same onsets as every frame stepped, whatever the packet sizes."""
    rng = np.random.default_rng(seed)
    motion, _ = stroke_sequence(rng, int(rng.integers(1, 4)), noise=0.003)
    poses = motion.positions.copy()
    visible = np.ones(poses.shape[:2], dtype=bool)
    if hidden:
        visible[30:40, 1] = False
        poses[30:40, 1] = poses[29, 1]
    results = []
    for kind in (VelocityDirection, _Stepped):
        seg = kind(**params)
        seg.reset(motion.parts, FPS)
        got, since = _in_blocks(seg, poses, visible, cuts)
        results.append((got, since, seg.flush(), seg._moving, seg._resting, seg._frame))
    assert results[0] == results[1]
