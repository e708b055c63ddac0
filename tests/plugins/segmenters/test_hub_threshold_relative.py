"""hub-threshold measured from the demonstrator's own rest, in body sizes (B&B §5.1, §7.1; K&G §4.1, §6)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.bench.metrics import segmentation_scores
from plugins.lib.body_size import body_scale
from plugins.lib.rest_posture import DwellingRest
from plugins.segmenters.hub_threshold import HubThreshold
from toolkit import Motion

FPS = 30.0
PARTS = ("root", "chest", "head", "left_hand", "right_hand", "left_foot", "right_foot")
# one's own hub: an upright figure about 1.7 m tall (root at the hips)
HUB = np.array([[0.0, 0.0, 0.0], [0.0, 0.35, 0.0], [0.0, 0.65, 0.0], [-0.25, -0.05, 0.0], [0.25, -0.05, 0.0],
                [-0.12, -0.95, 0.0], [0.12, -0.95, 0.0]])


def segmenter(scale: float = 1.0, **params) -> HubThreshold:
    """hub-threshold of an observer with HUB as its hub, ``scale`` times as large."""
    seg = HubThreshold(**params)
    body = SimpleNamespace(parts=PARTS, root_index=0, angle_mask=np.zeros(len(PARTS), bool))
    seg.attach(SimpleNamespace(body=body, motor=SimpleNamespace(hub_poses=lambda: scale * HUB[None])))
    return seg


def stance(stoop: float, wide: float, proud: float) -> np.ndarray:
    """A standing posture: chest and head bent forward by ``stoop`` (m), feet ``wide`` apart, head back ``proud``."""
    pose = HUB.copy()
    pose[1, 2] += stoop * 0.5
    pose[2, 2] += stoop - proud
    pose[2, 1] += 0.5 * proud
    pose[5, 0] -= wide
    pose[6, 0] += wide
    pose[3, 0] -= 0.05 * wide / 0.1
    pose[4, 0] += 0.05 * wide / 0.1
    return pose


def gesture(rest: np.ndarray, seconds: float = 1.2, reach: float = 0.6) -> np.ndarray:
    """The right hand raised forward and up and back to ``rest`` (a smooth bell in time)."""
    n = int(round(seconds * FPS))
    bell = np.sin(np.linspace(0.0, np.pi, n)) ** 2
    poses = np.repeat(rest[None], n, axis=0)
    poses[:, 4, 2] += reach * bell
    poses[:, 4, 1] += 0.6 * reach * bell
    return poses


def stream(stances, rest_s: float = 1.0, seed: int = 0, noise: float = 0.002):
    """Stand, gesture, stand... each gesture made from and back to its own stance; the stance changes (shifting
    into it, a short movement of its own, as a person would) where the list says. Returns the motion, the true
    gesture segments and the shifts."""
    rng = np.random.default_rng(seed)
    chunks, truth, shifts, at, previous = [], [], [], 0, None
    hold = int(round(rest_s * FPS))
    for s in stances:
        pose = stance(*s)
        if previous is not None and not np.allclose(previous, pose):
            step = int(round(0.6 * FPS))  # shifting into the new stance: a movement, but not a gesture
            w = (0.5 - 0.5 * np.cos(np.linspace(0.0, np.pi, step)))[:, None, None]
            chunks.append(previous[None] * (1 - w) + pose[None] * w)
            shifts.append((at, at + step))
            at += step
            chunks.append(np.repeat(pose[None], hold, axis=0))
            at += hold
        elif previous is None:
            chunks.append(np.repeat(pose[None], hold, axis=0))
            at += hold
        g = gesture(pose)
        chunks.append(g)
        truth.append((at, at + len(g)))
        at += len(g)
        chunks.append(np.repeat(pose[None], hold, axis=0))
        at += hold
        previous = pose
    poses = np.concatenate(chunks)
    poses = poses + rng.normal(0.0, noise, poses.shape)
    poses[:, 0] = 0.0  # root-relative
    return Motion(poses, FPS, PARTS), truth, shifts


STANCES = [(0.15, 0.0, 0.0), (0.15, 0.0, 0.0), (0.0, 0.12, 0.1), (0.0, 0.12, 0.1), (0.2, 0.1, 0.0), (0.2, 0.1, 0.0)]


def gestures_found(seg: HubThreshold, motion: Motion, gestures, shifts) -> tuple[float, float]:
    """F1 and boundary error (frames) of the gestures. A shift of stance is a movement too: a segment found
    within one is neither right nor wrong, and is left out."""
    found = [(s.start, s.end) for s in seg.segment(motion)]
    found = [(a, b) for a, b in found if not any(c - 3 <= a and b <= d + 3 for c, d in shifts)]
    scores = segmentation_scores(found, gestures)
    return scores["f1"], scores["boundary_error"]


def test_a_styled_stance_that_changes_reads_as_rest():
    """Stooped, then wide and proud, then stooped and wide: with the observer's own hub every stance is above the
    threshold (the paper's plain threshold finds one movement, its floor cannot follow a stance that is farther
    from the hub than the last); from the demonstrator's own rest every gesture and every shift of stance is
    found, each on its own."""
    motion, gestures, shifts = stream(STANCES)
    assert gestures_found(segmenter(floor=0.0), motion, gestures, shifts)[0] < 0.5
    assert gestures_found(segmenter(), motion, gestures, shifts)[0] < 0.9
    for units, stance_ in (("metres", "returned"), ("body", "returned"), ("metres", "held"), ("body", "held")):
        seg = segmenter(reference="rest", units=units, rest={"stance": stance_})
        f1, error = gestures_found(seg, motion, gestures, shifts)
        assert f1 == 1.0 and error <= 10, (units, seg.segment(motion), gestures)  # a third of a gesture
    # the rest it ends with is the last stance, not one's own hub
    assert np.abs(seg.rest - stance(*STANCES[-1])).max() < 0.01


def test_a_hold_is_not_rest_unless_held_for_settle():
    """A gesture that holds its extreme pose and returns to the rest: with stance = returned one movement unless the
    hold outlasts `settle` (2 s); with stance = held, a hold longer than `stand_time` reads as a new rest and cuts
    it."""
    rest = stance(0.1, 0.0, 0.0)
    for hold, stance_, pieces in ((0.1, "returned", 1), (1.0, "returned", 1), (2.5, "returned", 2), (0.1, "held", 1),
                                  (1.0, "held", 2)):
        up, down = np.split(gesture(rest, seconds=1.6), 2)
        held = np.repeat(up[-1:], int(round(hold * FPS)), axis=0)
        still = np.repeat(rest[None], 30, axis=0)
        motion = Motion(np.concatenate([still, up, held, down, still]), FPS, PARTS)
        found = segmenter(reference="rest", rest={"stance": stance_}).segment(motion)
        assert len(found) == pieces, (hold, stance_, found)


def test_the_papers_behaviour_is_the_default():
    motion, _, _ = stream(STANCES[:2], seed=1)
    plain = segmenter()
    assert plain.params["reference"] == "hub" and plain.params["units"] == "metres"
    assert plain.segment(motion) == segmenter(reference="hub", units="metres").segment(motion)
    assert np.array_equal(plain.rest, HUB)


def test_body_units_scale_with_the_body():
    """The same stream and observer ten times as large: in body sizes the same segments; in metres the paper's
    threshold (0.02 m) finds other ones."""
    motion, gestures, shifts = stream(STANCES[:3], noise=0.0)
    big = Motion(motion.positions * 10.0, FPS, PARTS)
    small = segmenter(reference="rest", units="body").segment(motion)
    large = segmenter(10.0, reference="rest", units="body").segment(big)
    assert small == large and len(small) >= len(gestures)
    assert segmenter(10.0, reference="rest").segment(big) != small


def test_size_threshold_is_the_papers_threshold_on_max():
    """0.1 body sizes: Max's body size times 0.1 is the paper's 0.02 m within 2%."""
    from tests.conftest import CHARACTERS  # noqa: F401  (the character path)
    from toolkit import create_plugin_manager, load_character

    max_ = load_character("max", create_plugin_manager())
    hub = max_.motor.hub_poses()[0]
    size = body_scale(hub - hub[max_.body.root_index], ~max_.body.angle_mask)
    assert abs(0.1 * size - 0.02) / 0.02 < 0.02


def test_dwelling_spreads_by_hand():
    """The spread of a window is the largest root-mean-square deviation of a part from its mean: a part at 0, 0,
    0.3 (three frames of dwell) has mean 0.1 and deviation sqrt((0.01 + 0.01 + 0.04) / 3) = sqrt(0.02)."""
    poses = np.zeros((3, 2, 3))
    poses[2, 1, 0] = 0.3
    rest = DwellingRest(2, 30.0, dwell=0.1, prior=np.zeros((2, 3)))  # 3 frames
    spread, size = rest.spreads(poses)
    assert np.isinf(spread[:2]).all()
    assert spread[2] == pytest.approx(np.sqrt(0.02))
    # the mean pose has parts at 0 and 0.1 on x: centroid 0.05, distances 0.05 each
    assert size[2] == pytest.approx(0.05)


def test_dwelling_rest_is_the_mean_of_the_standing_stretch():
    """Standing (spread within the radius) for a window of 3 frames re-anchors the rest on that window's mean, then
    on the mean of the whole stretch while it lasts; moving keeps it."""
    prior = np.zeros((1, 3))
    est = DwellingRest(1, 30.0, dwell=0.1, prior=prior)
    x = np.array([0.0, 1.0, 1.0, 1.0, 1.0, 1.2, 2.0, 2.0])
    poses = np.stack([x, np.zeros_like(x), np.zeros_like(x)], axis=1)[:, None, :]
    rests, events = est.update(poses, radius=0.11)
    # windows ending at 3 ([1, 1, 1]) and 4 stand; at 5 ([1, 1, 1.2]) the spread is 0.094 < 0.11: still standing
    assert rests[:3, 0, 0] == pytest.approx([0.0, 0.0, 0.0])
    assert rests[3:6, 0, 0] == pytest.approx([1.0, 1.0, (1.0 * 4 + 1.2) / 5])
    assert rests[6:, 0, 0] == pytest.approx([(1.0 * 4 + 1.2) / 5] * 2)  # [1, 1.2, 2] and [1.2, 2, 2] move
    assert list(np.flatnonzero(events[:, 0] >= 0)) == [3] and events[3].tolist() == [1, -1, -1]


def test_a_new_stance_is_a_candidate_until_returned_to():
    """With confirm: after the first rest (x = 0), standing at x = 1 is a candidate (the rest stays); standing at
    0 again drops it (a hold); standing at 2 then moving and standing at 2 again makes 2 the rest, reported as
    (candidate began, left, stood again)."""
    est = DwellingRest(1, 30.0, dwell=0.1, prior=np.zeros((1, 3)), confirm=True)
    x = [0, 0, 0, 1, 1, 1, 0, 0, 0, 2, 2, 2, 3, 2, 2, 2]
    poses = np.array([[[v, 0.0, 0.0]] for v in x], dtype=float)
    rests, events = est.update(poses, radius=0.01, near=0.5)
    assert rests[:, 0, 0].tolist() == [0.0] * 15 + [2.0]
    assert [tuple(e) for e in events.tolist() if e[0] >= 0] == [(0, -1, -1), (6, -1, -1), (9, 12, 13)]
    assert est.candidate is None
    settled = DwellingRest(1, 30.0, dwell=0.1, prior=np.zeros((1, 3)), confirm=True, settle=0.2)  # 6 frames
    rests, events = settled.update(np.array([[[v, 0.0, 0.0]] for v in [0, 0, 0] + [1] * 6], dtype=float),
                                   radius=0.01, near=0.5)
    assert rests[:, 0, 0].tolist() == [0.0] * 8 + [1.0]
    assert events[8].tolist() == [3, -1, -1]


@settings(max_examples=25, deadline=None)
@given(st.lists(st.integers(1, 60), min_size=1, max_size=30), st.sampled_from(["metres", "body"]),
       st.sampled_from(["returned", "held"]), st.integers(0, 3))
def test_blocks_and_frames_give_the_same_segments(sizes, units, stance_, seed):
    """Block-wise and frame-by-frame feeding give the same segments at the same frames, and the same rest."""
    motion, _, _ = stream(STANCES[seed:seed + 3], seed=seed)
    whole = segmenter(reference="rest", units=units, rest={"stance": stance_})
    whole.reset(motion.parts, motion.fps)
    one = [(f, s) for f in range(motion.n_frames) for s in whole.push(motion.positions[f], motion.visible[f])]
    one += [(motion.n_frames, s) for s in whole.flush()]
    blocks = segmenter(reference="rest", units=units, rest={"stance": stance_})
    blocks.reset(motion.parts, motion.fps)
    got, at, k = [], 0, 0
    while at < motion.n_frames:
        n = sizes[k % len(sizes)]
        closed, _ = blocks.push_block(motion.positions[at:at + n], motion.visible[at:at + n])
        got.extend((at + i, s) for i, s in closed)
        at, k = at + n, k + 1
    got += [(motion.n_frames, s) for s in blocks.flush()]
    assert got == one
    assert np.allclose(whole.rest, blocks.rest)


def test_a_noisy_tracker_still_shows_standing_up_to_a_point():
    """Tracker noise of 2.8 mm per axis moves some part more than `stillness` times the 0.02 m threshold (5 mm)
    when nobody moves: without `noise` standing is seen only now and then and gestures merge; with noise = 2 the
    radius follows the spread seen at rest and every gesture is found. At 4 mm twice that spread is above half the
    threshold: standing cannot be told from noise, nobody is seen standing, and the rest stays one's own hub (the
    paper's segments)."""
    for seed in range(3):
        motion, gestures, shifts = stream(STANCES, noise=0.0028, seed=seed)
        assert gestures_found(segmenter(reference="rest", rest={"noise": 0.0}), motion, gestures, shifts)[0] < 0.95
        assert gestures_found(segmenter(reference="rest"), motion, gestures, shifts)[0] == 1.0
    motion, gestures, shifts = stream(STANCES, noise=0.004)
    noisy = segmenter(reference="rest")
    assert noisy.segment(motion) == segmenter().segment(motion) and np.array_equal(noisy.rest, HUB)


def test_the_noise_floor_is_the_smallest_spread_of_the_last_seconds():
    """A running minimum over `floor` seconds (3 frames at 30 fps for 0.1 s), across blocks."""
    est = DwellingRest(1, 30.0, dwell=0.1, prior=np.zeros((1, 3)))
    first = est.noise_floor(np.array([5.0, 4.0, 6.0, 7.0]), 0.1)
    second = est.noise_floor(np.array([8.0, 1.0, 9.0, 9.0, 9.0]), 0.1)
    assert first.tolist() == [5.0, 4.0, 4.0, 4.0]
    assert second.tolist() == [6.0, 1.0, 1.0, 1.0, 9.0]
